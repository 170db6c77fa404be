"""Nothing lost, nothing silent, round three (issue 44): crashes and a hang, each now a one-line
refusal (or an answer) before any heavy work.

  * ``post --response-spectrum --periods 0`` (the help allows 0, the rigid limit): the PGA (before:
    ZeroDivisionError);
  * ``--oversample 100000000`` (or an automatic one from a tiny period): refused by the bound on the
    oscillators' sub-steps (before: ran for days);
  * a lock file of random bytes: refused in one line naming it (before: UnicodeDecodeError);
  * a checkpoint whose attributes were edited (the step): refused by the SHA-256 of its attributes
    (before: no checksum covered them); a truncated checkpoint: one line and no traceback (before:
    19 lines of h5py's traceback above the line; -ssi_debug prints it);
  * ``-ssi_seismic_highpass 1e-7``: refused by the memory its pads would take (before: a 44.7 GiB
    allocation, MemoryError).
"""
import io
import os

import h5py
import numpy as np
import pytest

from helpers import cli
from test_integrity import SMALL, refused, files

pytestmark = pytest.mark.mpi


def _table(tmp_path):
    t = np.arange(0.0, 2.0, 0.01)
    path = str(tmp_path / "acc.txt")
    np.savetxt(path, np.c_[t, np.sin(2 * np.pi * t)])
    return path


def _rsp(argv, capsys):
    from petsc_ssi.app import response as rsp
    out = io.StringIO()
    status = rsp.main([str(a) for a in argv], out=out)
    return status, out.getvalue(), capsys.readouterr().err


def test_period_zero_alone_is_the_pga(tmp_path, capsys):
    csv = str(tmp_path / "s.csv")
    st, out, err = _rsp(["--response-spectrum", "--table", _table(tmp_path), "--periods", "0", "--csv", csv], capsys)
    assert st == 0, err
    lines = [ln for ln in open(csv).read().splitlines() if not ln.startswith("#")][1:]
    row = np.array([[float(v) for v in ln.split(",")] for ln in lines])
    assert row.shape[0] == 1 and row[0, 0] == 0.0 and abs(row[0, 3] - 1.0) < 1e-12       # PSA(0) = PGA


@pytest.mark.parametrize("extra,msg", [(["--oversample", "100000000"], "--oversample 100000000: "),
                                       (["--periods", "1e-7,1", "--peaks", "nodes"], "--oversample auto (10 dt / T_min"),
                                       (["--periods", "1e-7,1"], "--periods: the shortest period 1e-07 s needs")])
def test_oversampling_beyond_the_work_bound_is_refused(tmp_path, capsys, extra, msg):
    st, out, err = _rsp(["--response-spectrum", "--table", _table(tmp_path)] + extra, capsys)
    assert st == 2 and msg in err and "sub-steps" in err and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("n", [1, 2])
def test_a_lock_of_random_bytes_is_refused_in_one_line(tmp_path, n):
    out = str(tmp_path / "o.h5")
    with open(out + ".lock", "wb") as fh:
        fh.write(bytes(np.random.default_rng(4).integers(0, 256, 512, dtype=np.uint8)))
    err = refused(cli(SMALL + ["-ssi_output", out], nranks=n, check=False))
    assert f"{out}.lock exists and is not a petsc-ssi lock" in err and f"remove {out}.lock" in err, err
    assert sorted(os.listdir(tmp_path)) == ["o.h5.lock"]


@pytest.fixture(scope="module")
def checkpointed(tmp_path_factory):
    d = tmp_path_factory.mktemp("ck")
    cli(SMALL + ["-ssi_output", str(d / "r.h5"), "-ssi_checkpoint", str(d / "ck-%d.h5"), "-ssi_checkpoint_every", "2"])
    return d


@pytest.mark.parametrize("n", [1, 2])
def test_an_edited_or_truncated_checkpoint_is_refused_in_one_line(checkpointed, tmp_path, n):
    import shutil
    run = tmp_path / "run"
    shutil.copytree(checkpointed, run)
    out = str(run / "r.h5")
    edited = str(tmp_path / "edited.h5")
    shutil.copy(run / "ck-4.h5", edited)
    with h5py.File(edited, "a") as f:
        f.attrs["step"] = 2                           # a restart would take the step-4 state as step 2's
    cut = str(tmp_path / "cut.h5")
    with open(run / "ck-4.h5", "rb") as src, open(cut, "wb") as dst:
        dst.write(src.read(os.path.getsize(run / "ck-4.h5") // 2))
    before = files(run)
    r = cli(SMALL + ["-ssi_output", out, "-ssi_restart", edited], nranks=n, check=False)
    err = refused(r)
    assert f"-ssi_restart {edited}: its attributes (step, options, run id, checksums) differ from their SHA-256" \
        in err, err
    r = cli(SMALL + ["-ssi_output", out, "-ssi_restart", cut], nranks=n, check=False)
    err = refused(r)
    assert f"-ssi_restart {cut}: cannot read it" in err and "h5py" not in r.stderr, (err, r.stderr[-3000:])
    assert files(run) == before
    if n == 1:                                        # the intact one restarts
        r = cli(SMALL + ["-ssi_output", out, "-ssi_restart", str(run / "ck-4.h5")])
        assert "restarted from" in r.stdout


def test_a_highpass_whose_pads_do_not_fit_is_refused():
    from petsc_ssi.seismic import records as R
    t = np.arange(0.0, 10.0, 0.005)
    rec = R.Record(t=t, values=np.sin(2 * np.pi * t) * np.hanning(t.size), quantity="acceleration",
                   units_in="m/s2", source="rec.txt", sha256="0", dt=0.005)
    with pytest.raises(R.RecordError) as e:
        R.process(rec, highpass=1e-7, taper=0.05)
    assert "-ssi_seismic_highpass 1e-07 Hz pads the record" in str(e.value) and "give a corner of at least" \
        in str(e.value), e.value
    R.process(rec, highpass=0.1, taper=0.05)          # a usual corner passes


def test_a_spectrum_pad_beyond_the_memory_is_refused():
    """``post --spectrum --pad 1e12``: refused by the memory its FFT would take (before: MemoryError
    and a traceback)."""
    from petsc_ssi.spectrum import amplitude_spectrum, SpectrumError
    t = np.arange(0.0, 1.0, 0.01)
    with pytest.raises(SpectrumError) as e:
        amplitude_spectrum(t, np.sin(2 * np.pi * t), pad=1e12)
    assert "--pad 1e+12:" in str(e.value) and "more than half the memory" in str(e.value), e.value
    amplitude_spectrum(t, np.sin(2 * np.pi * t), pad=4)
