"""The beta warning comes from the stability map (issue 30, item 3): its thresholds are what
runs/stability/stability_map.csv found, the project's own cases (the demo's building, the half
building, the paper's foundation) do not trigger it, and edge diffraction is one
line naming the earliest arrival and every receiver it reaches."""
import csv
import os

import pytest

from helpers import ROOT, cli

pytestmark = pytest.mark.run


def test_thresholds_are_the_maps():
    from petsc_ssi.bem.stability import MAP_STABLE_FROM, MAP_BETA_MAX
    rows = list(csv.DictReader(open(os.path.join(ROOT, "runs", "stability", "stability_map.csv"))))
    rows = [r for r in rows if r["part"] == "map"]
    for scheme, expect in MAP_STABLE_FROM.items():
        worst = 0.0
        for h in sorted({r["h"] for r in rows if r["scheme"] == scheme}):
            runs = sorted((float(r["beta"]), r["class"]) for r in rows if r["scheme"] == scheme and r["h"] == h)
            bad = [b for b, c in runs if c != "stable"]
            stable_from = min(b for b, c in runs if not bad or b > max(bad))   # every run from here on stable
            worst = max(worst, stable_from)
        assert worst == expect, (scheme, worst)
    top = max(float(r["beta"]) for r in rows)
    assert top == MAP_BETA_MAX and all(r["class"] == "stable" for r in rows if float(r["beta"]) == top)


def test_beta_warning_follows_the_scheme():
    from petsc_ssi.bem.stability import beta_warning
    assert beta_warning("stabilized", 0.1, 1.9) is None and beta_warning("plain", 0.2, 2.0) is None
    msg = beta_warning("plain", 0.1, 1.0)
    assert "below 0.15, from which every plain run" in msg and "-ssi_scheme stabilized from 0.07" in msg
    assert "above 2" in beta_warning("stabilized", 0.5, 2.5) and "\n" not in msg


@pytest.mark.parametrize("opts", ["runs/building/demo.opts", "runs/building/ssi-half-bonded.opts",
                                  "runs/foundation/sym-bonded.opts"])
def test_shipped_cases_do_not_warn_about_beta(opts):
    """Before: 'beta ... outside [0.3, 1.3]: the time marching may be inaccurate or unstable' on the
    demo's building (c_s dt / l from 0.366 to 2.0: inside the map's stable range)."""
    p = cli(["estimate", "-options_file", opts])
    assert "beta" not in "\n".join(ln for ln in p.stdout.splitlines() if "warning" in ln), p.stdout[-3000:]


def test_diffraction_is_one_line(tmp_path):
    """The demo's building stops at the memory check (after the set-up's warnings): one line with
    the earliest arrival and every receiver and the structure; before, one line each. The earliest:
    receiver 1 at x = 6 m, path from the load's far side (x = 8 + 0.5 m) to the edge x = 12 m and
    back, 3.5 + 6 m at c_p = 208 m/s."""
    t = (3.5 + 6.0) / 208.0
    p = cli(["-options_file", "runs/building/demo.opts", "-ssi_memory_limit", "0.001",
             "-ssi_output", str(tmp_path / "d.h5")], check=False)
    lines = [ln for ln in p.stdout.splitlines() if "diffracted" in ln]
    assert p.returncode == 2 and len(lines) == 1, p.stdout[-3000:]
    assert f"the earliest at t = {t:.4g} s" in lines[0] and f"receiver 1 (6, 0, 0) (t = {t:.4g} s)" in lines[0]
    assert all(f"receiver {k}" in lines[0] for k in range(3)) and "the structure" in lines[0]


def test_a_seismic_building_s_diffraction_is_from_its_interface(tmp_path):
    """The demo's building under a vertical wave (runs/seismic/building.opts, its slab load-free: -ssi_load_p0
    0) stops at the memory check: before, no diffraction warning at all (the waves' sources were the loaded
    cells only, and the slab load-free counted as a load in the wording); now the structure's interface,
    which scatters the wave, is the source. The earliest: receivers 0 and 1 at x = +-6 m, path from the
    interface's edge (x = +-3.6 m: two bays of 3.6 m) to the soil's edge (x = +-12 m) and back, 8.4 + 6 m at
    c_p = 208 m/s; the structure: 2 x 8.4 m."""
    from helpers import sin4_pulse
    rec = sin4_pulse(tmp_path / "pulse.txt", 0.2)
    p = cli(["-options_file", "runs/seismic/building.opts", "-ssi_seismic_record", rec, "-ssi_seismic_window",
             "0,0.4", "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none", "-ssi_seismic_scale", "1",
             "-ssi_seismic_units", "m/s2", "-ssi_t_end", "0.4", "-ssi_memory_limit", "0.001",
             "-ssi_output", str(tmp_path / "d.h5")], check=False)
    lines = [ln for ln in p.stdout.splitlines() if "diffracted" in ln]
    assert p.returncode == 2 and len(lines) == 1, p.stdout[-3000:]
    t, ts = 14.4 / 208.0, 16.8 / 208.0
    assert lines[0].startswith("petsc-ssi: warning: waves from the structure's interface (the seismic wave's scattered "
                               "field) diffracted at the mesh edge"), lines[0]
    assert f"the earliest at t = {t:.4g} s" in lines[0] and f"receiver 0 (6, 0, 0) (t = {t:.4g} s)" in lines[0]
    assert f"receiver 1 (-6, 0, 0) (t = {t:.4g} s)" in lines[0]
    assert f"the structure (interface nodes) (t = {ts:.4g} s)" in lines[0], lines[0]
    assert "load" not in lines[0]


def test_a_footing_s_own_reaction_is_warned(tmp_path):
    """A massless rigid footing (1 m x 1 m) under a vertical wave on a 3 m x 3 m grid, c_p = 42 m/s: the footing
    scatters the wave, so waves from it diffracted at the edge reach the receiver at x = 1 m (path 1 m from
    the footing's side to the edge, 0.5 m back) and the footing itself (1 + 1 m) before t_end; `petsc-ssi
    estimate` says so as the run would."""
    from helpers import sin4_pulse
    rec = sin4_pulse(tmp_path / "pulse.txt", 0.2)
    args = ["-ssi_problem", "bem", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "3,3",
            "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5", "-ssi_disp_group", "box:-0.5,0.5,-0.5,0.5",
            "-ssi_disp_rigid", "massless", "-ssi_dt", "0.01", "-ssi_receivers", "1,0,0", "-ssi_warn_beta", "0",
            "-ssi_seismic", "vertical", "-ssi_seismic_units", "m/s2", "-ssi_seismic_taper", "0",
            "-ssi_seismic_baseline", "none", "-ssi_seismic_record", rec]
    lines = [ln for ln in cli(["estimate"] + args).stdout.splitlines() if "diffracted" in ln]
    assert len(lines) == 1, lines
    t, tf = 1.5 / 42.0, 2.0 / 42.0
    assert lines[0].startswith("petsc-ssi: warning: waves from the footing (the seismic wave's scattered field) "
                               "diffracted"), lines[0]
    assert f"the earliest at t = {t:.4g} s" in lines[0] and f"the footing (t = {tf:.4g} s)" in lines[0], lines[0]
