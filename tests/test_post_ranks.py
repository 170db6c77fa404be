"""Nothing lost, nothing silent, round three (issue 44): post.

  * under mpirun every rank exits with rank 0's status (before: rank 1 only opened the file and
    exited 0 when rank 0 refused an argument);
  * ``post X.h5 --receivers --csv X.h5`` is refused (before: X.h5 was cut to 0 bytes);
  * ``post --info`` on an output whose part is missing says so (before: it listed snapshots it
    cannot read).
"""
import os
import subprocess
import sys

from helpers import cli, ROOT
from test_integrity import SMALL
import pytest

pytestmark = pytest.mark.mpi


def test_post_refuses_to_write_its_input_and_every_rank_says_2(tmp_path):
    out = str(tmp_path / "o.h5")
    cli(SMALL + ["-ssi_output", out])
    keep = open(out, "rb").read()
    r = cli(["post", out, "--receivers", "--csv", out], check=False)
    assert r.returncode == 2 and f"--csv {out}: is the input file" in r.stderr, r.stderr
    assert open(out, "rb").read() == keep
    code = ("import sys; from mpi4py import MPI; from petsc_ssi.app.cli import main; "
            f"s = main(['petsc-ssi', 'post', {out!r}, '--receivers', '--csv', {out!r}]); "
            "print('rank', MPI.COMM_WORLD.Get_rank(), 'status', s, flush=True)")
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    p = subprocess.run(["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "2", sys.executable, "-c", code],
                       cwd=ROOT, capture_output=True, text=True, timeout=300, env=env)
    assert "rank 0 status 2" in p.stdout and "rank 1 status 2" in p.stdout, (p.returncode, p.stdout + p.stderr[-2000:])
    assert open(out, "rb").read() == keep


def test_post_info_names_a_missing_part(tmp_path):
    out = str(tmp_path / "r.h5")
    cli(SMALL + ["-ssi_output", out, "-ssi_output_merge", "0", "-ssi_output_flush", "0"])
    part = sorted(os.listdir(tmp_path / "r.parts"))[0]
    os.remove(tmp_path / "r.parts" / part)
    r = cli(["post", out, "--info"], check=False)
    assert r.returncode == 2 and f"{out} links its dataset" in r.stderr and "which is missing" in r.stderr, \
        r.stdout + r.stderr
