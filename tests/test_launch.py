"""The processes petsc_ssi's scripts start: an MPI singleton's variables stay behind (petsc_ssi/launch.py).

A process that has initialised MPI without mpirun passes OMPI_MCA_ess=singleton on to the children it starts without
``env=``, and OpenMPI 4.1's mpirun started so exits 1 without a word: the slow tier's soft-layer test failed so
whenever an earlier test of the same pytest process had initialised MPI (``python jobscripts/singleton_mpirun.py``).
"""
import ast
import os
import re
import shutil
import subprocess
import sys

import pytest

from petsc_ssi.launch import child_env

pytestmark = pytest.mark.mpi

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_child_env_drops_a_singletons_variables_and_keeps_the_users():
    base = {"PATH": "/usr/bin", "OMPI_MCA_ess": "singleton", "OMPI_MCA_orte_launch": "1", "OMPI_MCA_pmix": "^s1",
            "PMIX_SERVER_URI4": "1.0;tcp4://127.0.0.1:1", "PMIX_RANK": "0", "OMPI_MCA_btl": "self,vader",
            "OMPI_ALLOW_RUN_AS_ROOT": "1"}
    env = child_env(base, OPENBLAS_NUM_THREADS=1)
    assert env == {"PATH": "/usr/bin", "OMPI_MCA_btl": "self,vader", "OMPI_ALLOW_RUN_AS_ROOT": "1",
                   "OPENBLAS_NUM_THREADS": "1"}
    # without the singleton's mark nothing goes (a process started by mpirun keeps what mpirun gave it)
    ranked = {"PMIX_RANK": "1", "OMPI_COMM_WORLD_RANK": "1", "OMPI_MCA_ess": "pmi"}
    assert child_env(ranked) == ranked
    assert child_env(base) is not base and "OMPI_MCA_ess" in base


# Children that need no environment of their own: the first-touch jobscripts' numpy children, git; and the script
# that shows what an inherited C environment does (its `env` child reads it)
NO_ENV = {"jobscripts/first_touch.py", "jobscripts/first_touch_overlap.py", "jobscripts/first_touch_pair.py",
          "jobscripts/first_touch_sizes.py", "petsc_ssi/io/output.py", "jobscripts/singleton_mpirun.py"}


def test_the_package_and_its_scripts_give_every_child_an_environment():
    """Every subprocess call in petsc_ssi/, runs/ and jobscripts/ passes env= (child_env() or a dict of
    os.environ, which does not hold the variables MPI set in the C environment), but for the files in NO_ENV."""
    missing, calls = [], 0
    for top in ("petsc_ssi", "runs", "jobscripts"):
        for d, _, files in os.walk(os.path.join(ROOT, top)):
            for f in files:
                if not f.endswith(".py"):
                    continue
                path = os.path.join(d, f)
                rel = os.path.relpath(path, ROOT)
                for node in ast.walk(ast.parse(open(path).read())):
                    if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                            and isinstance(node.func.value, ast.Name) and node.func.value.id == "subprocess"
                            and node.func.attr in ("run", "Popen", "call", "check_call", "check_output")):
                        calls += 1
                        if rel not in NO_ENV and not any(k.arg == "env" for k in node.keywords):
                            missing.append(f"{rel}:{node.lineno}")
    assert calls > 40, calls
    assert not missing, "subprocess calls without env= (petsc_ssi.launch.child_env()): " + ", ".join(missing)


CHILD = r"""
import subprocess, sys
from mpi4py import MPI
from petsc_ssi.launch import child_env
out = subprocess.run(["env", "-0"], capture_output=True).stdout.decode()
inherited = dict(kv.split("=", 1) for kv in out.split("\0") if "=" in kv)    # the C environment, singleton's included
print("SINGLETON", inherited.get("OMPI_MCA_ess") == "singleton")
cmd = ["mpirun", "--allow-run-as-root", "-n", "2", sys.executable, "-c",
       "from mpi4py import MPI; print('RANK', MPI.COMM_WORLD.rank, MPI.COMM_WORLD.size)"]
for label, env in (("CLEAN", child_env(inherited)), ("INHERITED", None)):
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=env)
    print(label, p.returncode, " ".join(p.stdout.split()), "|", p.stderr.strip().replace("\n", " / ")[-400:])
"""


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="no mpirun")
def test_an_mpi_singleton_starts_mpirun_with_child_env():
    r = subprocess.run([sys.executable, "-c", CHILD], cwd=ROOT, capture_output=True, text=True, timeout=300,
                       env=child_env())
    assert r.returncode == 0, r.stderr[-2000:]
    lines = {ln.split()[0]: ln for ln in r.stdout.splitlines() if ln}
    if "True" not in lines["SINGLETON"]:
        pytest.skip("this MPI's singleton sets no OMPI_MCA_ess=singleton: " + lines["SINGLETON"])
    status, out = lines["CLEAN"].split("|")[0].split(None, 2)[1:]
    assert status == "0" and sorted(re.findall(r"RANK (\d) (\d)", out)) == [("0", "2"), ("1", "2")], lines["CLEAN"]
    # inherited, the suite's mpirun (tests/bin/mpirun) names the cause before OpenMPI's mpirun fails without a word
    if os.environ.get("PETSC_SSI_REAL_MPIRUN"):
        assert "OMPI_MCA_ess=singleton in the environment" in lines["INHERITED"], lines["INHERITED"]
