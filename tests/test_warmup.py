"""No silent minute on the first run (issue 13, item 4): with an empty numba cache a run says in
one line that it is compiling; `python -m petsc_ssi.app.warmup` compiles ahead (make deps runs it), and
afterwards a run does not compile again."""
import os
import subprocess
import sys

from helpers import ROOT

RUN = ["-m", "petsc_ssi", "-ssi_problem", "bem", "-ssi_mesh_size", "4,4", "-ssi_mesh_h", "1", "-ssi_mesh_patch",
       "1,1", "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.005", "-ssi_t_end", "0.01",
       "-ssi_warn_beta", "0", "-ssi_output_overwrite"]


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
