"""-ssi_seismic vertical from multi-trace files (miniSEED through ObsPy): -ssi_seismic_traces says
which trace drives x, y and z. Found by an independent test (2026-11-26): a 3-component miniSEED
could drive -ssi_seismic sv (-ssi_seismic_component N) but not vertical, in any form, and the error
named a Python keyword ('give component=') instead of an option."""
import h5py
import numpy as np
import pytest

from helpers import cli

pytestmark = pytest.mark.mpi

FEM = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_fem_box_size", "1,1,1", "-ssi_fem_box_origin",
       "-0.5,-0.5,0", "-ssi_fem_E", "3e7", "-ssi_fem_rho", "2000", "-ssi_fem_fixed", "base", "-ssi_dt", "0.01",
       "-ssi_t_end", "0.2", "-ssi_receivers", "0,0,1", "-ssi_seismic", "vertical", "-ssi_seismic_units", "m/s2",
       "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none"]


@pytest.fixture(scope="module")
def three(tmp_path_factory):
    """HNE, HNN, HNZ traces at 100 Hz: a sin^4 pulse of 1, 2 and 3 m/s^2 (written in the order Z, E, N)."""
    obspy = pytest.importorskip("obspy")
    t = np.arange(0.0, 0.5, 0.01)
    p = np.where(t < 0.3, np.sin(np.pi * t / 0.3) ** 4, 0.0)
    traces = [obspy.Trace(data=(amp * p).astype(np.float64),
                          header={"network": "XX", "station": "SSI", "channel": ch, "sampling_rate": 100.0})
              for ch, amp in (("HNZ", 3.0), ("HNE", 1.0), ("HNN", 2.0))]
    path = tmp_path_factory.mktemp("ms") / "three.mseed"
    obspy.Stream(traces).write(str(path), format="MSEED")
    return str(path)


def _pga(path):
    with h5py.File(path, "r") as f:
        return {a: float(f[f"seismic/{a}_raw_pga"][()]) for a in "xyz" if f"seismic/{a}_raw_pga" in f}


@pytest.mark.parametrize("form,expect", [
    (["-ssi_seismic_traces", "E,N,Z"], {"x": 1.0, "y": 2.0, "z": 3.0}),
    (["-ssi_seismic_traces", "HNN,-,0"], {"x": 2.0, "z": 3.0}),                 # a channel code, none, an index
    (["-ssi_seismic_record_x", "F", "-ssi_seismic_record_z", "F", "-ssi_seismic_traces", "N,E,Z"], {"x": 2.0, "z": 3.0}),
])
def test_each_axis_takes_its_trace(tmp_path, three, form, expect):
    out = tmp_path / "o.h5"
    args = FEM + ["-ssi_output", str(out)] + [three if x == "F" else x for x in form]
    if "-ssi_seismic_record_x" not in form:
        args += ["-ssi_seismic_record", three]
    cli(args)
    got = _pga(out)
    assert set(got) == set(expect) and all(abs(got[a] - expect[a]) < 1e-12 for a in expect), got


@pytest.mark.parametrize("extra,words", [
    ([], "-ssi_seismic_traces X,Y,Z"),
    (["-ssi_seismic_traces", "E,N"], "give three traces"),
    (["-ssi_seismic_traces", "E,N,Q"], "'Q' matches 0 of the traces"),
    # one trace driving three axes (issue 44: E,E,E ran as a diagonal motion)
    (["-ssi_seismic_traces", "E,E,E"], "the trace HNE of"),
    (["-ssi_seismic_traces", "HNE,1,-"], "drives both x and y"),
])
def test_a_multi_trace_file_without_its_traces_is_refused_in_one_line(tmp_path, three, extra, words):
    p = cli(FEM + ["-ssi_output", str(tmp_path / "o.h5"), "-ssi_seismic_record", three] + extra, nranks=2,
            check=False, timeout=300)
    errors = [ln for ln in p.stderr.splitlines() if ln.startswith("petsc-ssi: error:")]
    assert p.returncode == 2 and len(errors) == 1, p.stdout[-2000:] + p.stderr[-2000:]
    assert words in errors[0], errors[0]


def test_a_record_with_gaps_is_refused(tmp_path):
    """A miniSEED whose channel is in three segments (gaps): refused whatever the trace asked for
    (issue 44: the index 0 ran the first segment; three segments could drive three axes)."""
    obspy = pytest.importorskip("obspy")
    from petsc_ssi.seismic import records as R
    t0 = obspy.UTCDateTime(2020, 1, 1)
    segs = []
    for off in (0, 10, 25):
        tr = obspy.Trace(np.sin(np.arange(500) * 0.1), header={"channel": "HNZ", "station": "ST", "sampling_rate": 100.0,
                                                               "starttime": t0 + off})
        segs.append(tr)
    path = str(tmp_path / "gaps.mseed")
    obspy.Stream(segs).write(path, format="MSEED")
    for comp in (None, "Z", 0):
        with pytest.raises(R.RecordError) as e:
            R.read_record(path, component=comp, units="m/s2")
        assert "the trace .ST..HNZ is in 3 segments (gaps or overlaps" in str(e.value), e.value


def test_one_column_of_a_table_cannot_drive_two_axes(tmp_path):
    """A 't ax ay az' table read with -ssi_seismic_traces: each axis its column (z,y,x swaps them), and one
    column for two axes is refused in one line on every rank (issue 44: x,x,x ran the first column as a
    diagonal motion; only ObsPy files were checked)."""
    t = np.arange(0.0, 0.5, 0.01)
    p = np.where(t < 0.3, np.sin(np.pi * t / 0.3) ** 4, 0.0)
    tab = tmp_path / "tab3.txt"
    np.savetxt(tab, np.c_[t, p, 2 * p, 3 * p], header="units: m/s2")
    out = tmp_path / "o.h5"
    cli(FEM + ["-ssi_output", str(out), "-ssi_seismic_record", str(tab), "-ssi_seismic_traces", "z,y,x"])
    got = _pga(out)
    assert all(abs(got[a] - v) < 1e-12 for a, v in (("x", 3.0), ("y", 2.0), ("z", 1.0))), got
    r = cli(FEM + ["-ssi_output", str(tmp_path / "r.h5"), "-ssi_seismic_record", str(tab), "-ssi_seismic_traces",
                   "x,x,x"], nranks=2, check=False, timeout=300)
    errors = [ln for ln in r.stderr.splitlines() if ln.startswith("petsc-ssi: error:")]
    assert r.returncode == 2 and len(errors) == 1, r.stdout[-2000:] + r.stderr[-2000:]
    assert "the column x of" in errors[0] and "drives both x and y" in errors[0], errors[0]


def test_a_restart_naming_the_obspy_format_auto_found_is_the_same_run(three):
    """The restart key resolves -ssi_seismic_format auto to the format ObsPy finds, so naming it (mseed) on a
    restart is no change of options (issue 44: refused as one), while another format (sac) still is; a
    checkpoint written before the format was resolved ('obspy') matches any ObsPy format."""
    from petsc_ssi.io.checkpoint import _record_format, key_difference
    base = {"seismic": "vertical", "seismic_record": three}
    auto, mseed, sac = (_record_format(dict(base, seismic_format=f)) for f in ("auto", "mseed", "sac"))
    assert auto == mseed == "MSEED" and sac == "SAC"
    assert key_difference({"seismic_format": auto}, {"seismic_format": mseed}) is None
    assert "-ssi_seismic_format is SAC here and was MSEED" in key_difference({"seismic_format": auto},
                                                                             {"seismic_format": sac})
    assert key_difference({"seismic_format": "obspy"}, {"seismic_format": mseed}) is None
