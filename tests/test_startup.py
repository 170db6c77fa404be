"""What a petsc-ssi process imports before it does any work.

numba takes 0.24-0.26 s to import (a one-rank run refused on its options: 0.75 s with it, 0.56 s without;
`python jobscripts/startup_times.py`, 2026-12-03). The compiled
kernels (bem/bsr.py, assemble.py, lagmats.py, ...) are imported where a run first uses them, so a run refused
on its options, a structure-only run (static, modes, -ssi_problem fem) and the post tools start without it.
A top-level import of a kernel module in the modules every command imports would undo that: this fails then.
"""
import subprocess
import sys

import pytest

pytestmark = pytest.mark.run

# every command's modules (app/cli.py imports these before it dispatches), and the structure-only commands'
COMMANDS = ("petsc_ssi.app.cli", "petsc_ssi.app.kinds", "petsc_ssi.app.estimate", "petsc_ssi.app.impedance",
            "petsc_ssi.app.record", "petsc_ssi.app.post", "petsc_ssi.app.static", "petsc_ssi.app.modes",
            "petsc_ssi.app.input_motion", "petsc_ssi.options", "petsc_ssi.bem.problem",
            "petsc_ssi.coupling.problem", "petsc_ssi.fem.problem")


def _imports(code):
    # (timeout: a soil run compiles its kernels where numba's cache is cold)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout.split()


def test_the_commands_modules_do_not_import_numba():
    got = _imports("import importlib, sys\n"
                   f"for m in {COMMANDS!r}: importlib.import_module(m)\n"
                   "print(' '.join(sorted(k for k in sys.modules if k == 'numba' or k.startswith('petsc_ssi.bem.'))))")
    assert "numba" not in got, [m for m in got if m != "numba"]
    assert "petsc_ssi.bem.halfspace" in got        # (the half-space's own modules are imported, as they must be)
    for kernel in ("bsr", "assemble", "lagmats", "kernels", "quadrature", "toeplitz", "lanes"):
        assert f"petsc_ssi.bem.{kernel}" not in got, kernel


def test_a_structure_only_run_does_not_import_numba(tmp_path):
    """A whole -ssi_problem fem run (the fixed box under a load) ends without numba in its process."""
    out = tmp_path / "f.h5"
    got = _imports(
        "import sys\n"
        "from petsc_ssi.app.cli import main\n"
        f"rc = main(['petsc-ssi', '-ssi_problem', 'fem', '-ssi_fem_box_cells', '2,2,2', '-ssi_fem_fixed', 'base',\n"
        f"           '-ssi_fem_load_group', 'top', '-ssi_fem_load_p0', '1000', '-ssi_dt', '0.01', '-ssi_t_end', '0.03',\n"
        f"           '-ssi_output', {str(out)!r}])\n"
        "print('rc', rc, 'numba' in sys.modules)")
    assert got[-3:] == ["rc", "0", "False"], got
    assert out.exists()


def test_a_soil_run_imports_the_kernels_it_needs(tmp_path):
    """The other side: a BEM run that assembles imports numba and its kernels (where they are used)."""
    out = tmp_path / "b.h5"
    got = _imports(
        "import sys\n"
        "from petsc_ssi.app.cli import main\n"
        f"rc = main(['petsc-ssi', '-ssi_problem', 'bem', '-ssi_mesh_size', '4,4', '-ssi_mesh_h', '1',\n"
        f"           '-ssi_mesh_patch', '1,1', '-ssi_load_group', 'load', '-ssi_load_p0', '1000', '-ssi_dt', '0.005',\n"
        f"           '-ssi_t_end', '0.015', '-ssi_warn_beta', '0', '-ssi_output', {str(out)!r}])\n"
        "print('rc', rc, 'numba' in sys.modules, 'petsc_ssi.bem.assemble' in sys.modules)")
    assert got[-4:] == ["rc", "0", "True", "True"], got
