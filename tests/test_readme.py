"""The README's "Running" block runs in order as written (issue 30, item 4: its second command
used to fail, the first having written the output it names).

The block's commands run one after the other in a scratch directory that links the repository's
`runs` and `meshes` (so `out/` starts empty, as in a fresh clone), with `.venv/bin/` the venv of
this interpreter when the checkout has none of its own; mpirun gets --oversubscribe (a busy machine
may offer fewer slots), nothing else is changed."""
import os
import re
import subprocess
import sys

from helpers import ROOT
import pytest

pytestmark = pytest.mark.mpi


def running_block():
    """The commands of the first ```sh block under '## Running' (comments and blank lines dropped)."""
    text = open(os.path.join(ROOT, "README.md")).read()
    sec = text[text.index("\n## Running\n"):]
    block = re.search(r"```sh\n(.*?)```", sec, re.S).group(1)
    cmds = []
    for line in block.splitlines():
        line = line.split("  #")[0].strip() if not line.lstrip().startswith("#") else ""
        if line:
            cmds.append(line)
    return cmds


def test_readme_running_block_runs_in_order(tmp_path):
    cmds = running_block()
    assert len(cmds) >= 5 and cmds[0].startswith(".venv/bin/petsc-ssi")
    for d in ("runs", "meshes"):
        os.symlink(os.path.join(ROOT, d), tmp_path / d)
    venv = os.path.join(ROOT, ".venv", "bin")
    if not os.path.isdir(venv):
        venv = os.path.dirname(sys.executable)
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    for cmd in cmds:
        run = cmd.replace(".venv/bin/", venv + "/").replace("mpirun --allow-run-as-root",
                                                           "mpirun --allow-run-as-root --oversubscribe")
        p = subprocess.run(["bash", "-c", run], cwd=tmp_path, capture_output=True, text=True, timeout=600, env=env)
        assert p.returncode == 0, f"README command failed: {cmd}\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}"
    out = tmp_path / "out"
    for f in ("pekeris-small.h5", "pekeris-small-n2.h5", "receivers.csv", "spectrum.csv", "block-modes.h5"):
        assert (out / f).stat().st_size > 0, f
    rows = (out / "receivers.csv").read_text().splitlines()
    assert rows[0] == "receiver,x_m,y_m,z_m,t_s,ux_m,uy_m,uz_m" and len(rows) > 10
