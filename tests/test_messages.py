"""Errors name their cause (issue 30, item 1): a .geo parameter that empties a group or breaks the
geometry is named as the parameter; a negative box size as such; a structure above the soil as
such (not as a receiver outside it); -ssi_structure_receivers as itself; post on a file that is
not (or no longer) HDF5 names the file, once at -n 2; a restart does not refuse what does not
change the run (-ssi_huge_pages, an input file moved to another path with the same content)."""
import os
import shutil
from types import SimpleNamespace

import h5py
import numpy as np
import pytest

from helpers import ROOT, cli

pytestmark = pytest.mark.mpi

GEO = os.path.join(ROOT, "meshes", "building.geo")


@pytest.mark.parametrize("param, expect", [
    ("nbx=0", "nbx=0: '{geo}' declares nbx [1, 1000]"),        # before: "no physical group 'foundation'"
    ("ns=0", "ns=0: '{geo}' declares ns [1, 1000]"),           # before: "no physical group 'floors'"
    ("sx=-3.6", "sx=-3.6: '{geo}' declares sx >= 0.001"),      # before: gmsh's "line 193: Uninitialized"
    ("nby=2.5", "nby=2.5: '{geo}' declares nby an integer"),
    ("half=2", "half=2: '{geo}' allows half in {{0, 1}}"),
    ("nbz=3", "'{geo}' has no parameter 'nbz' (its parameters: h, half, hc, hs, nbx, nby, ns, sx, sy)"),
])
def test_a_geo_parameter_is_named(param, expect):
    from petsc_ssi.fem.mesh import build_mesh, parse_mesh_params
    from petsc_ssi.petsc import SSIError
    cfg = SimpleNamespace(fem_mesh=GEO, fem_renumber=False, get=lambda k, d="": param if k == "fem_mesh_params" else d)
    assert parse_mesh_params(param)
    with pytest.raises(SSIError) as exc:
        build_mesh(cfg)
    msg = str(exc.value)
    assert msg.startswith(f"-ssi_fem_mesh_params {param.split('=')[0]}=") and expect.format(geo=GEO) in msg, msg
    assert "\n" not in msg


def test_a_geo_parameter_in_range_still_meshes():
    """The declared ranges admit the demo's reduced building (2 x 2 bays, two storeys, half)."""
    from petsc_ssi.mesh import gmsh as reader
    p = dict(nbx=2, nby=2, sx=3.6, sy=3.6, ns=2, half=1)
    model = reader.read(GEO, dim=3, params=p, user=tuple(p))
    assert {"foundation", "floors", "roof", "columns"} <= set(model.groups)


def test_a_negative_box_size_is_named():
    from petsc_ssi.fem.mesh import build_mesh
    from petsc_ssi.petsc import SSIError
    cfg = SimpleNamespace(fem_mesh="box", fem_box_cells="2,2,2", fem_box_size="1,1,-0.5",
                          fem_box_origin="-0.5,-0.5,0", fem_renumber=False, get=lambda k, d="": d)
    with pytest.raises(SSIError, match=r"^-ssi_fem_box_size 1,1,-0.5: the box's lengths lx,ly,lz must be > 0 m"):
        build_mesh(cfg, None)


def test_a_structure_above_the_soil_is_named():
    from petsc_ssi.coupling.model import check_on_surface
    from petsc_ssi.fem.mesh import structured_box
    from petsc_ssi.petsc import SSIError
    check_on_surface(structured_box((2, 2, 1), (1, 1, 0.5), (-0.5, -0.5, 0.0)), "base")
    with pytest.raises(SSIError, match=r"interface faces lie at z = 1 \.\. 1 m, above the soil's surface z = 0"):
        check_on_surface(structured_box((2, 2, 1), (1, 1, 0.5), (-0.5, -0.5, 1.0)), "base")


SSI = ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "2,2",
       "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5", "-ssi_fem_box_cells", "2,2,1", "-ssi_fem_box_size",
       "1,1,0.25", "-ssi_fem_E", "300e9", "-ssi_fem_rho", "200", "-ssi_dt", "0.0125", "-ssi_t_end", "0.025",
       "-ssi_fem_load_group", "top", "-ssi_fem_load_p0", "1000", "-ssi_warn_beta", "0"]


@pytest.mark.parametrize("extra, expect", [
    # the block 1 m above the soil, a receiver on its base: before, "-ssi_receivers: point (0, 0, 0) is
    # 1 m from the nearest FE node ... outside the structure"
    (["-ssi_fem_box_origin", "-0.5,-0.5,1", "-ssi_structure_receivers", "0,0,0"],
     "-ssi_fem_interface base: the structure's interface faces lie at z = 1 .. 1 m, above the soil's surface"),
    (["-ssi_fem_box_origin", "-0.5,-0.5,0", "-ssi_structure_receivers", "0,0,5"],
     "-ssi_structure_receivers: point (0, 0, 5) is"),
])
def test_coupled_errors_name_their_option(extra, expect, tmp_path):
    p = cli(SSI + extra + ["-ssi_output", str(tmp_path / "a.h5")], nranks=2, check=False)
    errs = [ln for ln in p.stderr.splitlines() if "error" in ln]
    assert p.returncode != 0 and len(errs) == 1 and expect in errs[0], p.stdout[-2000:] + p.stderr[-2000:]
    assert not os.path.exists(tmp_path / "a.h5")


def test_post_names_a_file_that_is_not_hdf5_once(tmp_path):
    """A text file and an HDF5 file cut in half: one line (not one per rank) naming the file."""
    bad = tmp_path / "bad.h5"
    bad.write_text("not a result\n")
    good, cut = tmp_path / "good.h5", tmp_path / "cut.h5"
    with h5py.File(good, "w") as f:
        f["receivers/t"] = np.arange(10.0)
        f["big"] = np.zeros(50000)
    data = good.read_bytes()
    cut.write_bytes(data[:len(data) // 2])
    for path, expect, args in ((bad, "not an HDF5 file", ["--info"]),
                               (cut, "an HDF5 file that cannot be read, truncated", ["--spectrum"])):
        for args in (["post", str(path)] + args,):
            p = cli(args, nranks=2, check=False)
            lines = [ln for ln in (p.stdout + p.stderr).splitlines() if "petsc-ssi post: error" in ln]
            assert p.returncode != 0 and len(lines) == 1, p.stdout + p.stderr
            assert lines[0].startswith(f"petsc-ssi post: error: {path}: {expect}"), lines


def _cfg(**vals):
    return SimpleNamespace(as_dict=lambda: dict(vals))


def test_restart_key_ignores_huge_pages_and_a_moved_file(tmp_path):
    """The key of a run whose mesh moved to another path (same bytes) and whose -ssi_huge_pages
    changed is the same run; a changed mesh is still refused."""
    from petsc_ssi.io.checkpoint import key_difference, run_key
    a = tmp_path / "a" / "block.geo"
    a.parent.mkdir()
    shutil.copy(os.path.join(ROOT, "meshes", "foundation.geo"), a)
    b = tmp_path / "b.geo"
    shutil.copy(a, b)
    saved = run_key(_cfg(fem_mesh=str(a), huge_pages="numpy", cs=20.0))
    assert key_difference(saved, run_key(_cfg(fem_mesh=str(b), huge_pages="off", cs=20.0))) is None
    with open(b, "a") as fh:
        fh.write("// changed\n")
    diff = key_difference(saved, run_key(_cfg(fem_mesh=str(b), huge_pages="numpy", cs=20.0)))
    assert diff == "the file of -ssi_fem_mesh changed since the checkpoint (SHA-256 differs)", diff
    assert "-ssi_cs is 21.0" in key_difference(saved, run_key(_cfg(fem_mesh=str(a), huge_pages="numpy", cs=21.0)))


def test_no_terminal_codes_under_mpirun():
    """numba's error highlighting (colorama) wrote ESC[0m at exit whenever stdout is a terminal, and
    mpirun gives every rank a pseudo-terminal: each run's output under mpirun ended with one per rank
    (issue 30). petsc_ssi turns the highlighting off before numba loads; the BEM assembly's module
    (numba's typed containers load the compiler machinery) under mpirun -n 2 now prints nothing."""
    import subprocess
    from helpers import PY
    code = "import petsc_ssi.bem.assemble"
    p = subprocess.run(["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "2", PY, "-c", code],
                       cwd=ROOT, capture_output=True, timeout=120,
                       env={k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING"})
    assert p.returncode == 0, p.stderr.decode()[-2000:]
    assert b"\x1b" not in p.stdout + p.stderr, (p.stdout + p.stderr)[-200:]
