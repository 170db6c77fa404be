"""Record processing that does no harm by default (issue 43): ``-ssi_seismic_baseline auto`` (the
default) leaves a record that already ends at rest as it is, corrects one that drifts, says what it
chose and why, and an explicit correction that leaves the motion further from rest than none warns
naming the option.

The clean record is the second derivative of a displacement that starts and ends at rest
(sin^4 envelope times sines of 0.15 to 2.3 Hz, 20 s at 10 ms): the poly6 baseline, which fits part of
its 0.15 Hz motion, leaves it at a final velocity of 61 % of PGV (the issue's 'clean record damaged'),
so the default must not apply it. The drifting record is the same with an acceleration offset of
1e-3 of its PGA (the seismic-input note's test: raw v_end / PGV 0.2).
"""
import warnings

import numpy as np
import pytest

from petsc_ssi.seismic import records as R
from petsc_ssi.seismic.records import Record, RecordWarning

pytestmark = pytest.mark.unit

T, DT = 20.0, 0.01
F, PH = [0.15, 0.4, 1.1, 2.3], [0.3, 1.0, 2.0, 0.5]


def _d(t):
    return np.sin(np.pi * t / T) ** 4 * sum(np.sin(2 * np.pi * f * t + p) / (2 * np.pi * f) ** 2 for f, p in zip(F, PH))


def _a(t):
    h = 1e-4                                           # (the displacement's own second derivative, to 1e-8)
    return (_d(t + h) - 2 * _d(t) + _d(t - h)) / h ** 2


def _record(values, t):
    return Record(t=t, values=values, quantity="acceleration", units_in="m/s2", source="<synthetic>", sha256="",
                  dt=DT)


def _process(rec, **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = R.process(rec, **kw)
    return m, [str(w.message) for w in caught if w.category is RecordWarning]


def test_clean_record_stays_unchanged_with_the_defaults():
    t = np.arange(0.0, T + DT / 2, DT)
    a = _a(t)
    m, notes = _process(_record(a, t))
    assert m.processing["baseline"] == "none" and m.processing["baseline_option"] == "auto"
    assert notes == []
    # the motion is the record times the default 5 % Hann taper, to round-off; PGA unchanged
    np.testing.assert_allclose(m.a, a * R.hann_taper(t, 0.05), rtol=0, atol=1e-12 * np.abs(a).max())
    assert m.stats["pga"] == pytest.approx(m.stats_raw["pga"], rel=1e-9)
    assert abs(m.stats["v_end"]) < 0.01 * m.stats["pgv"]
    line = [x for x in m.summary_lines() if x.startswith("baseline auto")]
    assert line and "-> none" in line[0] and "at rest: nothing to correct" in line[0]
    # what the default avoids: poly6 on the same record, and its warning names the cause and the option
    p, pnotes = _process(_record(a, t), baseline="poly6")
    assert abs(p.stats["v_end"]) > 0.1 * p.stats["pgv"]
    assert any("further from rest than no correction" in x and "-ssi_seismic_baseline none" in x for x in pnotes)
    assert all("\n" not in x for x in pnotes)


def test_record_with_an_offset_is_corrected_by_default():
    t = np.arange(0.0, T + DT / 2, DT)
    a = _a(t)
    off = a + 1e-3 * np.abs(a).max()
    m, notes = _process(_record(off, t))
    raw = m.stats_raw
    assert abs(raw["v_end"]) > 0.05 * raw["pgv"]                       # it drifts as read
    assert m.processing["baseline"] in ("mean", "poly6")
    assert abs(m.stats["v_end"]) < 0.01 * m.stats["pgv"] and abs(m.stats["d_end"]) < 0.1 * m.stats["pgd"]
    assert abs(m.stats["pga"] / raw["pga"] - 1) < 0.02
    assert notes == []
    line = [x for x in m.summary_lines() if x.startswith("baseline auto")][0]
    assert "% of PGV" in line and m.processing["baseline"] in line.split(":")[0]


def test_three_components_choose_each_their_own():
    """A 't ax ay az' record whose x is clean and y drifts: x keeps its record, y is corrected."""
    t = np.arange(0.0, T + DT / 2, DT)
    a = _a(t)
    cols = np.stack([a, a + 1e-3 * np.abs(a).max(), 0.5 * a], axis=1)
    m, _ = _process(_record(cols, t))
    kinds = m.processing["baseline"].split("/")
    assert kinds[0] == "none" and kinds[1] in ("mean", "poly6") and kinds[2] == "none"
    np.testing.assert_allclose(m.a[:, 0], a * R.hann_taper(t, 0.05), rtol=0, atol=1e-12 * np.abs(a).max())
    assert np.all(np.abs(m.stats["v_end"]) < 0.01 * np.asarray(m.stats["pgv"]))
