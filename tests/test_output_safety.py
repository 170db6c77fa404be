"""Output that is never lost or clobbered, and input that is refused before any work (issue 14).

Every bad case runs under `mpirun -n 2` with a timeout and must end with ONE line
'petsc-ssi: error: ...', exit status 2 on every rank, no traceback, no assembly, and every file
that existed before untouched (bytes and modification time)."""
import os

import pytest

from helpers import cli

SMALL = ["-ssi_problem", "bem", "-ssi_mesh_size", "4,4", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
         "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.005", "-ssi_t_end", "0.01",
         "-ssi_output_stride", "0"]
FEM = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_fem_fixed", "base", "-ssi_fem_load_group", "top",
       "-ssi_fem_load_p0", "1000", "-ssi_dt", "1e-3", "-ssi_t_end", "0.003"]

SSI = ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "2,2",
       "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5", "-ssi_fem_box_cells", "4,4,1", "-ssi_fem_box_size",
       "1,1,0.25", "-ssi_fem_box_origin", "-0.5,-0.5,0", "-ssi_fem_E", "300e9", "-ssi_fem_rho", "200",
       "-ssi_dt", "0.0125", "-ssi_t_end", "0.05"]


def one_line_error(r, n=2):
    lines = [ln for ln in r.stdout.splitlines() if ln.strip()]
    errs = [ln for ln in lines if ln.startswith("petsc-ssi: error: ")]
    assert r.returncode == 2, r.stdout + r.stderr
    assert len(errs) == 1, r.stdout
    assert "Traceback" not in r.stderr, r.stderr
    assert "[ssi] assembly" not in r.stdout and "[fem] alpha_m" not in r.stdout, r.stdout
    return errs[0]


def snapshot(d):
    """{path: (bytes, mtime)} of every file under d."""
    out = {}
    for root, _, files in os.walk(d):
        for f in files:
            p = os.path.join(root, f)
            if os.path.isfile(p):
                with open(p, "rb") as fh:
                    out[p] = (fh.read(), os.stat(p).st_mtime_ns)
    return out


@pytest.fixture(scope="module")
def previous(tmp_path_factory):
    """A finished FEM run (out.h5 + .xmf + .json) whose files the bad runs must not touch."""
    d = tmp_path_factory.mktemp("prev")
    cli(FEM + ["-ssi_output", str(d / "out.h5")])
    assert os.path.exists(d / "out.h5") and os.path.exists(d / "out.json")
    return d


def _cases(d):
    h5 = str(d / "out.h5")
    os.makedirs(d / "adir.h5", exist_ok=True)
    if not os.path.lexists(d / "full.h5"):
        os.symlink("/dev/full", d / "full.h5")
    return {
        "existing result": (FEM + ["-ssi_output", h5], "exists (a previous result); add -ssi_output_overwrite"),
        "existing result, modes": (["modes"] + FEM + ["-ssi_output", h5], "exists (a previous result)"),
        "existing result, static": (["static"] + FEM + ["-ssi_output", h5], "exists (a previous result)"),
        "existing result, bem": (SMALL + ["-ssi_output", h5], "exists (a previous result)"),
        "sidecar name .xmf": (FEM + ["-ssi_output", str(d / "out.xmf")], "'.xmf' is the name of a sidecar"),
        "sidecar name .json": (SMALL + ["-ssi_output", str(d / "new.json")], "'.json' is the name of a sidecar"),
        "a directory": (FEM + ["-ssi_output", str(d / "adir.h5"), "-ssi_output_overwrite"], "is a directory"),
        "/dev/full": (SMALL + ["-ssi_output", str(d / "full.h5"), "-ssi_output_overwrite"],
                      "exists and is not a regular file"),
        "directory under a file": (FEM + ["-ssi_output", h5 + "/x.h5"], "cannot create the directory"),
        "nan load": (FEM + ["-ssi_output", str(d / "n.h5"), "-ssi_fem_load_p0", "nan"],
                     "-ssi_fem_load_p0: 'nan' is not a finite number"),
        "inf density": (SMALL + ["-ssi_output", str(d / "n.h5"), "-ssi_rho", "inf"],
                        "-ssi_rho: 'inf' is not a finite number"),
        "inf end time": (SMALL + ["-ssi_output", str(d / "n.h5"), "-ssi_t_end", "inf"],
                         "-ssi_t_end: 'inf' is not a finite number"),
        "-inf dt": (FEM + ["-ssi_output", str(d / "n.h5"), "-ssi_dt", "-inf"], "-ssi_dt: '-inf' is not a finite number"),
        "patch beyond the mesh": (SMALL + ["-ssi_output", str(d / "n.h5"), "-ssi_mesh_patch", "2.5,1"],
                                  "-ssi_mesh_patch 2.5,1: the patch (half-widths) reaches the edge of the mesh"),
        "contact option, bonded": (SSI + ["-ssi_output", str(d / "n.h5"), "-ssi_contact_tol", "1e-6"],
                                   "-ssi_contact_tol acts only with -ssi_contact unilateral"),
        "unknown command": (["mode"] + FEM, "unknown command 'mode' (did you mean modes?)"),
        "unknown command, far": (["solve"] + FEM, "unknown command 'solve'; commands: run, post"),
    }


@pytest.mark.parametrize("name", ["existing result", "existing result, modes", "existing result, static",
                                  "existing result, bem", "sidecar name .xmf", "sidecar name .json", "a directory",
                                  "/dev/full", "directory under a file", "nan load", "inf density", "inf end time",
                                  "-inf dt", "patch beyond the mesh", "contact option, bonded", "unknown command",
                                  "unknown command, far"])
def test_refused_in_one_line_without_touching_files(name, previous):
    before = snapshot(previous)
    args, msg = _cases(previous)[name]
    r = cli(args, nranks=2, timeout=300, check=False)
    err = one_line_error(r)
    assert msg in err, err
    after = snapshot(previous)
    assert after == before, sorted(set(after) ^ set(before))


def test_overwrite_replaces_the_result(previous, tmp_path):
    """-ssi_output_overwrite replaces an existing result (a new run record is written)."""
    import shutil
    d = tmp_path / "copy"
    shutil.copytree(previous, d, symlinks=True)
    old = os.stat(d / "out.json").st_mtime_ns
    r = cli(FEM + ["-ssi_output", str(d / "out.h5"), "-ssi_output_overwrite"], nranks=2, timeout=300)
    assert r.returncode == 0
    assert os.stat(d / "out.json").st_mtime_ns > old


@pytest.mark.parametrize("flag", ["--version", "-version"])
def test_version_prints_and_exits(flag, tmp_path):
    r = cli([flag] + SMALL + ["-ssi_output", str(tmp_path / "v.h5")], nranks=2, timeout=120)
    out = r.stdout
    assert out.count("petsc-ssi ") == 1 and "PETSc 3." in out and "petsc4py" in out and "mpi4py" in out, out
    assert "[ssi]" not in out and not os.path.exists(tmp_path / "v.h5")


@pytest.mark.parametrize("flag", ["-help", "--help"])
def test_help_prints_and_exits(flag, tmp_path):
    r = cli(SMALL + ["-ssi_output", str(tmp_path / "h.h5"), flag], timeout=120)
    assert "-ssi_output_overwrite" in r.stdout and "Commands:" in r.stdout
    assert "[ssi] assembly" not in r.stdout and not os.path.exists(tmp_path / "h.h5")
