"""A run that is stopped keeps its results (issue 14): the output is made readable while the run
goes (-ssi_output_flush), a signal (SIGTERM, SIGINT, SIGUSR1) stops the run at the end of the
current step, and a stop writes the results up to the last step with the file attribute
``run_status`` saying how the run ended. Compared bit for bit with an uninterrupted run."""
import json
import signal

import h5py
import numpy as np
import pytest

from helpers import cli, kill_session, signal_midway

pytestmark = pytest.mark.mpi

BEM = ["-ssi_problem", "bem", "-ssi_mesh_size", "4,4", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
       "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.005", "-ssi_receivers", "2,0,0;0,0,0",
       "-ssi_output_stride", "5"]
FEM = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_fem_fixed", "base", "-ssi_fem_load_group", "top",
       "-ssi_fem_load_p0", "1000", "-ssi_dt", "1e-3", "-ssi_t_end", "0.05", "-ssi_receivers", "0,0,0.5",
       "-ssi_output_stride", "10"]


def read(path):
    with h5py.File(path, "r") as f:
        return {"status": str(f.attrs["run_status"]), "t": f["receivers/t"][:], "u": f["receivers/u"][:],
                "time": f["time"][:], "keys": sorted(f.keys())}


@pytest.mark.parametrize("nranks", [1, 2])
def test_flushing_every_step_changes_nothing(nranks, tmp_path):
    """-ssi_output_flush at every step (1e-9 s): the same receivers and snapshots as a run that
    writes only at the end (bit for bit on 1 rank; on 2 ranks two reruns of the same FEM case
    may differ at round-off with MUMPS, issue 14 item 10, so 1e-12 there); run_status 'completed'
    in the file and in the run record."""
    a, b = str(tmp_path / "a.h5"), str(tmp_path / "b.h5")
    cli(FEM + ["-ssi_output", a, "-ssi_output_flush", "0"], nranks=nranks)
    cli(FEM + ["-ssi_output", b, "-ssi_output_flush", "1e-9"], nranks=nranks)
    ra, rb = read(a), read(b)
    assert ra["status"] == rb["status"] == "completed"
    tol = 0.0 if nranks == 1 else 1e-12
    assert np.abs(ra["u"] - rb["u"]).max() <= tol * np.abs(ra["u"]).max()
    assert np.array_equal(ra["time"], rb["time"]) and len(ra["time"]) == 6
    assert ra["keys"] == rb["keys"]
    with h5py.File(a) as fa, h5py.File(b) as fb:
        da, db = fa["displacement_000005"][:], fb["displacement_000005"][:]
        assert np.abs(da - db).max() <= tol * np.abs(da).max()
    assert json.load(open(b.replace(".h5", ".json")))["run_status"] == "completed"


# slow tier: mpirun's SIGUSR1 to two ranks (9-17 s); the one-rank SIGTERM stays in make test
@pytest.mark.parametrize("how", ["SIGTERM one rank", pytest.param("SIGUSR1 mpirun two ranks", marks=pytest.mark.slow)])
def test_a_signal_stops_the_run_and_keeps_its_results(how, tmp_path):
    """A long BEM run is signalled once it has taken 30 steps: it ends at the end of a step with
    one line and exit status 2, and its file holds the steps done, equal bit for bit to the same
    steps of an uninterrupted run, with run_status 'stopped after step n ... by SIG...'."""
    out, log = str(tmp_path / "k.h5"), str(tmp_path / "k.log")
    args = BEM + ["-ssi_t_end", "20", "-ssi_output", out]
    sig = signal.SIGUSR1 if "SIGUSR1" in how else signal.SIGTERM
    rc, text = signal_midway(args, log, 30, lambda p: p.send_signal(sig), nranks=2 if "two" in how else 1)
    assert rc == 2, text[-2000:]
    errs = [ln for ln in text.splitlines() if ln.startswith("petsc-ssi: error: stopped by SIG")]
    assert len(errs) == 1 and "Traceback" not in text, text[-2000:]
    r = read(out)
    n = len(r["t"])                                     # the BEM records steps 1..n
    assert n >= 30 and r["status"].startswith(f"stopped after step {n} of 4000"), r["status"]
    assert ("SIGUSR1" if "SIGUSR1" in how else "SIGTERM") in r["status"]
    ref = str(tmp_path / "ref.h5")
    cli(BEM + ["-ssi_t_end", repr(n * 0.005), "-ssi_output", ref], nranks=2 if "two" in how else 1)
    rr = read(ref)
    assert rr["status"] == "completed" and len(rr["t"]) == n
    assert np.array_equal(r["u"], rr["u"])
    assert np.array_equal(r["time"], rr["time"])


def test_the_guard_stop_keeps_the_results(tmp_path):
    """The plain scheme at beta = 0.05 diverges and the guard stops it (tests/bem/test_guard.py's
    case; exit 2, one line): the file holds every step up to the stop and says why it stopped."""
    out = str(tmp_path / "g.h5")
    dt = 0.05 * 0.5 / 316.0
    r = cli(["-ssi_problem", "bem", "-ssi_mesh_size", "6,6", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
             "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_symmetry", "x=sym,y=sym", "-ssi_dt", repr(dt),
             "-ssi_t_end", repr(700 * dt), "-ssi_receivers", "0,0,0", "-ssi_output_stride", "0", "-ssi_warn_beta", "0",
             "-ssi_scheme", "plain", "-ssi_output", out], check=False, timeout=600)
    assert r.returncode == 2, r.stdout[-2000:] + r.stderr[-2000:]
    err = [ln for ln in r.stderr.splitlines() if ln.startswith("petsc-ssi: error: ")]
    assert len(err) == 1 and "diverging at step" in err[0], r.stdout[-2000:]
    step = int(err[0].split("diverging at step ")[1].split()[0])
    g = read(out)
    assert len(g["t"]) == step                          # every step up to the stop
    assert g["status"].startswith(f"stopped after step {step} of 700: the solution is diverging")


# slow tier: the make-test budget (10-20 s); the default tier's sibling: test_a_signal_stops_the_run_and_keeps_its_results
@pytest.mark.slow
def test_a_signal_stops_a_coupled_contact_run(tmp_path):
    """The coupled block on the half-space with unilateral contact (the foundation lifts off),
    signalled after 20 steps on 2 ranks: both files (soil with the interface series, structure)
    hold the steps done, equal to the same steps of the uninterrupted run (to 1e-6: two runs of this
    contact case with MUMPS on 2 ranks differ by up to 1e-8 in u_f while nodes lift off); a flush
    every step (-ssi_output_flush 1e-9) is on, so the partial writes of the coupled problem are
    exercised every step too."""
    from test_checkpoint import SSI
    ssi = SSI[:]
    ssi[ssi.index("-ssi_output_stride") + 1] = "5"
    out, log = str(tmp_path / "k.h5"), str(tmp_path / "k.log")
    rc, text = signal_midway(ssi + ["-ssi_t_end", "50", "-ssi_output", out, "-ssi_output_flush", "1e-9"], log, 20,
                             lambda p: p.send_signal(signal.SIGUSR1), nranks=2)
    assert rc == 2 and "petsc-ssi: error: stopped by SIGUSR1" in text, text[-2000:]
    r = read(out)
    n = len(r["t"])
    assert n >= 20 and r["status"].startswith(f"stopped after step {n} of 4000"), r["status"]
    ref = str(tmp_path / "ref.h5")
    cli(ssi + ["-ssi_t_end", repr(n * 0.0125), "-ssi_output", ref], nranks=2)
    with h5py.File(out) as f, h5py.File(ref) as g:
        assert int(g["interface/n_open"][:].max()) > 0                      # contact is active
        for k in ("interface/p", "interface/uf", "interface/closed", "receivers/u"):
            a, b = f[k][:], g[k][:]
            assert a.shape == b.shape, k
            assert np.abs(a.astype(float) - b).max() <= 1e-6 * max(np.abs(b).max(), 1e-300), k
    s, sr = out.replace(".h5", "_structure.h5"), ref.replace(".h5", "_structure.h5")
    with h5py.File(s) as f, h5py.File(sr) as g:
        assert str(f.attrs["run_status"]).startswith("stopped after step")
        assert np.abs(f["receivers/u"][:] - g["receivers/u"][:]).max() <= 1e-6 * np.abs(g["receivers/u"][:]).max()


def _start(args, log, nranks):
    """``petsc-ssi args`` (under mpirun for nranks > 1) in a session of its own (killed whole)."""
    import os
    import subprocess
    from helpers import PY, ROOT
    cmd = [PY, "-m", "petsc_ssi"] + list(args) + ["-ssi_monitor", "-ssi_monitor_every", "1"]
    if nranks > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(nranks)] + cmd
    with open(log, "w") as fh:
        return subprocess.Popen(cmd, cwd=ROOT, stdout=fh, stderr=subprocess.STDOUT, start_new_session=True,
                                env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))


def _wait_for(log, text, p, timeout=240):
    import time
    t0 = time.time()
    while time.time() - t0 < timeout and p.poll() is None:
        if text in open(log).read():
            return
        time.sleep(0.05)
    raise AssertionError(f"no '{text}' in the log:\n" + open(log).read()[-2000:])


# slow tier: the two-rank kill (15 s); the one-rank kill stays in make test
@pytest.mark.parametrize("nranks", [1, pytest.param(2, marks=[pytest.mark.slow])])
def test_a_kill_at_random_moments_keeps_the_flushed_steps(nranks, tmp_path):
    """SIGKILL without warning (a lost node; mpirun's kill when the stop outlasts its timeout) to the
    whole job (mpirun and every rank: helpers.kill_session), at 3 moments drawn at random (seeded)
    after the run's 5th step, the output flushed every 0.05 s and a snapshot every 3 steps: each time h5py opens the file, run_status is
    'running', and the steps the last flush recorded are all there, finite, and equal bit for bit
    to the same steps of an uninterrupted run (receivers, times, every snapshot)."""
    import random
    import time
    rng = random.Random(30 + nranks)
    args = BEM + ["-ssi_t_end", "20", "-ssi_output_flush", "0.05", "-ssi_output_stride", "3"]
    got = []
    for k in range(3):
        out, log = str(tmp_path / f"k{k}.h5"), str(tmp_path / f"k{k}.log")
        p = _start(args + ["-ssi_output", out], log, nranks)
        try:
            _wait_for(log, "step 5/", p)
            time.sleep(rng.uniform(0.0, 1.5))
        finally:
            kill_session(p)                          # mpirun and every rank at once
        with h5py.File(out, "r") as f:
            assert str(f.attrs["run_status"]) == "running"
            t, u, times = f["receivers/t"][:], f["receivers/u"][:], f["time"][:]
            snaps = [f[f"displacement_{j:06d}"][:] for j in range(len(times))]
        n = len(t)
        assert n >= 1 and u.shape[0] == n and np.isfinite(u).all()      # the first step flushed (setup > 0.05 s)
        assert np.allclose(t, 0.005 * np.arange(1, n + 1), rtol=1e-12, atol=0)
        assert len(times) >= n // 3 and all(np.isfinite(s).all() for s in snaps)
        got.append((n, u, times, snaps))
    nmax = max(g[0] for g in got)
    ref = str(tmp_path / "ref.h5")
    cli(BEM + ["-ssi_t_end", repr(nmax * 0.005), "-ssi_output_stride", "3", "-ssi_output", ref], nranks=nranks)
    with h5py.File(ref, "r") as f:
        ru, rtimes = f["receivers/u"][:], f["time"][:]
        for n, u, times, snaps in got:
            assert np.array_equal(u, ru[:n]) and np.array_equal(times, rtimes[:len(times)])
            for j, s in enumerate(snaps):
                assert np.array_equal(s, f[f"displacement_{j:06d}"][:]), j
    assert len({g[0] for g in got}) > 1                  # the kills came at different steps
