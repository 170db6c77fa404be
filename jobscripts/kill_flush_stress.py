"""How often a SIGKILL leaves the output unreadable (issue 30): a writer that does nothing but what a
run's output does between steps (a snapshot through PETSc's HDF5 viewer, then io.output.Output.flush:
the viewer closed, rank 0's staged rewrite of time, receivers and a group, the viewer reopened),
in a loop, is killed whole (SIGKILL to every process of its session, mpirun and the ranks at once)
at a random moment, and the file is then opened with h5py and every dataset of the last flush read. Repeated KILLS times; prints the failures
(the exception of each) and their count (an unreadable file is kept as k<N>-bad<i>.h5, its parts
as k<N>-bad<i>.parts: the links inside it name k<N>.parts, renamed back to read it). Because the writer only writes, the kills land in the
write windows far more often than in a real run's.

  python jobscripts/kill_flush_stress.py [KILLS] [NRANKS] [SEED]     (default 200 1 1)
  (the writer: python jobscripts/kill_flush_stress.py --writer PATH)
"""
import os
import random
import signal
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests"))
from helpers import kill_session  # noqa: E402  (SIGKILL to mpirun and every rank at once)
from petsc_ssi.launch import child_env  # noqa: E402


def writer(path):
    sys.path.insert(0, ROOT)
    from petsc_ssi.petsc import init
    PETSc = init(sys.argv[:1])
    from petsc_ssi.io.output import Output
    comm = PETSc.COMM_WORLD
    out = Output(path, comm)
    n = 400
    x = PETSc.Vec().createMPI(3 * n, bsize=3, comm=comm)
    x.set(1.0)
    out.write_mesh(x, np.zeros((n // 4, 4), np.int64) if comm.rank == 0 else None, "quad4")
    R = 8
    for k in range(1, 100000):
        x.set(float(k))
        out.write_fields(k * 1e-3, {"displacement": x})
        t = 1e-3 * np.arange(1, k + 1)
        u = np.repeat(t[:, None, None], R * 3, axis=1).reshape(k, R, 3)
        rec = {"points": np.zeros((R, 3)), "t": t, "u": u} if comm.rank == 0 else None
        grp = {"interface": {"force": np.outer(t, np.ones(6))}} if comm.rank == 0 else None
        out.flush(receivers=rec, groups=grp, attrs={"steps_done": k})
        if comm.rank == 0:
            print("flushed", k, flush=True)


def check(path):
    """Raise if the file is not readable as a flush left it."""
    import h5py
    with h5py.File(path, "r") as f:
        assert str(f.attrs["run_status"]) == "running"
        k = int(f.attrs["steps_done"])
        t, u = f["receivers/t"][:], f["receivers/u"][:]
        force, times = f["interface/force"][:], f["time"][:]
        assert len(t) == k and u.shape == (k, 8, 3) and force.shape == (k, 6), (k, len(t), u.shape)
        assert np.array_equal(u[:, 0, 0], t) and np.array_equal(force[:, 0], t)
        assert len(times) >= k
        for j in range(len(times)):
            d = f[f"displacement_{j:06d}"][:]
            assert np.all(d == j + 1), j
    return k


def main():
    kills = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    nranks = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    rng = random.Random(int(sys.argv[3]) if len(sys.argv) > 3 else 1)
    tmp = os.path.join(ROOT, "out", "kill_stress")
    os.makedirs(tmp, exist_ok=True)
    bad = []
    steps = []
    for i in range(kills):
        path = os.path.join(tmp, f"k{nranks}.h5")
        for f in (path, path[:-3] + ".xmf"):
            if os.path.exists(f):
                os.remove(f)
        cmd = [sys.executable, os.path.abspath(__file__), "--writer", path]
        if nranks > 1:
            cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(nranks)] + cmd
        log = os.path.join(tmp, "writer.log")
        with open(log, "w") as fh:
            p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=fh, start_new_session=True, text=True,
                                 env=child_env(OPENBLAS_NUM_THREADS="1"))
            first = p.stdout.readline()                # the first flush is done
            if first.startswith("flushed"):
                time.sleep(rng.uniform(0.0, 1.0))
            kill_session(p)
            p.stdout.close()
        if not first.startswith("flushed"):
            raise SystemExit("the writer did not start: " + open(log).read()[-2000:])
        try:
            steps.append(check(path))
        except Exception as e:                          # noqa: BLE001 (every failure is counted)
            import traceback
            where = [ln for ln in traceback.format_exc().splitlines() if "kill_flush_stress" in ln or "f[" in ln]
            bad.append(f"kill {i}: {type(e).__name__}: {(str(e).splitlines() or [''])[0][:200]} ({'; '.join(w.strip() for w in where[-2:])})")
            os.replace(path, path[:-3] + f"-bad{i}.h5")
            if os.path.isdir(path[:-3] + ".parts"):              # its parts, where its links point
                os.replace(path[:-3] + ".parts", path[:-3] + f"-bad{i}.parts")
            print(bad[-1], flush=True)
    print(f"{kills} kills at {nranks} rank(s): {len(bad)} unreadable "
          f"(flushes done before a kill: {min(steps, default=0)}..{max(steps, default=0)})")
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--writer":
        writer(sys.argv[2])
    else:
        sys.exit(main())
