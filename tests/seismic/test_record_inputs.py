"""Record files as users bring them (an independent test, 2026-11-26): Fortran 'D' exponents in a
PEER file's values, a table under a row of column names, a file no reader knows (the error names
the user's file, not ObsPy's temporary copy), a record of zeros, and an azimuth that does not change
the wave (a warning)."""
import numpy as np
import pytest

from helpers import cli
from petsc_ssi.seismic import records as R
from petsc_ssi.seismic.records import RecordError

pytestmark = pytest.mark.mpi

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
    errors = [ln for ln in p.stderr.splitlines() if ln.startswith("petsc-ssi: error:")]
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


def _cut_harmonic(path, quantity, units):
    """A 2 Hz harmonic motion (acceleration amplitude 1 m/s^2) cut at t = 0.3 s, where it moves:
    velocity -cos / w, displacement -sin / w^2 of the acceleration sin(w t)."""
    w = 2 * np.pi * 2.0
    t = np.arange(0.0, 2.0, 0.005)
    s = t + 0.3
    x = {"velocity": -np.cos(w * s) / w, "displacement": -np.sin(w * s) / w ** 2}[quantity]
    np.savetxt(path, np.c_[t, x], header=f"units: {units}")
    return str(path)


@pytest.mark.parametrize("quantity,units", [("velocity", "m/s"), ("displacement", "m")])
def test_an_untapered_record_that_does_not_start_at_rest_is_refused(tmp_path, quantity, units):
    """With no taper, the motion would jump from rest to the record's first velocity: an impulse the
    record does not hold (an independent test: a DT2 cut where it moves gave a PGA 16 times the real
    one). Refused; with a taper the record is taken, and the raw record's PGA (its own slope at the
    start, not a forced rest) is the harmonic's amplitude to 1 %."""
    rec = R.read_record(_cut_harmonic(tmp_path / f"{quantity}.txt", quantity, units), quantity=quantity)
    with pytest.raises(RecordError, match="does not start at rest.*-ssi_seismic_taper"):
        R.process(rec, taper=0.0, baseline="none")
    m = R.process(rec, taper=0.05, baseline="none")
    assert abs(float(np.max(m.stats_raw["pga"])) - 1.0) < 0.01, m.stats_raw["pga"]


def test_a_run_ending_inside_the_high_pass_pad_is_warned(tmp_path):
    """A high-pass at 0.5 Hz leads the record by a pad of 0.75 * 4 / 0.5 = 6 s: a fixed base run to
    3 s never sees the record (an independent test: peak base shear 0.04 N instead of 5 kN). Said;
    the output states the record's time of the motion's start (record_t0)."""
    import h5py
    r = tmp_path / "pulse.txt"
    t = np.arange(0.0, 0.3, 0.01)
    np.savetxt(r, np.c_[t, np.sin(np.pi * t / 0.3) ** 4])
    out = tmp_path / "hp.h5"
    args = [x if x != "0.1" else "3" for x in FEM]             # -ssi_t_end 3
    p = cli(args + ["-ssi_seismic_record", str(r), "-ssi_seismic_highpass", "0.5", "-ssi_output", str(out)])
    said = [ln for ln in p.stdout.splitlines() if ln.startswith("petsc-ssi: warning:") and "before the record" in ln]
    assert len(said) == 1 and "-ssi_t_end 3 s" in said[0], p.stdout
    with h5py.File(out, "r") as f:
        assert float(f["seismic/x_record_t0"][()]) == pytest.approx(-6.0, abs=0.011)
        unit = f["seismic/t0"].attrs["unit"]
        assert "motion time t + t0" in (unit.decode() if isinstance(unit, bytes) else str(unit))
