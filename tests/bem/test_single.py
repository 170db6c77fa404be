"""Lags kept in single precision (-ssi_lag_single_from; issue 13, item 3): the lags from a given one
on (and the interpolating matrices that stand for them) are stored as float32 block-sparse, 40 B
per 3x3 block, and the products accumulate in double.

What is checked: the stored values are the double lags rounded to float32, bit for bit; the run
differs from the double run (so the float32 path is taken) by no more than 1e-6 of each field's
maximum (measured: about 1e-8; the rounding is 6e-8 per value); the time-blocked and per-step history
sums still agree to round-off with float32 lags, on 1 and 2 ranks, with interpolation and in a
coupled contact run; the stored bytes drop as the memory estimate says; a lag file of such a run
reloads bitwise and is refused by a double run; a lag below 3 is refused."""
import json

import numpy as np
import pytest

from helpers import cli, resolve_error
from test_history_block import BEM, INTERP, SSI, fields, same, log_line

pytestmark = pytest.mark.mpi


def stored_gb(out):
    """(estimated, stored) GB of lag matrices from the run's log."""
    est = float(log_line(out, "memory estimate: lag matrices")[0].split("lag matrices")[1].split()[0])
    st = float(log_line(out, "] assembly")[0].split("stored")[1].split()[0])
    return est, st


def rel_diff(a, b):
    """The largest difference of a recorded field relative to its maximum (moments of a symmetric
    run, round-off themselves, relative to the force times 1 m, as in ``same``)."""
    A, B = fields(a), fields(b)
    assert set(A) == set(B)
    out = 0.0
    for k in A:
        scale = np.abs(A[k]).max()
        if "moment" in k and k.replace("moment", "force") in A:
            scale = max(scale, np.abs(A[k.replace("moment", "force")]).max())
        if scale > 0:
            out = max(out, np.abs(A[k] - B[k]).max() / scale)
    return out


def test_buckets_round_the_far_lags_to_float32():
    """The buckets keep lags >= single_from in float32: the double buckets' values rounded, bit for
    bit, the columns and row pointers the same; lower lags stay double."""
    from petsc_ssi.bem.lagset import Buckets
    rng = np.random.default_rng(3)
    rows = np.arange(4)
    n = 40
    row = np.sort(rng.integers(0, 4, n))
    lag = rng.integers(1, 6, n)
    col = rng.integers(0, 7, n).astype(np.int64)
    val = rng.standard_normal((n, 9))
    out = []
    for sf in (0, 3):
        B = Buckets(5, rows, 7, single_from=sf)
        B.add(row, lag, col, val)
        out.append([B.csr(l) for l in range(1, 6)])
    for l in range(1, 6):
        (p0, c0, v0), (p1, c1, v1) = out[0][l - 1], out[1][l - 1]
        assert np.array_equal(p0, p1) and np.array_equal(c0, c1)
        assert v1.dtype == (np.float32 if l >= 3 else np.float64)
        assert np.array_equal(v1, v0.astype(v1.dtype))
        assert l < 3 or not np.array_equal(v1.astype(float), v0)      # rounded, not a copy


def test_single_lags_change_the_run_by_rounding_only(tmp_path):
    """Single precision from lag 3: 1e-6 of each field's maximum at most, and not zero; the block-
    sparse float32 Mats store less than the double ones (dense and block-sparse), as estimated."""
    ref, sgl = (str(tmp_path / f"{k}.h5") for k in ("ref", "sgl"))
    r0 = cli(BEM + ["-ssi_output", ref]).stdout
    r1 = cli(BEM + ["-ssi_output", sgl, "-ssi_lag_single_from", "3"]).stdout
    assert "single-precision block-sparse" in log_line(r1, "] assembly")[0]
    d = rel_diff(ref, sgl)
    assert 1e-12 < d <= 1e-6, d
    e0, s0 = stored_gb(r0)
    e1, s1 = stored_gb(r1)
    assert s1 < 0.75 * s0, (s0, s1)
    assert abs(e1 - s1) <= 0.15 * s1, (e1, s1)          # the memory estimate follows the storage
    assert "history sum: step by step" in r1, "the automatic choice changed: test_single_lags_time_blocked"


# slow tier: the float32 products time-blocked (5 s; the sibling above runs them step by step)
@pytest.mark.slow
def test_single_lags_time_blocked(tmp_path):
    """The float32 products per step (the automatic choice for this run) and time-blocked: the same sums in
    another order (observed 4.0e-16)."""
    sgl, blk = (str(tmp_path / f"{k}.h5") for k in ("sgl", "blk"))
    r1 = cli(BEM + ["-ssi_output", sgl, "-ssi_lag_single_from", "3"]).stdout
    assert "history sum: step by step" in r1, "the automatic choice changed: run sgl with -ssi_history_block 1"
    out = cli(BEM + ["-ssi_output", blk, "-ssi_lag_single_from", "3", "-ssi_history_block", "5"]).stdout
    assert "time-blocked, 5 steps per block" in out
    same(sgl, blk)


# slow tier: single-precision lags interpolated, coupled and at -n 2 (30 s; single == double by rounding and
#  the lag file's bitwise reload stay)
@pytest.mark.slow
def test_single_lags_interpolated_coupled_and_parallel(tmp_path):
    """With the far lags interpolated (the interpolating matrices single too), in a coupled run
    with unilateral contact, and on 2 ranks: within 1e-6 of the double run, and the 2-rank run the
    1-rank run to round-off: 1e-11 of the run's largest displacement or traction with the far lags
    interpolated (observed 1.4e-15), 1e-9 in the coupled run (observed 5.9e-12, the contact gap: the
    block lifts off and its free flight carries the round-off of the lift-off velocity,
    test_history_block's coupled case; the former 1e-11 left a margin of 1.7x)."""
    for name, args, rtol in (("interp", BEM + INTERP, 1e-11), ("ssi", SSI, 1e-9)):
        ref, sgl, par = (str(tmp_path / f"{name}-{k}.h5") for k in ("ref", "sgl", "par"))
        cli(args + ["-ssi_output", ref])
        r = cli(args + ["-ssi_output", sgl, "-ssi_lag_single_from", "3"]).stdout
        assert "single-precision" in r
        d = rel_diff(ref, sgl)
        assert 1e-13 < d <= 1e-6, (name, d)
        cli(args + ["-ssi_output", par, "-ssi_lag_single_from", "3", "-ssi_reproducible"], nranks=2)
        same(sgl, par, rtol=rtol)


# slow tier: single lags' file reload (6 s; the double lag file's bitwise reload stays)
@pytest.mark.slow
def test_single_lag_file_reloads_bitwise(tmp_path):
    """-ssi_lags_save of a single-precision run (written as double MPIBAIJ) and -ssi_lags_load in the
    same set-up: bitwise the run that assembled; a double run refuses the file, naming why."""
    lags = str(tmp_path / "soil.lags")
    a, b = str(tmp_path / "a.h5"), str(tmp_path / "b.h5")
    sf = ["-ssi_lag_single_from", "3"]
    cli(BEM + sf + ["-ssi_output", a, "-ssi_lags_save", lags])
    assert json.load(open(lags + ".json"))["key"]["single_from"] == "3"
    r = cli(BEM + sf + ["-ssi_output", b, "-ssi_lags_load", lags])
    assert "loaded from" in r.stdout
    A, B = fields(a), fields(b)
    for k in A:
        assert np.array_equal(A[k], B[k]), k
    r = cli(BEM + ["-ssi_output", str(tmp_path / "c.h5"), "-ssi_lags_load", lags], check=False)
    assert r.returncode != 0 and "single_from differs" in r.stdout + r.stderr


@pytest.mark.parametrize("value", ["1", "2", "-4"])
def test_low_lags_stay_double(value):
    msg = resolve_error(**dict(BEM_OPTS, lag_single_from=value))
    assert msg and "lag_single_from" in msg and "lags 1 and 2" in msg, msg


BEM_OPTS = {"problem": "bem", "mesh_size": "4,4", "mesh_h": 1, "mesh_patch": "1,1", "load_group": "load",
            "load_p0": 1000, "dt": 0.005, "t_end": 0.02}


def test_buckets_refuse_single_step_matrix_lags():
    from petsc_ssi.bem.lagset import Buckets
    for sf in (1, 2):
        with pytest.raises(ValueError, match="lags 1 and 2"):
            Buckets(4, np.arange(2), 3, single_from=sf)


def test_peak_counts_the_interpolating_assemblies():
    """The memory check's peak: the largest phase, including the assembly of each interpolating
    matrix after the exact Mats are built (its blocks and its own cache and chunk)."""
    from petsc_ssi.bem.cost import peak_bytes
    mats, trip = np.array([10.0, 10.0, 4.0, 4.0]), np.array([10.0, 10.0, 4.0, 4.0])   # 2 exact + 2 interpolating
    assert peak_bytes(mats, trip, [0.0], 5.0, 0.0, n_exact=2) == pytest.approx(1.1 * 28.0)     # last: 20 + 4 + 4
    assert peak_bytes(mats, trip, [0.0], 5.0, 0.0, n_exact=2, asm_interp=3.0) == pytest.approx(1.1 * 31.0)
    assert peak_bytes(mats[:2], trip[:2], [1.0], 5.0, 2.0) == pytest.approx(1.1 * (25.0 + 1.0 + 2.0))


def test_block_choice_counts_values_not_bytes():
    """A float32 block-sparse matrix has the flops of a double one with the same values in 40/76 of
    its bytes: the block choice takes the stored values when given."""
    from petsc_ssi.bem.cost import choose_block
    d = np.zeros(40)
    blocks = np.full(40, 2.0e6)
    assert choose_block(d, 76.0 * blocks) == choose_block(d, 76.0 * blocks, sparse_values=9 * blocks)
    b40, s40 = choose_block(d, 40.0 * blocks, sparse_values=9 * blocks)
    assert b40 >= 2 and 1 <= s40 <= b40


def test_an_option_added_since_a_checkpoint_counts_as_its_default():
    from petsc_ssi.io.checkpoint import key_difference
    assert key_difference({"dt": "0.001"}, {"dt": "0.001", "lag_single_from": "0"}) is None
    msg = key_difference({"dt": "0.001"}, {"dt": "0.001", "lag_single_from": "3"})
    assert msg and "-ssi_lag_single_from is 3 here and was 0" in msg


def test_a_threshold_beyond_the_lags_is_said(tmp_path):
    """-ssi_lag_single_from beyond every stored lag: one warning line, the run all-double."""
    r = cli(BEM + ["-ssi_t_end", "0.02", "-ssi_output", str(tmp_path / "w.h5"), "-ssi_lag_single_from", "500"])
    warns = [ln for ln in r.stdout.splitlines() if "-ssi_lag_single_from 500" in ln]
    assert len(warns) == 1 and "every lag stays in double precision" in warns[0], r.stdout[-2000:]
    assert "single-precision" not in log_line(r.stdout, "] assembly")[0]
