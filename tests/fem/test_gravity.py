"""The structure's self-weight (issue 43, gravity; ``petsc_ssi/fem/gravity.py``): a static case
solved once before the steps, its member forces and support reactions written beside the run's, and
combined with the run's signed extremes (G + max E, G + min E).

- A fixed-base portal frame (Euler-Bernoulli members, axial deformation negligible) under its own
  weight: the beam's weight is a uniform load w = rho A_b g, so by slope-deflection (no sway: the frame
  and the load are symmetric) the corner moment is M_B = w L^2 / (6 (k + 2)), the base moment
  M_A = M_B / 2, the horizontal thrust H = (M_A + M_B) / h, k = (I_b / L) / (I_c / h); each column's
  axial force at its base is half the frame's weight minus the weight the base node carries itself.
  The run lumps the weight at the nodes (the mass it integrates with), which differs from the uniform
  load by fixed-end moments of the beam's elements, O(1/n^2): at 16 beam elements the base moment and thrust are 0.39 % low; the
  tolerance is 1 %.
- The building (meshes/building.geo, reduced) on its fixed foundation: the support reactions sum to its
  weight g sum m (1e-9) and the bottom columns' axial forces to the weight of everything above the
  supported nodes (1e-9).
"""
import os

import h5py
import numpy as np
import pytest

from fem_helpers import run_cli

pytestmark = pytest.mark.run

E, RHO, G = 30e9, 2500.0, 9.81
H, L, NC, NB = 3.0, 6.0, 6, 16                  # column height, span [m]; elements per column, beam
AC, IC, AB, IB = 100.0, 2e-3, 100.0, 4e-3      # areas [m^2] (axial deformation negligible), inertias [m^4]

PORTAL = f"""
Point(1) = {{0, 0, 0}}; Point(2) = {{0, 0, {H}}}; Point(3) = {{{L}, 0, {H}}}; Point(4) = {{{L}, 0, 0}};
Line(1) = {{1, 2}}; Line(2) = {{2, 3}}; Line(3) = {{4, 3}};
Transfinite Curve{{1, 3}} = {NC + 1}; Transfinite Curve{{2}} = {NB + 1};
Physical Curve("columns") = {{1, 3}}; Physical Curve("beam") = {{2}};
Physical Point("base") = {{1, 4}}; Physical Point("top") = {{2}};
"""


def _part(name, area, inertia, orientation):
    p = f"-ssi_fem_part_{name}_"
    return [p + "element", "frame", p + "E", str(E), p + "nu", "0.2", p + "rho", str(RHO), p + "area", str(area),
            p + "Iy", str(inertia), p + "Iz", str(inertia), p + "J", str(inertia), p + "shear_factor", "0",
            p + "orientation", orientation]


def _portal(tmp_path, extra=(), n=1):
    geo = tmp_path / "portal.geo"
    geo.write_text(PORTAL)
    out = str(tmp_path / "portal.h5")
    args = (["-ssi_problem", "fem", "-ssi_fem_mesh", str(geo), "-ssi_fem_parts", "columns,beam",
             "-ssi_fem_fixed", "base", "-ssi_fem_gravity", str(G), "-ssi_structure_forces", "all",
             "-ssi_fem_point_load", f"top,2e4,0,0", "-ssi_fem_load_history", "box", "-ssi_fem_load_t0", "0.02",
             "-ssi_dt", "5e-3", "-ssi_t_end", "0.1", "-ssi_receivers", f"0,0,{H}", "-ssi_output", out,
             "-ssi_structure_drift_levels", f"0,{H}"]
            + _part("columns", AC, IC, "1,0,0") + _part("beam", AB, IB, "0,0,1") + list(extra))
    r = run_cli(args, n=n)
    assert r.returncode == 0, r.stdout + r.stderr
    return out, r


def test_portal_frame_self_weight_closed_form(tmp_path):
    """The portal's member forces under self-weight against slope-deflection (module docstring), its
    reactions against its weight, and the combined envelopes against G + the run's signed extremes
    (a horizontal box pulse at the beam: E(t) changes sign, so max > 0 > min somewhere)."""
    out, r = _portal(tmp_path)
    assert "gravity 9.81 m/s^2 along -z" in r.stdout
    w = RHO * AB * G
    k = (IB / L) / (IC / H)
    MB = w * L ** 2 / (6 * (k + 2))
    MA = MB / 2
    Hx = (MA + MB) / H
    with h5py.File(out, "r") as f:
        col, beam = f["forces/columns_gravity"][()], f["forces/beam_gravity"][()]
        nodes = f["forces/columns_nodes"][()]
        X = f["coordinates"][()].reshape(-1, 3)
        gr = f["gravity"]
        W = float(gr["weight"][()])
        assert abs(W - G * RHO * (2 * AC * H + AB * L)) < 1e-9 * W
        assert np.allclose(gr["base_force"][()], [0, 0, -W], rtol=0, atol=1e-9 * W)
        assert gr["reactions"].shape == (2, 6) and np.allclose(gr["reactions"][:, 2], W / 2, rtol=1e-9)
        assert "G + max_t E(t)" in f["forces/columns_gravity_plus_max"].attrs["combination"]
        assert f["gravity/g"].attrs["unit"] == "m/s^2"
        # the columns' lowest elements (node 0 at z = 0): moment about y' and shear at the base
        low = np.nonzero(np.isclose(X[nodes[:, 0], 2], 0.0) | np.isclose(X[nodes[:, 1], 2], 0.0))[0]
        assert len(low) == 2
        end = [0 if np.isclose(X[nodes[e, 0], 2], 0.0) else 1 for e in low]
        Mbase = [abs(col[e, 6 * s + 4]) for e, s in zip(low, end)]
        Vbase = [abs(col[e, 6 * s + 2]) for e, s in zip(low, end)]
        Nbase = [abs(col[e, 6 * s + 0]) for e, s in zip(low, end)]
        assert np.allclose(Mbase, MA, rtol=1e-2), (Mbase, MA)
        assert np.allclose(Vbase, Hx, rtol=1e-2), (Vbase, Hx)
        # the base node's own lumped weight (half a column element) goes straight into its support
        assert np.allclose(Nbase, W / 2 - RHO * AC * G * H / NC / 2, rtol=1e-9)
        # the corner: the beam's end moment, and its axial force is the thrust
        bx = f["forces/beam_nodes"][()]
        first = np.nonzero(np.isclose(X[bx[:, 0], 0], 0.0) | np.isclose(X[bx[:, 1], 0], 0.0))[0][0]
        s = 0 if np.isclose(X[bx[first, 0], 0], 0.0) else 1
        assert abs(abs(beam[first, 6 * s + 4]) - MB) < 1e-2 * MB, (beam[first], MB)
        assert abs(abs(beam[first, 6 * s]) - Hx) < 1e-2 * Hx
        # the combined envelopes are G + the signed extremes, and the extremes are the |E| envelope
        for p in ("columns", "beam"):
            g, mx, mn = (f[f"forces/{p}_{w_}"][()] for w_ in ("gravity", "max", "min"))
            env = f[f"forces/{p}_envelope"][()]
            assert np.array_equal(f[f"forces/{p}_gravity_plus_max"][()], g + mx)
            assert np.array_equal(f[f"forces/{p}_gravity_plus_min"][()], g + mn)
            assert np.all(mx >= 0) and np.all(mn <= 0)
            assert np.allclose(np.maximum(mx, -mn), env, rtol=0, atol=1e-12 * env.max())
        assert f["forces/columns_max"][:, 4].max() > 0 > f["forces/columns_min"][:, 4].min()
        # the demands' base shear combined: the gravity case's (0 by symmetry) plus the extremes
        d = f["demands/base_shear"][()]
        assert np.allclose(gr["base_shear_gravity_plus_max"][()], gr["base_shear_gravity"][()] + d.max(axis=0))
        assert np.allclose(gr["base_shear_gravity_plus_min"][()], gr["base_shear_gravity"][()] + d.min(axis=0))
        assert abs(gr["base_shear_gravity"][0]) < 1e-9 * W


def test_static_command_adds_the_self_weight(tmp_path):
    """``petsc-ssi static`` with -ssi_fem_gravity and no other load: the solution is the self-weight
    case, its member forces the closed form's base moment, its group the weight."""
    geo = tmp_path / "portal.geo"
    geo.write_text(PORTAL)
    out = str(tmp_path / "static.h5")
    r = run_cli(["static", "-ssi_fem_mesh", str(geo), "-ssi_fem_parts", "columns,beam", "-ssi_fem_fixed", "base",
                 "-ssi_fem_gravity", str(G), "-ssi_structure_forces", "columns", "-ssi_receivers", f"0,0,{H}",
                 "-ssi_output", out] + _part("columns", AC, IC, "1,0,0") + _part("beam", AB, IB, "0,0,1"))
    assert r.returncode == 0, r.stdout + r.stderr
    w = RHO * AB * G
    MA = w * L ** 2 / (12 * ((IB / L) / (IC / H) + 2))
    with h5py.File(out, "r") as f:
        col, nodes = f["forces/columns"][0], f["forces/columns_nodes"][()]
        X = f["coordinates"][()].reshape(-1, 3)
        assert abs(float(f["gravity/weight"][()]) - G * RHO * (2 * AC * H + AB * L)) < 1e-6
    low = [(e, 0 if np.isclose(X[nodes[e, 0], 2], 0.0) else 1) for e in range(len(nodes))
           if np.isclose(X[nodes[e], 2], 0.0).any()]
    assert len(low) == 2
    assert np.allclose([abs(col[e, 6 * s + 4]) for e, s in low], MA, rtol=1e-2)


SLAB = os.path.join("runs", "structures", "slab-on-columns.opts")


@pytest.mark.parametrize("opts, value, words", [(SLAB, "981", "looks like cm/s^2"), (SLAB, "-9.81", "must be >= 0"),
                                                (os.path.join("runs", "building", "demo.opts"), "9.81",
                                                 "not modelled in a coupled run")])
def test_gravity_bad_value_refused_in_one_line(tmp_path, opts, value, words):
    """A gravity in cm/s^2, a negative one, and gravity in a coupled run are refused in one line
    before any work (no output)."""
    out = str(tmp_path / "x.h5")
    r = run_cli(["-options_file", opts, "-ssi_fem_gravity", value, "-ssi_output", out])
    assert r.returncode != 0 and words in r.stdout + r.stderr
    assert "Traceback" not in r.stderr and not os.path.exists(out)


BUILDING = ["-options_file", os.path.join("runs", "building", "fixed-base.opts"),
            "-ssi_fem_mesh_params", "nbx=2,nby=2,sx=3.6,sy=3.6,ns=2", "-ssi_t_end", "0.01",
            "-ssi_fem_gravity", str(G), "-ssi_structure_forces", "columns", "-ssi_receivers", "0,0,6"]


def test_building_reactions_and_columns_carry_its_weight(tmp_path):
    """The reduced building (2 x 2 bays, 2 storeys) on its fixed foundation: the reactions sum to its
    weight, and the columns' axial forces just above the foundation sum to the weight of every node
    that is not supported (the foundation's own weight goes straight into its supports)."""
    out = str(tmp_path / "b.h5")
    r = run_cli(BUILDING + ["-ssi_output", out])
    assert r.returncode == 0, r.stdout + r.stderr
    with h5py.File(out, "r") as f:
        W = float(f["gravity/weight"][()])
        assert abs(W - G * float(f.attrs["structure_mass"])) < 1e-9 * W
        assert abs(-f["gravity/base_force"][2] - W) < 1e-9 * W
        assert abs(f["gravity/reactions"][:, 2].sum() - W) < 1e-9 * W
        col, nodes = f["forces/columns_gravity"][()], f["forces/columns_nodes"][()]
        X = f["coordinates"][()].reshape(-1, 3)
        supported = set(f["gravity/reaction_nodes"][()].tolist())
        low = [e for e in range(len(nodes)) if nodes[e, 0] in supported or nodes[e, 1] in supported]
        # N at the supported end of each bottom column element: compression = -N_i (stress resultant)
        N = sum(col[e, 0] if nodes[e, 0] in supported else -col[e, 6] for e in low)
        free = float(f["gravity/free_weight"][()])
    assert len(low) == 9                            # a 3 x 3 grid of columns
    z = X[:, 2]
    assert np.all(np.isclose(z[list(supported)], 0.0))
    # every node above the foundation hangs on the columns: their axial forces at the base sum to the
    # weight of the free nodes (the supported nodes' own lumped weight goes straight into the supports)
    assert free > 0.5 * W
    assert abs(N - free) < 1e-9 * W, (N, free, W)
