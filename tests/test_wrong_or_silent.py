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
