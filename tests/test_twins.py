"""Twins (issue 44): ``post --response-spectrum --ratio B.h5`` refuses, in one line, a B that did not
run the same earthquake as A (another record's SHA-256, another scale or processing, another
control, other axes), as ``post --glance`` does: both use app/twins.py. A coupled run's structure
file is judged by its soil output, which holds the seismic input. The files are the glance tests'
hand-made outputs (tests/test_post_glance.py)."""
import io

import numpy as np
import pytest

from petsc_ssi.app import response as rsp
from test_post_glance import write_ssi, write_fixed

pytestmark = pytest.mark.unit


def ratio(a, b, capsys):
    out = io.StringIO()
    st = rsp.main([a, "--ratio", b, "--periods", "0.1:1:4"], out=out)
    return st, out.getvalue(), capsys.readouterr().err


def test_ratio_refuses_a_twin_of_another_scale_record_or_control(tmp_path, capsys):
    import h5py
    s = write_ssi(str(tmp_path))
    ss = s[:-3] + "_structure.h5"                       # the coupled run's structure file
    fx = write_fixed(str(tmp_path))
    st, out, err = ratio(ss, fx, capsys)
    assert st == 0, err                                 # twins: the ratio is computed
    assert "ratio" in out
    with h5py.File(fx, "r+") as f:                      # -ssi_seismic_scale 2 on the fixed base
        f["seismic/x_acceleration"][...] = 2.0 * f["seismic/x_acceleration"][()]
    st, out, err = ratio(ss, fx, capsys)
    assert st == 2 and "processed x records differ" in err and "-ssi_seismic_scale" in err, err
    assert len(err.strip().splitlines()) == 1 and out == ""
    fx2 = write_fixed(str(tmp_path), name="fixed2.h5")
    for path, sha in ((s, "a" * 64), (fx2, "b" * 64)):
        with h5py.File(path, "r+") as f:
            f["seismic/x_sha256"] = np.bytes_(sha)
    st, _, err = ratio(ss, fx2, capsys)
    assert st == 2 and "records differ (x: SHA-256 aaaaaaaaaaaa..." in err, err
    inc = write_ssi(str(tmp_path), name="inc.h5", control="incident")
    st, _, err = ratio(inc[:-3] + "_structure.h5", ss, capsys)
    assert st == 2 and "-ssi_seismic_control differ" in err, err


def test_ratio_refuses_an_earthquake_against_none_and_keeps_plain_pairs(tmp_path, capsys):
    import h5py
    s = write_ssi(str(tmp_path))
    fx = write_fixed(str(tmp_path))
    with h5py.File(fx, "r+") as f:                      # a run without a record
        del f["seismic"]
    st, _, err = ratio(s[:-3] + "_structure.h5", fx, capsys)
    assert st == 2 and "holds none: not twins" in err and len(err.strip().splitlines()) == 1, err
    fx2 = write_fixed(str(tmp_path), name="plain.h5")
    with h5py.File(fx2, "r+") as f:
        del f["seismic"]
    st, _, err = ratio(fx, fx2, capsys)                 # neither ran an earthquake: not judged
    assert st == 0, err
