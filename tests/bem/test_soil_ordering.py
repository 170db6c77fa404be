"""MUMPS's ordering of the soil's step matrix (petsc.SOIL_MUMPS): PETSc hands MUMPS the step matrix with
its block size 3 and ICNTL(15) = -3 (the graph of the nodes), whose 3 x 3 blocks are half empty on a flat
surface; the defaults order the DOFs' own graph with AMD (ICNTL(15) 0, ICNTL(7) 0), which fills less. On a
16 m x 16 m grid of 1 m elements: fewer factor entries than the node graph with PORD (MUMPS's automatic
choice without METIS or SCOTCH; 3.69 M against 4.71 M seen), the same answer to 1e-12, and a user's
explicit options win over the defaults; the run's log line gives the factors' size and ordering."""
import os
import re
import sys

import pytest

from helpers import cli

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_history_block import same  # noqa: E402

pytestmark = pytest.mark.run

GRID = ["-ssi_problem", "bem", "-ssi_mesh_size", "16,16", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
        "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.0025", "-ssi_t_end", "0.03",
        "-ssi_receivers", "3,0,0;0,0,0", "-ssi_warn_beta", "0", "-ssi_bem_ksp_view", "::ascii_info_detail",
        "-ssi_step_mirror", "off"]       # (the step matrix as it is: its mirror blocks, bem/mirror.py, fill less still)


def _mumps(out):
    get = lambda pat: int(re.search(pat, out).group(1))    # noqa: E731
    return (get(r"ICNTL\(7\) \(sequential matrix ordering\):\s*(-?\d+)"),
            get(r"ICNTL\(15\) \(compression of the input matrix\):\s*(-?\d+)"),
            get(r"INFOG\(29\) \(after factorization: effective number of entries in the factors[^:]*:\s*(\d+)"))


def test_the_soils_ordering_fills_less_and_a_users_choice_wins(tmp_path):
    a, b = str(tmp_path / "default.h5"), str(tmp_path / "blocks.h5")
    out = cli(GRID + ["-ssi_output", a]).stdout
    o7, o15, n_default = _mumps(out)
    assert (o7, o15) == (0, 0)
    # the run's own line (petsc.mumps_factor_info) says the factors' size MUMPS reports and its ordering
    line = re.search(r"\[ssi\] step matrix: 3267 DOFs, MUMPS LU, ([\d.]+) M entries in the factors \(([\d.]+) GB\), "
                     r"ordering AMD \(INFOG\(7\) = 0\)", out)
    assert line, out[-3000:]
    assert abs(float(line.group(1)) * 1e6 - n_default) <= 5e-4 * n_default
    assert abs(float(line.group(2)) * 1e9 - 8 * n_default) <= 5e-3 * 8 * n_default
    u7, u15, n_blocks = _mumps(cli(GRID + ["-ssi_output", b, "-ssi_bem_mat_mumps_icntl_15", "-3",
                                           "-ssi_bem_mat_mumps_icntl_7", "4"]).stdout)
    assert (u7, u15) == (4, -3)                     # (the user's options, not the defaults)
    assert n_default < 0.9 * n_blocks, (n_default, n_blocks)
    same(a, b)
