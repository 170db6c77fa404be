"""The de-duplication of the shared element cache (bem/lagset.py): each distinct (key, lo, hi) request
is integrated once, from its first occurrence (the lowest rank's representative), also when two
different keys share a hash."""
import numpy as np
import pytest

from petsc_ssi.bem.lagset import _first_occurrences, _mix64

pytestmark = pytest.mark.unit


@pytest.mark.parametrize("collide", [False, True])
def test_first_occurrences(collide):
    rng = np.random.default_rng(3)
    base = rng.integers(-5, 5, size=(40, 27))
    pick = rng.integers(0, 40, size=500)
    keys = base[pick]
    lohi = np.c_[pick % 3 + 1, pick % 3 + 4]
    meta = np.c_[lohi, np.zeros((500, 4), np.int64)]
    h = (pick // 2 if collide else pick).astype(np.int64) * 7919      # collide: two keys per hash
    full = np.c_[keys, lohi]
    first, inv = _first_occurrences(h, meta, lambda: full)
    assert len(first) == len(np.unique(full, axis=0))
    assert np.array_equal(full[first[inv]], full)                    # every request maps to its own key
    for g, f in enumerate(first):                                     # ... and to its first occurrence
        assert f == np.nonzero((full == full[f]).all(axis=1))[0].min()
    assert len(_first_occurrences(h[:0], meta[:0], lambda: full[:0])[0]) == 0


def test_owner_hash_is_balanced():
    """Owner = mixed hash mod p: the raw FNV-style hashes of the cache all had the same parity on the
    medium case (one rank owned every geometry); mixed, 4 ranks get 25 +- 3 % each of 20000 keys
    whose low bits are all equal."""
    h = (np.arange(20000, dtype=np.int64) * 1024 + 7)
    counts = np.bincount(np.mod(_mix64(h), 4).astype(np.int64), minlength=4) / 20000
    assert np.all(np.abs(counts - 0.25) < 0.03), counts
