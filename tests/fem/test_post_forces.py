"""``petsc-ssi post FILE.h5 --forces [PART,...] --csv``: the member forces as the section resultants an engineer
reads (frames: N > 0 tension at each end; shells as stored), against the portal frame's closed form under its
self-weight (test_gravity: slope-deflection):

- the columns' base: N = -(W/2 - the base node's own weight), compression;
- the beam (orientation 0,0,1: z' up): M2 = +M_B at the corners (hogging stretches the top fibre +z'), and
  -(w L^2 / 8 - M_B) at midspan (sagging), within 1 % and 2 % (the lumped weight's fixed-end moments);
- peak_abs is the file's |E| envelope; at end i the section's G + E max is minus the file's G + min_t E(t) of the
  end forces, at end j the file's own; an unknown part and a file without forces refused in one line.
"""
import csv
import io

import h5py
import numpy as np
import pytest

from fem_helpers import run_cli
from test_gravity import AB, AC, G, H, IB, IC, L, NC, RHO, _portal

pytestmark = pytest.mark.run


def _table(text):
    rows = [r for r in csv.reader(io.StringIO(text)) if r and not r[0].startswith("#")]
    assert rows[0] == ["part", "element", "end", "node", "x_m", "y_m", "z_m", "component", "unit", "peak_abs",
                       "gravity", "gravity_plus_max", "gravity_plus_min"]
    return [dict(zip(rows[0], r)) for r in rows[1:]]


def test_portal_section_resultants(tmp_path):
    out, _ = _portal(tmp_path)
    r = run_cli(["post", out, "--forces", "--csv"])
    assert r.returncode == 0, r.stderr
    assert "N > 0 tension" in r.stdout and "# modelled part: the whole mesh" in r.stdout
    rows = _table(r.stdout)
    assert {x["part"] for x in rows} == {"columns", "beam"}
    W = G * RHO * (2 * AC * H + AB * L)
    w = RHO * AB * G
    MB = w * L ** 2 / (6 * ((IB / L) / (IC / H) + 2))
    # the columns' base: compression
    base = [x for x in rows if x["part"] == "columns" and float(x["z_m"]) == 0.0 and x["component"] == "N"]
    assert len(base) == 2 and all(x["unit"] == "N" for x in base)
    expect = -(W / 2 - RHO * AC * G * H / NC / 2)
    assert all(float(x["gravity"]) == pytest.approx(expect, rel=1e-9) for x in base), (base, expect)
    # the beam: hogging at the corners, sagging at midspan
    m2 = [x for x in rows if x["part"] == "beam" and x["component"] == "M2"]
    corner = [float(x["gravity"]) for x in m2 if float(x["x_m"]) in (0.0, L)]
    mid = [float(x["gravity"]) for x in m2 if abs(float(x["x_m"]) - L / 2) < 1e-9]
    assert len(corner) == 2 and len(mid) == 2
    assert np.allclose(corner, MB, rtol=1e-2), (corner, MB)
    assert np.allclose(mid, -(w * L ** 2 / 8 - MB), rtol=2e-2), (mid, w * L ** 2 / 8 - MB)
    # against the file's end forces
    with h5py.File(out, "r") as f:
        comps = str(f["forces/beam_envelope"].attrs["components"]).split(",")
        env, gmax, gmin = (f[f"forces/beam_{s}"][()] for s in ("envelope", "gravity_plus_max", "gravity_plus_min"))
    for x in [x for x in rows if x["part"] == "beam"]:
        e, c = int(x["element"]), comps.index(f"{x['component']}_{x['end']}")
        assert float(x["peak_abs"]) == pytest.approx(env[e, c], rel=1e-8, abs=1e-300)
        hi, lo = (-gmin[e, c], -gmax[e, c]) if x["end"] == "i" else (gmax[e, c], gmin[e, c])
        assert float(x["gravity_plus_max"]) == pytest.approx(hi, rel=1e-8, abs=1e-6)
        assert float(x["gravity_plus_min"]) == pytest.approx(lo, rel=1e-8, abs=1e-6)
    # one part by name, to a file; refusals
    r = run_cli(["post", out, "--forces", "beam", "--csv", str(tmp_path / "beam.csv")])
    assert r.returncode == 0 and {x["part"] for x in _table((tmp_path / "beam.csv").read_text())} == {"beam"}
    r = run_cli(["post", out, "--forces", "beams", "--csv"])
    err = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2 and len(err) == 1 and "holds no member forces of a part 'beams' (it holds: beam, " \
        "columns)" in err[0], r.stderr
    r = run_cli(["post", out, "--forces"])
    assert r.returncode == 2 and "--forces writes a CSV: give --csv" in r.stderr


def test_forces_refused_without_the_group(tmp_path):
    p = tmp_path / "x.h5"
    with h5py.File(p, "w") as f:
        f.attrs["problem"] = "fem"
    r = run_cli(["post", str(p), "--forces", "--csv"])
    assert r.returncode == 2 and "no group forces (member forces are written with -ssi_structure_forces" in r.stderr


def test_static_file_signed_section_resultants(tmp_path):
    """A `petsc-ssi static` file of the portal under its self-weight alone: one solution with the self-weight in it,
    so --forces prints its signed section resultants (column value; before: peak_abs |value| and a header saying
    the run had no gravity); they equal the transient run's gravity case G (its own solve, test_portal_...) to
    1e-9, the columns' base in compression, the beam hogging at the corners; the file says what it models."""
    from test_gravity import PORTAL
    geo = tmp_path / "portal.geo"
    geo.write_text(PORTAL)
    out = str(tmp_path / "static.h5")
    from test_gravity import _part
    r = run_cli(["static", "-ssi_fem_mesh", str(geo), "-ssi_fem_parts", "columns,beam", "-ssi_fem_fixed", "base",
                 "-ssi_fem_gravity", str(G), "-ssi_structure_forces", "all", "-ssi_output", out]
                + _part("columns", AC, IC, "1,0,0") + _part("beam", AB, IB, "0,0,1"))
    assert r.returncode == 0, r.stdout + r.stderr
    r = run_cli(["post", out, "--forces", "--csv"])
    assert r.returncode == 0, r.stderr
    assert f"the options' loads plus the self-weight (-ssi_fem_gravity {G:g} m/s^2)" in r.stdout
    assert "# modelled part: the whole mesh" in r.stdout and "no -ssi_fem_gravity" not in r.stdout
    rows = [x for x in csv.reader(io.StringIO(r.stdout)) if x and not x[0].startswith("#")]
    assert rows[0] == ["part", "element", "end", "node", "x_m", "y_m", "z_m", "component", "unit", "value"]
    static = {(x[0], x[1], x[2], x[7]): float(x[9]) for x in rows[1:]}
    (tmp_path / "dyn").mkdir()
    dyn, _ = _portal(tmp_path / "dyn")
    ref = {(x["part"], x["element"], x["end"], x["component"]): float(x["gravity"])
           for x in _table(run_cli(["post", dyn, "--forces", "--csv"]).stdout)}
    assert set(static) == set(ref) and len(ref) > 20
    scale = max(abs(v) for v in ref.values())
    assert max(abs(static[k] - ref[k]) for k in ref) <= 1e-9 * scale
    W = G * RHO * (2 * AC * H + AB * L)
    base = [float(x[9]) for x in rows[1:] if x[0] == "columns" and x[7] == "N" and float(x[6]) == 0.0]
    assert len(base) == 2 and np.allclose(base, -(W / 2 - RHO * AC * G * H / NC / 2), rtol=1e-9), base
    MB = RHO * AB * G * L ** 2 / (6 * ((IB / L) / (IC / H) + 2))
    assert max(v for (p, e, end, c), v in static.items() if p == "beam" and c == "M2") == pytest.approx(MB, rel=1e-2)


BRACKETS = """// four cantilevers fixed at 'base', loaded at 'tip': A a 3-4-5 slope in the x-z plane, B the same (other
// orientation), C skewed in 3D, D as A with its line drawn tip to base (x' reversed)
Point(1) = {0, 0, 0}; Point(2) = {3, 0, 4}; Point(3) = {0, 5, 0}; Point(4) = {3, 5, 4};
Point(5) = {10, 0, 0}; Point(6) = {12, 3, 6}; Point(7) = {0, 10, 0}; Point(8) = {3, 10, 4};
Line(1) = {1, 2}; Line(2) = {3, 4}; Line(3) = {5, 6}; Line(4) = {8, 7};
Transfinite Curve{1, 2, 3, 4} = 5;
Physical Curve("A") = {1}; Physical Curve("B") = {2}; Physical Curve("C") = {3}; Physical Curve("D") = {4};
Physical Point("base") = {1, 3, 5, 7}; Physical Point("tip") = {2, 4, 6, 8};
"""


def test_inclined_and_skewed_cantilevers_against_statics(tmp_path):
    """Statically determinate 3D cantilevers (BRACKETS) under a tip force F = (200, 300, -1000) N: every section
    resultant of `post --forces` (a static file: signed) equals statics written from the CSV header's own words
    (x' node 0 -> 1, z' the orientation made normal to x', y' = z' x x'; the resultant on the face whose outward
    normal points to the tip is (F, (tip - x) x F), negated where +x' points away from the tip), to 1e-9 of the
    largest moment; the orientation moves moments between M2 and M3 and leaves N alone (A: 0,1,0; B: 0,0,1), and
    a member drawn tip to base (D) flips V and M as its axes say. (An independent check of 2026-12-03 made this a
    test.) At A's base by hand: N = F . (0.6, 0, 0.8) = -680 N (compression)."""
    geo = tmp_path / "brackets.geo"
    geo.write_text(BRACKETS)
    out = str(tmp_path / "brackets.h5")
    orient = {"A": "0,1,0", "B": "0,0,1", "C": "0,0,1", "D": "0,1,0"}
    args = ["static", "-ssi_fem_mesh", str(geo), "-ssi_fem_parts", "A,B,C,D", "-ssi_fem_fixed", "base",
            "-ssi_fem_point_load", "tip,200,300,-1000", "-ssi_structure_forces", "all", "-ssi_output", out]
    for name, o in orient.items():
        p = f"-ssi_fem_part_{name}_"
        args += [p + "element", "frame", p + "E", "2e11", p + "nu", "0.3", p + "rho", "7850", p + "area", "0.01",
                 p + "Iy", "1e-5", p + "Iz", "2e-5", p + "J", "3e-5", p + "shear_factor", "0", p + "orientation", o]
    r = run_cli(args)
    assert r.returncode == 0, r.stdout + r.stderr
    r = run_cli(["post", out, "--forces", "--csv"])
    assert r.returncode == 0, r.stderr
    rows = [x for x in csv.reader(io.StringIO(r.stdout)) if x and not x[0].startswith("#")]
    rows = [dict(zip(rows[0], x)) for x in rows[1:]]
    F = np.array([200.0, 300.0, -1000.0])
    ends = {(x["part"], x["element"], x["end"]): np.array([float(x[k]) for k in ("x_m", "y_m", "z_m")]) for x in rows}
    members = {"A": ((0, 0, 0), (3, 0, 4)), "B": ((0, 5, 0), (3, 5, 4)), "C": ((10, 0, 0), (12, 3, 6)),
               "D": ((0, 10, 0), (3, 10, 4))}
    got, hand = [], []
    for x in rows:
        p, e = x["part"], x["element"]
        base, tip = (np.array(v, float) for v in members[p])
        o = np.array([float(v) for v in orient[p].split(",")])
        xi, xj = ends[(p, e, "i")], ends[(p, e, "j")]
        ex = (xj - xi) / np.linalg.norm(xj - xi)
        ez = o - (o @ ex) * ex
        ez /= np.linalg.norm(ez)
        ey = np.cross(ez, ex)
        R, M = F, np.cross(tip - ends[(p, e, x["end"])], F)
        if ex @ (tip - base) < 0:
            R, M = -R, -M
        hand.append({"N": R @ ex, "V2": R @ ey, "V3": R @ ez, "T": M @ ex, "M2": M @ ey, "M3": M @ ez}[x["component"]])
        got.append(float(x["value"]))
    assert len(got) == 4 * 4 * 2 * 6
    scale = max(abs(v) for v in hand)
    assert np.abs(np.array(got) - np.array(hand)).max() <= 1e-9 * scale
    val = {(x["part"], x["element"], x["end"], x["component"]): float(x["value"]) for x in rows}
    assert val[("A", "0", "i", "N")] == pytest.approx(-680.0, rel=1e-12)     # compression, the sign read directly
    assert val[("B", "0", "i", "N")] == pytest.approx(-680.0, rel=1e-12)
    assert abs(val[("A", "0", "i", "M2")]) == pytest.approx(abs(val[("B", "0", "i", "M3")]), rel=1e-9)
