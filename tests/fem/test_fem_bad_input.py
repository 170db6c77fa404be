"""Bad input ends the run before heavy work with ONE line 'petsc-ssi: error: ...' and exit status 2,
on every rank (the singular-D cases are in test_fem_integrators.py, in-process)."""
import pytest

from fem_helpers import run_cli

pytestmark = pytest.mark.mpi

FEM = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_t_end", "0.01", "-ssi_dt", "0.005",
       "-ssi_output", ""]


def one_line_error(r):
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    errs = [ln for ln in lines if ln.startswith("petsc-ssi: error: ")]
    assert r.returncode == 2, r.stdout + r.stderr
    assert len(errs) == 1, r.stdout + r.stderr
    assert "Traceback" not in r.stderr, r.stderr
    return errs[0]


@pytest.fixture(scope="module")
def tet_geo(tmp_path_factory):
    p = tmp_path_factory.mktemp("mesh") / "tets.geo"
    p.write_text('SetFactory("OpenCASCADE");\nBox(1) = {0,0,0,1,1,1};\nMesh.MeshSizeMax = 0.5;\n'
                 'Physical Surface("top") = {6};\nPhysical Volume("v") = {1};\n')
    return str(p)


CASES = [
    (["-ssi_fem_nu", "0.5"], "-ssi_fem_nu 0.5: Poisson's ratio must lie in (-1, 0.5)"),
    (["-ssi_fem_nu", "-1"], "-ssi_fem_nu -1.0: Poisson's ratio must lie in (-1, 0.5)"),
    (["-ssi_fem_E", "0"], "-ssi_fem_E 0.0: must be > 0"),
    (["-ssi_fem_rho", "-2000"], "-ssi_fem_rho -2000.0: must be > 0"),
    (["-ssi_dt", "0"], "-ssi_dt 0.0: must be > 0"),
    (["-ssi_dt", "-1e-3"], "-ssi_dt -0.001: must be > 0"),
    (["-ssi_fem_load_group", "roof", "-ssi_fem_load_p0", "1000"],
     "-ssi_fem_load_group: no face group 'roof' in mesh box:2,2,2 (face groups: base, top,"),
    (["-ssi_fem_fixed", "bottom"], "-ssi_fem_fixed: no group 'bottom'"),
    (["-ssi_fem_load_p0", "1000"], "-ssi_fem_load_p0 is set but -ssi_fem_load_group names no face group"),
    (["-ssi_fem_mesh", "nowhere.msh"], "-ssi_fem_mesh nowhere.msh: no such file"),
    (["-ssi_fem_newmark_alpha", "0.3"], "green needs delta^2 = alpha"),
    (["-ssi_fem_E_modulus", "3e8"], "unknown option -ssi_fem_E_modulus"),
    (["-ssi_receivers", "0,0"], "-ssi_receivers: '0,0' is not 3 comma-separated numbers"),
    (["-ssi_receivers", "0,0,5"], "-ssi_receivers: point (0, 0, 5) is 4.5 m from the nearest FE node, more "
     "than the largest element size 0.5 m: it lies outside the structure"),
    (["-ssi_fem_point_load", "3,0,0.5,1,0,0"], "-ssi_fem_point_load: point (3, 0, 0.5) is 2.5 m from the "
     "nearest FE node, more than the largest element size 0.5 m"),
    (["-ssi_fem_point_load", "0,0,0.5"], "-ssi_fem_point_load: '0,0,0.5' is not 6 or 9 comma-separated numbers "
     "(each point needs x,y,z,fx,fy,fz and optionally mx,my,mz)"),
]


@pytest.mark.parametrize("args, message", CASES, ids=[" ".join(c[0][:2]) for c in CASES])
def test_one_line_error(args, message):
    line = one_line_error(run_cli(FEM + args))
    assert message in line, line


def test_mesh_without_hex8(tet_geo):
    line = one_line_error(run_cli(FEM + ["-ssi_fem_mesh", tet_geo]))
    assert "has no hex8 (8-node brick) cells (3D cells found: Tetrahedron 4 x" in line, line


@pytest.mark.parametrize("args, message", [
    (["-ssi_fem_load_group", "roof", "-ssi_fem_load_p0", "1"], "no face group 'roof'"),
    (["-ssi_fem_nu", "0.7"], "Poisson's ratio must lie in (-1, 0.5)")])
def test_error_on_every_rank(args, message):
    """Under mpirun -n 2: same exit status 2, one line (rank 0 prints), no hang (timeout 60 s)."""
    r = run_cli(FEM + args, n=2, timeout=60)
    assert r.returncode == 2 and message in one_line_error(r)


TABLES = {"non-numeric": ("0 0\n0.01 one\n", "history table '{path}': "),
          "decreasing": ("0 0\n0.02 1\n0.01 1\n", "t must increase strictly (data row 3: t = 0.01 after 0.02)"),
          "three columns": ("0 0 1\n0.01 1 1\n", "need rows of two numbers 't h'"),
          "nan": ("0 0\n0.01 nan\n", "non-finite value")}


@pytest.mark.parametrize("kind", list(TABLES))
def test_bad_load_table_fails_before_the_mesh(tmp_path, kind):
    """A malformed -ssi_fem_load_table ends the run in the option checks: one line, before the mesh
    is read (no '[fem] mesh' line), let alone assembled and factorised."""
    text, message = TABLES[kind]
    path = tmp_path / "h.txt"
    path.write_text(text)
    r = run_cli(FEM + ["-ssi_fem_load_group", "top", "-ssi_fem_load_p0", "1000", "-ssi_fem_load_history",
                       "table", "-ssi_fem_load_table", str(path)])
    line = one_line_error(r)
    assert line.startswith("petsc-ssi: error: -ssi_fem_load_history table: history table"), line
    assert message.format(path=path) in line, line
    assert "[fem]" not in r.stdout, r.stdout
