"""No silent minute on the first run (issue 13, item 4): with an empty numba cache a run says in
one line that it is compiling; `python -m petsc_ssi.app.warmup` compiles ahead (make deps runs it), and
afterwards a run does not compile again."""
import os
import subprocess
import sys

from helpers import ROOT
import pytest

pytestmark = pytest.mark.mpi

RUN = ["-m", "petsc_ssi", "-ssi_problem", "bem", "-ssi_mesh_size", "4,4", "-ssi_mesh_h", "1", "-ssi_mesh_patch",
       "1,1", "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.005", "-ssi_t_end", "0.01",
       "-ssi_warn_beta", "0", "-ssi_output_overwrite"]


# slow tier: a cold numba cache compiled from scratch (47 s): make deps warms the cache CI uses, and
#  test_warmup's other tests check the warm state
@pytest.mark.slow
def test_cold_cache_is_announced_then_the_warm_up_covers_every_run(tmp_path):
    """One compile: a run with an empty cache announces it (one line); the warm-up then finds the
    cache only partly warm (a run compiled what it met), loads and compiles the rest, and marks it;
    a second warm-up finds it warm. In that cache, new processes running the time-blocked BEM march
    (block-sparse lags, panels and the per-step rest), the same with single-precision far lags, and
    a coupled run with contact compile nothing: every kernel signature these runs meet is in the
    warm-up (the count: numba's compile_extra, patched in the process)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), OPENBLAS_NUM_THREADS="1")
    py = lambda args: subprocess.run([sys.executable] + args, cwd=ROOT, env=env, capture_output=True,  # noqa: E731
                                     text=True, timeout=600)
    r = py(RUN + ["-ssi_output", str(tmp_path / "a.h5")])
    lines = [ln for ln in r.stdout.splitlines() if "compiling the BEM kernels" in ln]
    assert r.returncode == 0 and len(lines) == 1, r.stdout
    w = py(["-m", "petsc_ssi.app.warmup"])
    assert w.returncode == 0 and "[warmup] numba cache partly warm" in w.stdout and "[warmup] done" in w.stdout, \
        w.stdout + w.stderr
    w = py(["-m", "petsc_ssi.app.warmup"])
    assert w.returncode == 0 and "[warmup] numba cache is warm" in w.stdout, w.stdout + w.stderr
    runs = {"bem-blocked": RUN[2:] + ["-ssi_lag_storage", "sparse", "-ssi_history_block", "2"],
            "bem-single": RUN[2:] + ["-ssi_lag_single_from", "3", "-ssi_t_end", "0.03", "-ssi_history_block", "3"],
            "ssi-contact": SSI_RUN}
    for what, args in runs.items():
        p = py(["-c", PROBE_RUN] + args + ["-ssi_output", str(tmp_path / f"{what}.h5")])
        assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
        line = [ln for ln in p.stdout.splitlines() if ln.startswith("COMPILED")]
        assert line and line[0].startswith("COMPILED 0 "), (what, line or p.stdout[-3000:])
    r = py(RUN + ["-ssi_output", str(tmp_path / "b.h5")])
    assert r.returncode == 0 and "compiling" not in r.stdout, r.stdout


COUNT = """
import sys
import petsc_ssi  # first: it points NUMBA_CACHE_DIR at the cache of these sources
import numba.core.compiler as c
calls = []
orig = c.compile_extra
def counted(*a, **k):
    calls.append(getattr(a[2], '__qualname__', repr(a[2])) if len(a) > 2 else '?')
    return orig(*a, **k)
c.compile_extra = counted
"""
PROBE = COUNT + """
from petsc_ssi.bem.lagset import load_kernels
load_kernels()
print('COMPILED', len(calls), calls)
"""


def test_warm_run_compiles_nothing():
    """With a warm cache, loading the BEM kernels (a tiny assembly: the element cache's typed Dict,
    every assembly kernel) compiles nothing in a new process: numba.typed.Dict made or measured from
    Python compiles its helpers in every process, uncached (0.3-0.5 s per rank per run), so the
    assembly makes and measures it in compiled code. The first process warms the cache if needed."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    for _ in range(2):
        r = subprocess.run([sys.executable, "-c", PROBE], cwd=ROOT, env=env, capture_output=True, text=True,
                           timeout=600)
        assert r.returncode == 0, r.stdout + r.stderr
    line = [ln for ln in r.stdout.splitlines() if ln.startswith("COMPILED")]
    assert line and line[0].startswith("COMPILED 0 "), r.stdout


PROBE_RUN = COUNT + """
from petsc_ssi.app.cli import main
rc = main(['petsc-ssi'] + sys.argv[1:])
print('COMPILED', len(calls), calls)
sys.exit(rc)
"""

SSI_RUN = ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "2,2",
           "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5", "-ssi_fem_box_cells", "4,4,1", "-ssi_fem_box_size",
           "1,1,0.25", "-ssi_fem_box_origin", "-0.5,-0.5,0", "-ssi_fem_E", "3e8", "-ssi_fem_rho", "2000",
           "-ssi_dt", "0.0125", "-ssi_t_end", "0.1", "-ssi_fem_load_group", "top", "-ssi_fem_load_p0", "1000",
           "-ssi_fem_load_history", "box", "-ssi_fem_load_t0", "0.05", "-ssi_contact", "unilateral",
           "-ssi_warn_beta", "0", "-ssi_output_overwrite"]


def test_cache_dir_is_not_nested_in_child_processes(tmp_path):
    """A process that imports petsc_ssi points NUMBA_CACHE_DIR at <base>/<hash of the sources>; its
    child processes (mpirun, the tests' subprocesses) inherit that and must keep it, not nest a
    second <hash> under it (they then compiled every kernel again into a cache of their own)."""
    code = "import os, petsc_ssi; print('DIR', os.environ['NUMBA_CACHE_DIR'])"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "base"))
    first = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True)
    d1 = first.stdout.split("DIR ", 1)[1].strip()
    assert os.path.dirname(d1) == str(tmp_path / "base"), d1
    env["NUMBA_CACHE_DIR"] = d1
    second = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True)
    assert second.stdout.split("DIR ", 1)[1].strip() == d1, second.stdout


STATUS = "import petsc_ssi; print('STATUS', *petsc_ssi.numba_cache_status(), petsc_ssi.checkout_key())"


def _second_checkout(tmp_path):
    """A second checkout of the same sources: the package copied (new path, new mtimes, as a git
    worktree or clone gives); returns (its root, clean(cache, key): remove what it left in the
    shared cache, numba's sub-directory for its path and its warm-up mark)."""
    import hashlib
    import shutil
    root = tmp_path / "clone"
    root.mkdir()
    shutil.copytree(os.path.join(ROOT, "petsc_ssi"), root / "petsc_ssi",
                    ignore=shutil.ignore_patterns("__pycache__"), copy_function=shutil.copy)

    def clean(cache, key):
        d = str(root / "petsc_ssi" / "bem")                     # numba's sub-directory for that path
        shutil.rmtree(os.path.join(cache, "bem_" + hashlib.sha1(d.encode()).hexdigest()), ignore_errors=True)
        if os.path.exists(os.path.join(cache, "warmup-done-" + key)):
            os.remove(os.path.join(cache, "warmup-done-" + key))
    return root, clean


def _status(cwd, env):
    r = subprocess.run([sys.executable, "-c", STATUS + "; import os; print('DIR', os.environ['NUMBA_CACHE_DIR'])"],
                       cwd=str(cwd), env=dict(env, PYTHONPATH=str(cwd)), capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    line = [ln.split() for ln in r.stdout.splitlines() if ln.startswith("STATUS")][0]
    cache = [ln.split(None, 1)[1] for ln in r.stdout.splitlines() if ln.startswith("DIR")][0]
    return int(line[1]), int(line[2]), line[3], cache


def test_a_second_checkout_is_not_taken_for_warm(tmp_path):
    """Issue 30: numba files its cache index under the source file's path and stamps it with the
    file's mtime and size, so a second checkout of the same sources (same hash, same cache
    directory) loads nothing the first one compiled. The warm check asks numba's index for THIS
    checkout: warm in the repository (warmed first if needed), cold in a copy of the package, and
    the checkout keys (the warm-up's mark) differ."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    fresh, total, key, cache = _status(ROOT, env)
    if not fresh:                                        # a cold cache: warm this checkout first
        subprocess.run([sys.executable, "-m", "petsc_ssi.app.warmup"], cwd=ROOT, env=env, check=True,
                       capture_output=True, timeout=900)
        fresh, total, key, cache = _status(ROOT, env)
    assert total >= 20 and fresh > 0, (fresh, total)
    clone, clean = _second_checkout(tmp_path)
    f2, t2, key2, cache2 = _status(clone, env)
    try:
        assert cache2 == cache                           # the same sources: the same cache directory ...
        assert t2 == total and f2 == 0                   # ... and none of its kernels for this checkout
        assert key2 != key
    finally:
        clean(cache2, key2)


# slow tier: a second checkout compiles every kernel once (30-80 s, 279 s on the loaded machine): the cheap
#  test_a_second_checkout_is_not_taken_for_warm checks the per-checkout warm check it rests on
@pytest.mark.slow
def test_a_second_checkout_compiles_once_and_says_so(tmp_path):
    """A second checkout whose first run compiles says so in one line (this checkout's path in it);
    its warm-up then compiles the rest and marks this checkout warm, and a new process's run there
    compiles nothing (numba's compile_extra counted, as above), though the repository's own
    checkout had filled the same cache directory before."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    clone, clean = _second_checkout(tmp_path)
    cenv = dict(env, PYTHONPATH=str(clone))
    py = lambda args: subprocess.run([sys.executable] + args, cwd=str(clone), env=cenv,  # noqa: E731
                                     capture_output=True, text=True, timeout=900)
    _, _, key, cache = _status(clone, env)
    try:
        r = py(RUN + ["-ssi_output", str(tmp_path / "a.h5")])
        lines = [ln for ln in r.stdout.splitlines() if "compiling the BEM kernels" in ln]
        assert r.returncode == 0 and len(lines) == 1 and "first run of this checkout" in lines[0], r.stdout[-3000:]
        assert str(clone / "petsc_ssi") in lines[0]
        w = py(["-m", "petsc_ssi.app.warmup"])
        assert w.returncode == 0 and "[warmup] done" in w.stdout, w.stdout + w.stderr
        w = py(["-m", "petsc_ssi.app.warmup"])
        assert "[warmup] numba cache is warm" in w.stdout and str(clone / "petsc_ssi") in w.stdout, w.stdout
        p = py(["-c", PROBE_RUN] + RUN[2:] + ["-ssi_lag_storage", "sparse", "-ssi_history_block", "2",
                                              "-ssi_output", str(tmp_path / "b.h5")])
        assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
        line = [ln for ln in p.stdout.splitlines() if ln.startswith("COMPILED")]
        assert line and line[0].startswith("COMPILED 0 "), line or p.stdout[-3000:]
        assert "compiling" not in p.stdout
    finally:
        clean(cache, key)
