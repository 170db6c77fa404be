"""Record files as users bring them (an independent test, 2026-11-26): Fortran 'D' exponents in a
PEER file's values, a table under a row of column names, a file no reader knows (the error names
the user's file, not ObsPy's temporary copy), a record of zeros, and an azimuth that does not change
the wave (a warning)."""
import numpy as np
import pytest

from helpers import cli
from petsc_ssi.seismic import records as R
from petsc_ssi.seismic.records import RecordError

AT2 = ("PEER NGA STRONG MOTION DATABASE RECORD\nTEST 1999, STATION, 0\n"
       "ACCELERATION TIME SERIES IN UNITS OF G\nNPTS=    4, DT=   .0100 SEC,\n{}\n")


def test_fortran_d_exponents_read_as_e(tmp_path):
    a, b = tmp_path / "d.AT2", tmp_path / "e.AT2"
    a.write_text(AT2.format("  .1000000D-02 -.2500000D-01  0.0000000D+00  .3000000d-02"))
    b.write_text(AT2.format("  .1000000E-02 -.2500000E-01  0.0000000E+00  .3000000E-02"))
    ra, rb = R.read_record(str(a)), R.read_record(str(b))
    assert np.array_equal(ra.values, rb.values) and ra.values[1] == pytest.approx(-0.025 * R.G)


@pytest.mark.parametrize("head", ["time,acc", "t [s]  a [m/s2]", "time;acceleration"])
def test_a_table_under_a_row_of_column_names(tmp_path, head):
    rows = "\n".join(f"{0.01 * k:.2f},{np.sin(k):.6f}" if "," in head else f"{0.01 * k:.2f} {np.sin(k):.6f}"
                     for k in range(20))
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    a.write_text(f"# units: m/s2\n{head}\n{rows}\n")
    b.write_text(f"# units: m/s2\n{rows}\n")
    ra, rb = R.read_record(str(a)), R.read_record(str(b))
    assert ra.metadata["format"] == "table" and np.array_equal(ra.values, rb.values) and np.array_equal(ra.t, rb.t)


def test_an_unknown_file_names_itself(tmp_path):
    pytest.importorskip("obspy")
    p = tmp_path / "notes.txt"
    p.write_text("these are my notes\nabout a record\n")
    with pytest.raises(RecordError) as e:
        R.read_record(str(p))
    msg = str(e.value)
    assert str(p) in msg and "tmp" not in msg.replace(str(tmp_path), "") and "ObsPy does not recognise" in msg


FEM = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_fem_box_size", "1,1,1", "-ssi_fem_box_origin",
       "-0.5,-0.5,0", "-ssi_fem_fixed", "base", "-ssi_dt", "0.01", "-ssi_t_end", "0.1", "-ssi_seismic", "vertical",
       "-ssi_seismic_units", "m/s2", "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none"]


def test_a_record_of_zeros_is_refused_and_an_unused_azimuth_is_said(tmp_path):
    z = tmp_path / "zero.txt"
    np.savetxt(z, np.c_[np.arange(10) * 0.01, np.zeros(10)])
    p = cli(FEM + ["-ssi_seismic_record", str(z), "-ssi_output", str(tmp_path / "z.h5")], nranks=2, check=False,
            timeout=300)
    errors = [ln for ln in p.stdout.splitlines() if ln.startswith("petsc-ssi: error:")]
    assert p.returncode == 2 and len(errors) == 1 and "zero everywhere" in errors[0], p.stdout + p.stderr
    r = tmp_path / "pulse.txt"
    t = np.arange(0.0, 0.3, 0.01)
    np.savetxt(r, np.c_[t, np.sin(np.pi * t / 0.3) ** 4])
    p = cli(FEM + ["-ssi_seismic_record", str(r), "-ssi_seismic_azimuth", "30", "-ssi_output", str(tmp_path / "a.h5")])
    said = [ln for ln in p.stdout.splitlines() if ln.startswith("petsc-ssi: warning:") and "azimuth" in ln]
    assert len(said) == 1 and "not used by -ssi_seismic vertical" in said[0], p.stdout


def test_content_above_the_runs_nyquist_frequency_is_said(tmp_path):
    """A 30 Hz harmonic record under steps of 0.02 s (Nyquist 25 Hz): said; under 0.005 s: not."""
    r = tmp_path / "h30.txt"
    t = np.arange(0.0, 1.0, 0.002)
    np.savetxt(r, np.c_[t, np.sin(2 * np.pi * 30 * t) * np.sin(np.pi * t) ** 2])
    for dt, said in (("0.02", 1), ("0.005", 0)):
        p = cli([x if x != "0.01" else dt for x in FEM] + ["-ssi_seismic_record", str(r),
                                                             "-ssi_output", str(tmp_path / f"n{dt}.h5")])
        lines = [ln for ln in p.stdout.splitlines() if ln.startswith("petsc-ssi: warning:") and "Nyquist" in ln]
        assert len(lines) == said, p.stdout
        if said:
            assert "25 Hz" in lines[0] and "-ssi_dt" in lines[0]
    from petsc_ssi.seismic.records import energy_above
    assert energy_above(t, np.sin(2 * np.pi * 30 * t), 25.0) > 0.99
    assert energy_above(t, np.sin(2 * np.pi * 30 * t), 35.0) < 0.01
