"""Issue 30, "wrong or silent": inputs that used to run on with a wrong result, do nothing silently,
or crash, now refused in one line ('petsc-ssi: error: ...', exit status 2, every rank, before the
work) or named in one warning line. Each check here fails on the code before its fix."""
import pytest

from helpers import cli


def one_line_error(r):
    """The single error line of a refused run (exit status 2, no traceback)."""
    errs = [ln for ln in r.stdout.splitlines() if ln.startswith("petsc-ssi: error: ")]
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert len(errs) == 1, r.stdout
    assert "Traceback" not in r.stderr, r.stderr
    return errs[0]


# ------------------------------------------------------------ options files that include each other

@pytest.mark.parametrize("n", [1, 2])
def test_options_files_in_a_cycle_are_named(tmp_path, n):
    """A file that includes itself, or three that include each other, made PETSc recurse to a
    segmentation fault; now one line names the cycle, before PETSc starts."""
    (tmp_path / "self.opts").write_text(f"-ssi_dt 1e-3\n-options_file {tmp_path}/self.opts\n")
    line = one_line_error(cli(["-options_file", str(tmp_path / "self.opts")], nranks=n, check=False))
    assert line == f"petsc-ssi: error: -options_file {tmp_path}/self.opts includes itself (remove its -options_file line)"
    (tmp_path / "a.opts").write_text(f"-ssi_dt 1e-3 -options_file {tmp_path}/b.opts\n")
    (tmp_path / "b.opts").write_text(f"# b\n-options_file {tmp_path}/c.opts\n")
    (tmp_path / "c.opts").write_text(f"-ssi_t_end 1\n-options_file {tmp_path}/a.opts\n")
    line = one_line_error(cli(["-options_file", str(tmp_path / "a.opts")], nranks=n, check=False))
    assert f"{tmp_path}/a.opts -> {tmp_path}/b.opts -> {tmp_path}/c.opts -> {tmp_path}/a.opts: " \
           "the options files include each other in a cycle" in line, line
    # an included file that is missing is named with the file that includes it
    (tmp_path / "d.opts").write_text(f"-options_file {tmp_path}/nope.opts\n")
    line = one_line_error(cli(["-options_file", str(tmp_path / "d.opts")], nranks=n, check=False))
    assert f"nope.opts (included by {tmp_path}/d.opts): No such file" in line, line


# ------------------------------------------------------------ impedance: symmetry planes of the footing

IMP = ["impedance", "-ssi_cp", "548", "-ssi_cs", "316", "-ssi_rho", "2000", "-ssi_mesh_size", "6,4",
       "-ssi_mesh_h", "0.5", "-ssi_dt", "8e-4", "-ssi_t_end", "0.024", "-ssi_warn_beta", "0",
       "-ssi_output_overwrite"]


def _K0(csv_path):
    import csv
    with open(csv_path) as fh:
        return {row["mode"]: float(row["K0"]) for row in csv.DictReader(fh)}


def test_impedance_of_an_off_centre_footing_uses_only_its_planes(tmp_path):
    """A 2 m x 2 m footing on x in [0, 2] m: the plane x = 0 used to be applied anyway (the footing
    mirrored into one twice as long: K0 1.45 times too large here, 2.9 in the issue's case). Now
    only y = 0 is used, the line says so, x_ref is the footing's centre, and K0 (vertical, rocking)
    equals the whole surface's (-ssi_impedance_symmetry 0) to 1e-6 (the plane's round-off only)."""
    args = IMP + ["-ssi_disp_group", "box:0,2,-1,1", "-ssi_impedance_modes", "vertical,rocking"]
    r = cli(args + ["-ssi_output", str(tmp_path / "sym.h5")], nranks=2)
    assert ("[impedance] symmetry planes used: y = 0 (x = 0 not used: the footing (spanning x in [0, 2] m) is "
            "not symmetric about it); reference point x_ref = (1, 0, 0) m") in r.stdout, r.stdout
    cli(args + ["-ssi_output", str(tmp_path / "whole.h5"), "-ssi_impedance_symmetry", "0"])
    a, b = _K0(tmp_path / "sym-impedance.csv"), _K0(tmp_path / "whole-impedance.csv")
    for mode in ("vertical", "rocking"):
        assert abs(a[mode] / b[mode] - 1) < 1e-6, (mode, a[mode], b[mode])


@pytest.mark.parametrize("n", [1, 2])
def test_impedance_needs_soil_around_the_footing(tmp_path, n):
    """The whole meshed surface as the footing (-ssi_disp_group surface), or a footing reaching the
    surface's edge, was run and compared with Pais & Kausel without a word; now refused in one line
    before the runs."""
    args = IMP + ["-ssi_output", str(tmp_path / "i.h5"), "-ssi_impedance_modes", "vertical"]
    line = one_line_error(cli(args + ["-ssi_disp_group", "surface"], nranks=n, check=False))
    assert line == ("petsc-ssi: error: -ssi_disp_group surface: the footing is the whole meshed surface; petsc-ssi "
                    "impedance needs the footing as a part of the surface with soil around it (mesh a larger "
                    "surface or name a smaller group)")
    r = cli(args + ["-ssi_disp_group", "box:1,3,-1,1"], nranks=n, check=False)
    assert "the footing reaches the edge of the meshed surface (at x = 3, y = " in one_line_error(r)
    assert "[impedance] mode" not in r.stdout
