"""Nothing lost, nothing silent, round three (issue 44): silent wrong answers, each now refused in
one line naming the option (or said in a note).

  * ``--glance`` against a "twin" that ran another record (its SHA-256) or another scale (the
    processed record): refused (before: a table of SSI effects that were the records' difference);
  * ``-ssi_seismic_start nan`` (before: NaN in every dataset, exit 0) and ``-1`` on a fixed base
    (before: the first second of the record dropped): refused.
"""
import numpy as np
import pytest

from test_post_glance import write_ssi, write_fixed, run as glance

pytestmark = pytest.mark.mpi


def test_glance_refuses_a_twin_of_another_record_or_scale(tmp_path, capsys):
    import h5py
    s = write_ssi(str(tmp_path))
    fx = write_fixed(str(tmp_path))
    assert glance([s, "--glance", fx], capsys)[0] == 0
    with h5py.File(fx, "r+") as f:
        f["seismic/x_acceleration"][...] = 2.0 * f["seismic/x_acceleration"][()]        # -ssi_seismic_scale 2
    st, out, err = glance([s, "--glance", fx], capsys)
    assert st == 2 and "processed x records differ" in err and "-ssi_seismic_scale" in err, err
    assert len(err.strip().splitlines()) == 1
    fx = write_fixed(str(tmp_path), name="fixed2.h5")
    for path, sha in ((s, "a" * 64), (fx, "b" * 64)):
        with h5py.File(path, "r+") as f:
            f["seismic/x_sha256"] = np.bytes_(sha)
    st, out, err = glance([s, "--glance", fx], capsys)
    assert st == 2 and "the runs' records differ (x: SHA-256 aaaaaaaaaaaa..." in err, err


def _fem_record(tmp_path, cols=1):
    t = np.arange(0.0, 1.0, 0.005)
    a = np.sin(2 * np.pi * 3 * t) * np.hanning(t.size)
    path = str(tmp_path / "rec.txt")
    np.savetxt(path, np.c_[t, np.outer(a, np.ones(cols))], header="units: m/s2")
    return path


FEM = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_t_end", "0.02", "-ssi_dt", "0.005",
       "-ssi_output", "", "-ssi_seismic", "vertical"]


@pytest.mark.parametrize("n", [1, 2])
def test_a_fixed_base_start_that_is_not_a_shift_or_floats_is_refused(tmp_path, n):
    from helpers import cli
    from test_integrity import refused
    one, three = _fem_record(tmp_path), _fem_record(tmp_path / "..", 3)
    cases = [(["-ssi_fem_fixed", "base", "-ssi_seismic_record", one, "-ssi_seismic_start", "nan"],
              "-ssi_seismic_start 'nan': expected auto or a finite number of seconds"),
             (["-ssi_fem_fixed", "base", "-ssi_seismic_record", one, "-ssi_seismic_start", "-1"],
              "-ssi_seismic_start -1: a negative shift drops the first 1 s of the record"),
             (["-ssi_seismic_record", one], "drives x but no translation along x is fixed (-ssi_fem_fixed (none))"),
             (["-ssi_fem_fixed", "base:x", "-ssi_seismic_record", three],
              "drives y, z but no translation along y or z is fixed (-ssi_fem_fixed base:x)")]
    for extra, msg in cases[n - 1::2]:          # (the checks are replicated: half the cases at each rank count)
        err = refused(cli(FEM + extra, nranks=n, check=False))
        assert msg in err, (extra, err)


def test_a_ratio_against_a_component_without_motion_says_so(tmp_path, capsys):
    import io
    from petsc_ssi.app import response as rsp
    t = np.arange(0.0, 2.0, 0.01)
    a = np.sin(2 * np.pi * t)
    for name, scale in (("a.txt", 1.0), ("b.txt", 0.5), ("z.txt", 1e-20)):
        np.savetxt(str(tmp_path / name), np.c_[t, scale * a])
    for b, noted in (("b.txt", False), ("z.txt", True)):
        out = io.StringIO()
        st = rsp.main(["--response-spectrum", "--table", str(tmp_path / "a.txt"), "--ratio-table",
                       str(tmp_path / b), "--periods", "0.5,1"], out=out)
        assert st == 0, capsys.readouterr().err
        text = out.getvalue()
        assert ("note: B's a component (z.txt) peaks at 1e-20 m/s^2 against A's 1: it carries no motion" in text) \
            == noted, text


@pytest.mark.parametrize("text,words", [
    ("PEER\nev, st, E\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS=   4, DT= 100.0 SEC\n0 1 -1 0\n",
     "DT = 100.0 s on line 4: a strong-motion record is sampled every 1 s or faster"),
])
def test_a_peer_record_sampled_implausibly_is_refused(tmp_path, text, words):
    from petsc_ssi.seismic import records as R
    path = tmp_path / "r.AT2"
    path.write_text(text)
    with pytest.raises(R.RecordError) as e:
        R.read_record(str(path))
    assert words in str(e.value), e.value


def test_record_refusals_name_the_options(tmp_path):
    from petsc_ssi.seismic import records as R
    path = tmp_path / "t.txt"
    path.write_text("0 1\n0.01 2\n0.02 0\n")
    for kw, words in (({}, "give them with -ssi_seismic_units (post: --table-units)"),
                      ({"units": "m/s2", "component": "x"}, "(-ssi_seismic_component or -ssi_seismic_traces)")):
        with pytest.raises(R.RecordError) as e:
            R.read_record(str(path), **kw)
        assert words in str(e.value) and "units=" not in str(e.value) and "component=" not in str(e.value), e.value


def test_input_motion_keeps_the_control_point_where_disp_ref_moves(tmp_path):
    """-ssi_disp_ref says about which point the footing's motion is told, not where the wave is
    controlled: the wave's start t0 (and so every series) is the same with and without it (before:
    the control point moved to x_ref and an oblique wave's series shifted in time)."""
    import h5py
    from helpers import run_bem
    sys_path = __import__("sys").path
    sys_path.insert(0, str(__import__("pathlib").Path(__file__).parent / "bem"))
    from test_input_motion import pulse, base
    rec = pulse(tmp_path / "p.txt", 0.1)
    t0 = []
    for name, extra in (("a.h5", {}), ("b.h5", {"disp_ref": "0.5,0,0"})):
        run_bem(**base(tmp_path, name, rec, symmetry="y=anti", t_end=0.03, **extra))
        with h5py.File(tmp_path / name, "r") as f:
            t0.append(float(f["seismic/t0"][()]))
    assert t0[0] == t0[1], t0


def test_a_wave_needs_a_scatterer_and_a_footing_soil_around_it(tmp_path):
    """Refused before the assembly: a massless footing that is the whole meshed surface or reaches
    its edge (before: input-motion ran it), and a wave on the half-space with nothing in it (before:
    a zero scattered field was marched)."""
    import sys
    import pathlib
    sys.path.insert(0, str(pathlib.Path(__file__).parent / "bem"))
    from helpers import resolve_error
    from test_input_motion import pulse, base
    rec = pulse(tmp_path / "p.txt", 0.1)
    o = base(tmp_path, "r.h5", rec)
    o.pop("output")
    groups = ("common", "bem", "seismic")
    err = resolve_error(groups, **dict(o, disp_group="box:-1,1,-1,1"))
    assert "the footing is the whole meshed surface; a massless footing (input-motion) needs" in err, err
    err = resolve_error(groups, **dict(o, disp_group="box:-0.5,1,-0.5,0.5"))
    assert "the footing reaches the edge of the meshed surface" in err, err
    nothing = {k: v for k, v in o.items() if not k.startswith("disp")}
    err = resolve_error(groups, **nothing)
    assert "-ssi_seismic sh on the half-space alone with nothing in it" in err, err
    assert resolve_error(groups, **o) is None


def test_a_wave_with_a_zero_soil_load_is_not_called_load_free(tmp_path, capfd):
    """runs/seismic/building.opts zeroes the demo's soil load (-ssi_load_p0 0) under the wave of a
    coupled run: no warning that the soil carries no load (the wave loads it); without a wave it stays."""
    import sys
    import pathlib
    sys.path.insert(0, str(pathlib.Path(__file__).parent / "bem"))
    from helpers import petsc
    from test_input_motion import pulse, base
    from petsc_ssi import options
    import petsc_ssi.app.kinds  # noqa: F401
    from petsc_ssi.bem.halfspace import HalfSpace
    from petsc_ssi.petsc import SSIError
    PETSc = petsc()
    o = {k: v for k, v in base(tmp_path, "r.h5", pulse(tmp_path / "p.txt", 0.1)).items()
         if not k.startswith("disp") and k != "output"}
    o.update(load_group="load", load_p0=0)
    db = PETSc.Options()
    for wave, said in ((True, False), (False, True)):
        opts = o if wave else {k: v for k, v in o.items() if not k.startswith("seismic")}
        for k, v in opts.items():
            db.setValue("ssi_" + k, str(v))
        try:
            capfd.readouterr()
            cfg = options.resolve(("common", "bem", "seismic"))
            try:
                HalfSpace(cfg, PETSc.COMM_WORLD, log=lambda m: None)
            except SSIError as exc:       # a wave on a soil with nothing in it is refused after the warnings
                assert wave and "with nothing in it" in str(exc), exc
            assert ("the soil carries no load of its own" in capfd.readouterr().out) == said, wave
        finally:
            for k in opts:
                db.delValue("ssi_" + k)


@pytest.mark.parametrize("opts,words", [
    ({"cp": 1e7}, "-ssi_cp 1e+07 m/s is faster than any soil or rock"),
    ({"mesh_size": "4,4", "mesh_h": 10, "mesh_patch": ""}, "-ssi_mesh_h 10 m is larger than the mesh (-ssi_mesh_size 4,4)"),
])
def test_soil_numbers_out_of_range_are_refused(opts, words):
    from helpers import resolve_error
    o = dict(mesh_size="4,4", mesh_h=1, mesh_patch="1,1", load_group="load", load_p0=1000, dt=0.005, t_end=0.01)
    o.update(opts)
    err = resolve_error(("common", "bem"), **o)
    assert err is not None and words in err, err


def test_an_unusual_soil_is_said_once_before_the_assembly(tmp_path):
    """A soil of c_s 5 m/s or rho 10 kg/m^3 (issue 44: a wrong unit ran without a word) gets one warning
    line naming the option and the range; soils and rocks, and the tests' reduced soil (c_s 20 m/s), none."""
    from petsc_ssi.bem.halfspace import soil_plausibility
    for cs, rho in ((100.0, 1800.0), (20.0, 1800.0), (3500.0, 2700.0)):
        assert soil_plausibility(cs, rho) is None
    assert "-ssi_cs 5 m/s" in soil_plausibility(5.0, 1800.0) and "rho" not in soil_plausibility(5.0, 1800.0)
    assert "-ssi_cs 0.2 m/s" in soil_plausibility(0.2, 1.8) and "-ssi_rho 1.8 kg/m^3" in soil_plausibility(0.2, 1.8)
    assert "-ssi_rho 9000 kg/m^3" in soil_plausibility(100.0, 9000.0)
    from helpers import cli
    p = cli(["-ssi_problem", "bem", "-ssi_mesh_size", "4,4", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
             "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_cs", "5", "-ssi_cp", "10", "-ssi_rho", "10",
             "-ssi_dt", "0.02", "-ssi_t_end", "0.04", "-ssi_output", str(tmp_path / "s.h5"), "-ssi_warn_beta", "0"],
            nranks=2)
    lines = [ln for ln in p.stdout.splitlines() if "unusual soil" in ln]
    assert len(lines) == 1 and "-ssi_cs 5 m/s" in lines[0] and "-ssi_rho 10 kg/m^3" in lines[0], p.stdout[-2000:]
    assert p.stdout.index("unusual soil") < p.stdout.index("[ssi] assembly")


@pytest.mark.parametrize("n", [1, 2])
def test_a_geo_mesh_smaller_than_its_element_size_is_refused(tmp_path, n):
    """Issue 44: -ssi_mesh_h 10 on a .geo of 4 m x 4 m (meshes/halfspace.geo) ran with elements of the
    mesh's extent, not the size asked; now refused in one line on every rank before any assembly, as
    the grid generator's is."""
    from helpers import cli
    p = cli(["-ssi_problem", "bem", "-ssi_mesh", "meshes/halfspace.geo", "-ssi_mesh_size", "4,4", "-ssi_mesh_h", "10",
             "-ssi_mesh_patch", "1,1", "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.005",
             "-ssi_t_end", "0.01", "-ssi_output", str(tmp_path / "s.h5")], nranks=n, check=False)
    errs = [ln for ln in p.stderr.splitlines() if ln.startswith("petsc-ssi: error:")]
    assert p.returncode != 0 and len(errs) == 1, p.stdout[-2000:]
    assert "-ssi_mesh_h 10 m is larger than the mesh meshes/halfspace.geo (4 m x 4 m)" in errs[0], errs[0]
    assert "[ssi] assembly" not in p.stdout


def test_record_processing_refusals_name_the_options():
    from petsc_ssi.seismic import records as R
    t = np.arange(0.0, 1.0, 0.01)
    rec = R.Record(t=t, values=np.sin(2 * np.pi * t) * np.hanning(t.size), quantity="acceleration", units_in="m/s2",
                   source="rec.txt", sha256="0", dt=0.01)
    for kw, words in (({"scale": 0.0}, "-ssi_seismic_scale 0.0: must be finite"),
                      ({"taper": 0.7}, "-ssi_seismic_taper 0.7:"), ({"highpass": -1.0}, "-ssi_seismic_highpass -1.0 Hz")):
        with pytest.raises(R.RecordError) as e:
            R.process(rec, **kw)
        assert words in str(e.value), e.value


def test_obspy_warnings_reach_the_run_and_a_corrupt_record_is_refused(tmp_path, monkeypatch):
    """ObsPy's warnings while reading (e.g. a corrupt miniSEED record, whose samples it skips) were
    swallowed: now a RecordWarning (a run note), and one about corrupt data refuses the file."""
    import warnings
    obspy = pytest.importorskip("obspy")
    from petsc_ssi.seismic import records as R
    tr = obspy.Trace(np.sin(np.arange(200) * 0.1), header={"channel": "HNZ", "sampling_rate": 100.0})
    path = str(tmp_path / "one.mseed")
    obspy.Stream([tr]).write(path, format="MSEED")
    real = obspy.read
    for said, refused in (("a gap of 2 samples was filled", False), ("corrupt record at 512 (skipped)", True)):
        def read(*a, _said=said, **k):
            warnings.warn(_said, UserWarning)
            return real(*a, **k)
        monkeypatch.setattr(obspy, "read", read)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            if refused:
                with pytest.raises(R.RecordError) as e:
                    R.read_record(path, units="m/s2")
                assert "a warning that data are corrupt (corrupt record at 512" in str(e.value), e.value
            else:
                R.read_record(path, units="m/s2")
                assert any(issubclass(w.category, R.RecordWarning) and "ObsPy: a gap of 2 samples" in str(w.message)
                           for w in caught), [str(w.message) for w in caught]


def test_a_stride_beyond_the_last_step_is_said(tmp_path):
    """-ssi_output_stride 100 on a 7-step run writes no field snapshot (the fields are written every 100 steps):
    one warning line says so; a stride that writes some, or 0 (receivers only, asked for), says nothing."""
    import os
    from helpers import ROOT, cli
    base = ["-options_file", os.path.join(ROOT, "runs", "pekeris", "small.opts"), "-ssi_t_end", "0.005"]
    for stride, said in (("100", True), ("3", False), ("0", False)):
        out = cli(base + ["-ssi_output_stride", stride, "-ssi_output", str(tmp_path / f"s{stride}.h5")]).stdout
        assert ("no field snapshot is written" in out) == said, (stride, out[-1500:])
