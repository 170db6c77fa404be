"""Small fixes of issue 30, item 7: a shadowed mpl_toolkits (Debian's, beside the venv's
matplotlib) no longer makes every plot warn about Axes3D; -help lists the PETSc solver options
under -ssi_bem_ and -ssi_fem_ with petsc-ssi's defaults."""
import os
import subprocess
import sys

from helpers import ROOT, cli
import pytest

pytestmark = pytest.mark.run

SHADOW = "raise ImportError('a different matplotlib built this mpl_toolkits')\n"


def _plot_warnings(tmp_path, first):
    shadow = tmp_path / "shadow" / "mpl_toolkits" / "mplot3d"
    shadow.mkdir(parents=True, exist_ok=True)
    (shadow / "__init__.py").write_text(SHADOW)
    code = (f"import warnings; warnings.simplefilter('always')\n{first}\n"
            "import matplotlib; matplotlib.use('Agg'); import matplotlib.pyplot as plt\n"
            "plt.figure(); plt.plot([0, 1]); print('ok')\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path / "shadow"), ROOT]))
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0 and "ok" in p.stdout, p.stderr
    return p.stderr


def test_a_shadowed_mpl_toolkits_does_not_warn(tmp_path):
    assert "Unable to import Axes3D" in _plot_warnings(tmp_path, "pass")     # the shadow is real
    assert "Axes3D" not in _plot_warnings(tmp_path, "import petsc_ssi")


def test_help_lists_the_solver_options():
    out = cli(["-help"]).stdout
    for opt in ("-ssi_bem_ksp_type", "-ssi_bem_pc_type", "-ssi_fem_ksp_type", "-ssi_fem_pc_type"):
        assert opt in out, opt
    assert "-ssi_bem_ksp_type preonly -ssi_bem_pc_type lu" in out
