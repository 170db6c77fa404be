#!/usr/bin/env python3
"""An mpirun started by an MPI singleton: ``python jobscripts/singleton_mpirun.py [RUNS]`` initialises MPI in this
process (mpi4py: an MPI singleton), lists the variables MPI added to its C environment (which ``os.environ`` does not
show and ``subprocess`` passes on without ``env=``), and starts ``mpirun -n 2 python -c "print(1)"`` RUNS times (3)
each with: the C environment as inherited; ``petsc_ssi.launch.child_env()``; and ``os.environ`` plus one of the added
variables at a time. Prints the exit statuses and what mpirun wrote (petsc_ssi/launch.py quotes this).
"""
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from mpi4py import MPI  # noqa: E402,F401  (this process is now an MPI singleton)

from petsc_ssi.launch import child_env  # noqa: E402


def c_environ():
    out = subprocess.run(["env", "-0"], capture_output=True).stdout.decode()
    return dict(kv.split("=", 1) for kv in out.split("\0") if "=" in kv)


def mpirun(env, runs):
    cmd = ["mpirun", "--allow-run-as-root", "-n", "2", sys.executable, "-c", "print(1)"]
    res = [subprocess.run(cmd, capture_output=True, text=True, env=env) for _ in range(runs)]
    return [r.returncode for r in res], (res[-1].stdout + res[-1].stderr).strip().replace("\n", " | ")[:120]


def main():
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    full = c_environ()
    added = sorted(k for k in full if os.environ.get(k) != full[k] and k != "_")
    print(f"MPI {MPI.Get_library_version().splitlines()[0]}")
    print(f"variables the singleton added to the C environment ({len(added)}): {' '.join(added)}")
    for label, env in [("inherited C environment (subprocess without env=)", None),
                       ("petsc_ssi.launch.child_env()", child_env())]:
        st, text = mpirun(env, runs)
        print(f"{label:55s} exit statuses {st}  output: {text!r}")
    for k in added:
        env = dict(os.environ)
        env[k] = full[k]
        st, _ = mpirun(env, 1)
        print(f"  os.environ + {(k + '=' + full[k])[:60]:60s} exit status {st[0]}")


if __name__ == "__main__":
    main()
