"""runs/seismic/report.py writes its figures into the run's directory, never over the PNGs kept in
the repository beside it (issue 44: run.sh's report replaced runs/seismic/roof.png)."""
import hashlib
import importlib.util
import os

import h5py
import numpy as np

from helpers import ROOT
import pytest

pytestmark = pytest.mark.run


def _digest(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def test_seismic_report_writes_into_the_run_directory(tmp_path, capsys):
    t = np.linspace(0.0, 1.0, 101)
    a = np.zeros((t.size, 1, 3))
    a[:, 0, 0] = np.sin(2 * np.pi * 2 * t)
    for name, key in (("building_structure.h5", "acceleration"), ("fixed-base.h5", "absolute_acceleration"),
                      ("building.h5", "u")):
        with h5py.File(tmp_path / name, "w") as f:
            f["receivers/t"], f[f"receivers/{key}"] = t, a
            if name == "building.h5":
                f["seismic/x_pga"] = 1.0
    kept = os.path.join(ROOT, "runs", "seismic", "roof.png")
    before = _digest(kept)
    spec = importlib.util.spec_from_file_location("seismic_report", os.path.join(ROOT, "runs", "seismic", "report.py"))
    report = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(report)
    report.main(str(tmp_path))
    assert os.path.getsize(tmp_path / "roof.png") > 1000
    assert _digest(kept) == before


def test_history_lanes_script_equals_the_matmul_products():
    """jobscripts/history_lanes.py (the README's measurement of the lane products): every lane width's
    block, step and interpolating products equal the matmul ones to round-off on a small slab that is not a
    whole number of groups."""
    import re
    import subprocess
    import sys
    r = subprocess.run([sys.executable, os.path.join(ROOT, "jobscripts", "history_lanes.py"), "--slab", "70",
                        "--lags", "6", "--block", "4", "--anchors", "5", "--states", "40", "--own", "2",
                        "--fw", "16,64", "--repeat", "1"],
                       capture_output=True, text=True, timeout=600, env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert r.returncode == 0, r.stderr[-2000:]
    rows = [ln for ln in r.stdout.splitlines() if re.match(r"\| 0 \| lanes", ln)]
    assert len(rows) == 2, r.stdout
    for ln in rows:
        assert float(ln.strip("|").split("|")[-1]) <= 1e-13, ln


@pytest.mark.parametrize("lags,block", [(11, 4), (5, 8), (16, 4)])
def test_history_time_fft_equals_the_direct_products(lags, block):
    """jobscripts/history_time_fft.py (the README's measurement of a fast convolution in time): its
    overlap-save blocks give the direct block products (``toeplitz.history_products``) to round-off, for
    D a multiple of b, D < b and D not a multiple of b, on a small slab."""
    import re
    import subprocess
    import sys
    r = subprocess.run([sys.executable, os.path.join(ROOT, "jobscripts", "history_time_fft.py"), "--slab", "40",
                        "--lags", str(lags), "--block", str(block), "--repeat", "1"],
                       capture_output=True, text=True, timeout=600, env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert r.returncode == 0, r.stderr[-2000:]
    row = [ln for ln in r.stdout.splitlines() if re.match(r"\| 0 \|", ln)]
    assert len(row) == 1, r.stdout
    err = float(row[0].strip("|").split("|")[-1])
    assert err <= 1e-13, row[0]


def test_building_soil_exact_reference_is_the_box_of_the_step_solution():
    """jobscripts/building_soil_exact.py's reference: the 25 ms box of Lamb's step solution over the square. Before
    the box ends it is the step solution itself; long after every arrival it returns to zero (the two steps'
    static offsets cancel), to 1e-3 of its peak."""
    import sys
    sys.path.insert(0, os.path.join(ROOT, "jobscripts"))
    import building_soil_exact as bse
    from petsc_ssi.analytic.pekeris import patch_displacement
    t = np.linspace(0.0, 0.024, 25)
    ux, uz = bse.exact(10.0, 0.0, t, 14.5, 0.5, 1000.0)
    sx, _, sz = patch_displacement(10.0 - 14.5, 0.0, t, 0.5, 0.5, 1000.0, bse.CS, bse.CP, bse.RHO)
    assert np.array_equal(ux, sx) and np.array_equal(uz, sz)
    tt = np.linspace(0.0, 3.0, 1201)
    ux, uz = bse.exact(10.0, 0.0, tt, 14.5, 0.5, 1000.0)
    peak = np.abs(uz).max()
    assert peak > 0 and np.abs(uz[tt > 2.5]).max() < 1e-3 * peak and np.abs(ux[tt > 2.5]).max() < 1e-3 * peak


def test_building_soil_exact_table_reference_is_the_convolution_with_the_pulse():
    """jobscripts/building_soil_exact.py's reference for the tabulated 0.1 s Hann pulse (``exact_table``: the
    table's ramps' responses summed): against a direct convolution of Lamb's step solution with the analytic
    pulse's rate, u(t) = int_0^T U(t - tau) p'(tau) dtau by 400-point Gauss-Legendre, to 1e-3 of the peak (the
    table is linear between rows 1 ms apart: its difference to sin^2 is O(1e-4); the step solution's kinks at
    the arrivals make the Gauss rule converge slowly, hence its 400 points; `pytest -s` prints the differences).
    At every third of the run's 5 ms steps (20 times, the peak's among them):
    each time costs 400 evaluations of the patch's step solution."""
    import sys
    sys.path.insert(0, os.path.join(ROOT, "jobscripts"))
    import building_soil_exact as bse
    from petsc_ssi.analytic.pekeris import patch_displacement
    t = np.arange(0.0, 0.3, 0.015)
    ux, uz = bse.exact_table(10.0, 0.0, t, 14.5, 0.5, 1000.0)
    x, w = np.polynomial.legendre.leggauss(400)
    tau, w = 0.5 * bse.HANN_T * (x + 1.0), 0.5 * bse.HANN_T * w
    rate = (np.pi / bse.HANN_T) * np.sin(2.0 * np.pi * tau / bse.HANN_T)          # d/dt sin^2(pi t / T)
    ref = sum(wk * rk * np.array(patch_displacement(10.0 - 14.5, 0.0, np.maximum(t - tk, 0.0), 0.5, 0.5, 1000.0,
                                                     bse.CS, bse.CP, bse.RHO)) for tk, wk, rk in zip(tau, w, rate))
    for name, got, want in (("u_x", ux, ref[0]), ("u_z", uz, ref[2])):
        peak = np.abs(want).max()
        print(f"Hann table against the direct convolution, {name}: {np.abs(got - want).max() / peak:.3g} of the peak")
        assert peak > 0 and np.abs(got - want).max() <= 1e-3 * peak, np.abs(got - want).max() / peak


def test_toeplitz_sweep_script_runs_a_case(tmp_path):
    """jobscripts/toeplitz_sweep.py (the general cases of the toeplitz store against the dense store, a benchmark
    of its own): its cheapest case (1 x 0.9375 m cells, a load at the grid's edge, one rank) runs, its CSV row
    says the stores agree to 1e-12, and it exits 0; a mismatch is its exit status 1 (its ``compare`` on two
    different runs)."""
    import csv
    import subprocess
    import sys
    r = subprocess.run([sys.executable, os.path.join(ROOT, "jobscripts", "toeplitz_sweep.py"), str(tmp_path), "0"],
                       cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    rows = list(csv.reader(open(tmp_path / "toeplitz_sweep.csv")))
    assert len(rows) == 2 and rows[1][0].startswith("1 x 0.9375 m cells") and int(rows[1][3]) >= 3, rows
    assert float(rows[1][4]) <= 1e-12, rows
    sys.path.insert(0, os.path.join(ROOT, "jobscripts"))
    from toeplitz_sweep import compare
    with h5py.File(tmp_path / "case0-dense.h5") as f, h5py.File(tmp_path / "moved.h5", "w") as g:
        for k in f:
            f.copy(k, g)
        d = g["receivers/u"]
        d[...] = d[...] * (1 + 1e-8)
    assert compare(str(tmp_path / "case0-dense.h5"), str(tmp_path / "moved.h5"))[1] > 1e-10
