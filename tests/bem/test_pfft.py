"""The toeplitz store's distributed 2-D real FFTs (``bem.pfft``, mpi4py-fft's slab decomposition): each rank's
frequencies in the k_y-major order are scipy's ``rfft2`` of the whole planes there, the inverse gives each rank's
rows back, and ranks beyond min(Mx, My // 2 + 1) hold no rows and no frequencies."""
import os
import shutil

import pytest

from helpers import ranks_json

pytestmark = pytest.mark.mpi

CODE = r'''
import sys, json
import numpy as np
from mpi4py import MPI
from scipy.fft import rfft2
from petsc_ssi.bem.pfft import SlabFFT, slab_counts, kx_ky
comm = MPI.COMM_WORLD
out = []
for Mx, My in [(12, 10), (7, 4), (5, 3)]:
    A = np.random.default_rng(Mx).standard_normal((27, Mx, My))
    f = SlabFFT(comm, Mx, My)
    x0, x1 = f.rows
    assert list(f.counts) == list(slab_counts(Mx, My, comm.size))
    S = f.forward(np.ascontiguousarray(A[:, x0:x1]))
    ref = rfft2(A, axes=(-2, -1))
    kx, ky = kx_ky(Mx, My, f.f0, f.f1)
    e_f = float(np.abs(S - ref[:, kx, ky]).max(initial=0.0) / np.abs(ref).max())
    B = f.backward(S)
    e_b = float(np.abs(B - A[:, x0:x1]).max(initial=0.0) / np.abs(A).max())
    rows = comm.allgather((x0, x1))
    freq = comm.allgather((f.f0, f.f1))
    f.destroy()
    out.append(dict(grid=[Mx, My], member=f.member, fwd=e_f, bwd=e_b, rows=rows, freq=freq))
every = comm.gather(out, root=0)          # (one line from rank 0: mpirun may run the ranks' lines together)
if comm.rank == 0:
    print("PFFT" + json.dumps(every), flush=True)
'''


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
@pytest.mark.parametrize("n", [1, 2, 3])
def test_slab_fft_is_rfft2_on_each_ranks_frequencies(n):
    """Forward: each rank's slab equals ``rfft2`` of the whole planes at its (k_x, k_y), to 1e-14 of the largest
    coefficient; backward: the rank's rows, to 1e-14; the rows and the frequencies cover the grid and the half
    spectrum once, in rank order; on the 5 x 3 grid (two columns of the half spectrum) a third rank holds
    neither rows nor frequencies and the others still transform (7 x 4 at -n 3: three columns, every rank)."""
    per_rank = ranks_json(CODE, n, "PFFT")
    assert len(per_rank) == n
    for r in per_rank:
        for g in r:
            assert g["fwd"] <= 1e-14 and g["bwd"] <= 1e-14, g
            Mx, My = g["grid"]
            rows, freq = g["rows"], g["freq"]
            assert rows[0][0] == 0 and all(a[1] == b[0] for a, b in zip(rows, rows[1:]))
            assert max(b for _, b in rows) == Mx
            assert freq[0][0] == 0 and all(a[1] == b[0] for a, b in zip(freq, freq[1:]))
            assert freq[-1][1] == Mx * (My // 2 + 1)
    g53 = [g for r in per_rank for g in r if g["grid"] == [5, 3]]
    assert sum(g["member"] for g in g53) == min(n, 2)
    if n == 3:
        empty = [g for g in g53 if not g["member"]]
        assert empty[0]["rows"][2] == [5, 5] and empty[0]["freq"][2][0] == empty[0]["freq"][2][1]


# (six oversubscribed ranks in the slow tier: 14 s of make test's budget in its run of 2026-12-02; its sibling, three
# ranks of which one holds no frequencies, stays)
@pytest.mark.parametrize("n, limit, h, g, rtol", [pytest.param(3, 2, 2, 2, 5e-12, id="n3-fft_ranks2"),
                                                   pytest.param(6, 0, 5, 4, 5e-12, id="n6-beyond-the-slabs",
                                                                marks=pytest.mark.slow)])
def test_coupled_run_with_ranks_without_frequencies_equals_one_rank(tmp_path, n, limit, h, g, rtol):
    """The coupled foundation with unilateral contact on the toeplitz store at -n 3 with
    -ssi_toeplitz_fft_ranks 2, and at -n 6, where the H side's FFT grid of 8 x 8 has 5 columns of half spectrum
    and the G side's 4: ranks hold no frequencies (the log says so), and still send their nodes' states and take
    their nodes' sums; every recorded field equals -n 1's to 5e-12 of the run's largest value of its kind (at
    -n 3 and -n 6 the dense store itself moves this case's interface tractions by about 1e-12 from -n 1, its MUMPS
    sums over the ranks and the contact's active set; the toeplitz store about as much, with and without
    -ssi_reproducible, in runs just over and just under 1e-12: scratch comparisons and one failed run)."""
    import sys
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from test_history_block import SSI, same
    from helpers import cli
    args = SSI + ["-ssi_lag_store", "toeplitz", "-ssi_t_end", "0.25"]
    a, b = str(tmp_path / "n1.h5"), str(tmp_path / "n.h5")
    out1 = cli(args + ["-ssi_output", a]).stdout
    outn = cli(args + ["-ssi_output", b] + (["-ssi_toeplitz_fft_ranks", str(limit)] if limit else []), nranks=n).stdout
    assert "H on 1 of 1 rank(s)" in out1, out1[-2000:]
    line = [ln for ln in outn.splitlines() if "toeplitz transforms:" in ln]
    assert line and f"H on {h} of {n} rank(s)" in line[0] and f"G on {g} of {n}" in line[0], outn[-3000:]
    assert "hold no frequencies" in line[0]
    same(a, b, rtol)
