r"""The toeplitz store's 2-D real FFTs over the ranks (issue 41: "through an existing distributed engine"):
mpi4py-fft's slab decomposition (``mpi4py_fft.PFFT``, FFTW underneath), a batch of planes at a time.

A plane of the FFT grid Mx x My is split over the ranks by rows (x) in physical space and by columns of the
half spectrum (k_y = 0 .. My // 2) in Fourier space: mpi4py-fft transforms along y on each rank's rows, moves
the data by its own all-to-all (MPI subarray types), and transforms along x on each rank's columns. So each
rank holds, of every kernel and kept state, the frequencies (k_x, k_y) with k_y in its columns and every k_x:
stored k_y-major (frequency index f = (k_y - k_y0) Mx + k_x on the rank, ``kx_ky``), so that the ranks'
slabs, one after the other, are the whole spectrum in one order whatever the number of ranks (the lag
files' order, ``lagstore``). A slab decomposition takes at most min(Mx, My // 2 + 1) ranks: beyond that the
first ones transform and the others hold no rows and no frequencies (``members``).

Used for the kernels' build on more than one rank (each rank's share of a chunk's planes summed onto the planes' row blocks,
transformed) and per step for the new state's transform and the sums' inverse transform: no rank gathers a
whole state or a whole spectrum (what each rank transformed in full before)."""
import importlib

import numpy as np

from ..petsc import SSIError

# FFTW's plan from its heuristics: the same plan, so the same bits, in every run (FFTW_MEASURE times
# candidate plans and may pick another one run to run)
PLANNER = "FFTW_ESTIMATE"


def blockdist(n, size, rank):
    """(count, start) of ``rank``'s block of n items over ``size`` ranks: mpi4py-fft's own rule
    (``mpi4py_fft.pencil._blockdist``; checked against its local slices on every plan)."""
    q, r = divmod(int(n), int(size))
    return q + (1 if r > rank else 0), rank * q + min(rank, r)


def members(Mx, My, p, limit=0):
    """The ranks that transform a plane Mx x My (the first ones): a slab decomposition splits the rows and the
    half spectrum's columns, so at most min(Mx, My // 2 + 1) of them; and at most ``limit`` (> 0:
    -ssi_toeplitz_fft_ranks)."""
    return max(1, min(int(p), int(Mx), int(My) // 2 + 1, int(limit) if limit else int(p)))


def slab_counts(Mx, My, p, limit=0):
    """(p,) the frequencies each rank holds of the half spectrum Mx x (My // 2 + 1): Mx times its columns."""
    q = members(Mx, My, p, limit)
    return np.array([Mx * blockdist(My // 2 + 1, q, r)[0] if r < q else 0 for r in range(int(p))], np.int64)


def kx_ky(Mx, My, f0, f1):
    """(kx, ky) of the frequencies f0 .. f1 - 1 of the k_y-major order (f = ky Mx + kx)."""
    f = np.arange(int(f0), int(f1))
    return f % Mx, f // Mx


def require(comm):
    """Collective (``comm`` petsc4py or mpi4py): one line on every rank if mpi4py-fft is missing on any rank,
    before heavy work (the store's check of its memory calls it)."""
    mpi = comm.tompi4py() if hasattr(comm, "tompi4py") else comm
    try:
        importlib.import_module("mpi4py_fft")
        why = ""
    except ImportError as e:
        why = str(e)
    bad = mpi.allgather(why)
    missing = [f"rank {r}: {w}" for r, w in enumerate(bad) if w]
    if missing:
        raise SSIError(f"-ssi_lag_store toeplitz needs mpi4py-fft ({missing[0]}{' and others' if len(missing) > 1 else ''}): "
                       "`make deps`, or `pip install mpi4py-fft` with FFTW's library and headers (Debian: libfftw3-dev)")


class SlabFFT:
    """Collective (``comm``, an mpi4py communicator): the 2-D real FFTs of batches of Mx x My planes over the
    ranks. ``rows`` (x0, x1): this rank's rows of a plane in physical space; ``f0``, ``f1``: its frequencies
    in the k_y-major order (``counts`` every rank's); ``forward(a)`` (nb, x1 - x0, My) real -> (nb, f1 - f0)
    complex, unnormalised (scipy's ``rfft2``); ``backward(s)`` the inverse, normalised (``irfft2``)."""

    def __init__(self, comm, Mx, My, limit=0):
        from mpi4py import MPI
        require(comm)
        self.Mx, self.My, self.Myh = int(Mx), int(My), int(My) // 2 + 1
        p, r = comm.Get_size(), comm.Get_rank()
        self.q = members(Mx, My, p, limit)
        self.member = r < self.q
        self.sub = comm.Split(0 if self.member else MPI.UNDEFINED, r)
        self.rows_of = [(lambda c, s: (s, s + c))(*blockdist(Mx, self.q, k)) if k < self.q else (Mx, Mx)
                        for k in range(p)]
        self.rows = self.rows_of[r]
        self.counts = slab_counts(Mx, My, p, limit)
        self.f0 = int(self.counts[:r].sum())
        self.f1 = self.f0 + int(self.counts[r])
        self.nky = self.counts[r] // self.Mx
        self._plans = {}

    def _plan(self, nb):
        """mpi4py-fft's plan of a batch of nb planes (kept per batch size until ``forget``), its local slices
        checked. Its forward transform preserves its input array (FFTW_PRESERVE_INPUT), so what a caller writes
        there stays between transforms (the per-step grid's zeros)."""
        if nb not in self._plans:
            from mpi4py_fft import PFFT
            P = PFFT(self.sub, (nb, self.Mx, self.My), axes=(1, 2), dtype=float, grid=(1, -1, 1),
                     planner_effort=PLANNER, overwrite_input="FFTW_PRESERVE_INPUT")
            si, so = P.local_slice(False), P.local_slice(True)
            ok = ((si[1].start, si[1].stop) == self.rows and so[2].stop - so[2].start == self.nky
                  and so[2].start * self.Mx == self.f0)
            from mpi4py import MPI
            if not self.sub.allreduce(ok, op=MPI.LAND):         # (every member, no hang)
                raise SSIError(f"mpi4py-fft's slabs are not the ones expected on some rank (here {si}, {so}; rows "
                               f"{self.rows}, frequencies {self.f0}..{self.f1}): report this with the grid {self.Mx} x "
                               f"{self.My} and the rank count")
            self._plans[nb] = P
        return self._plans[nb]

    def forget(self, keep=()):
        """The plans (their arrays and communicators) of every batch size but ``keep`` freed (collective over the
        members, which make and forget plans in the same order)."""
        for nb in [nb for nb in self._plans if nb not in keep]:
            self._plans.pop(nb).destroy()

    def inputs(self, nb):
        """(nb, x1 - x0, My) float64: the forward transform's input array of nb planes (this rank's rows), to be
        written in place; zeros when first made."""
        if not self.member:
            return np.zeros((nb, 0, self.My))
        return self._plan(nb).forward.input_array

    def transform(self, nb):
        """Collective over the members: the forward transform of ``inputs(nb)`` -> (nb, Mx, k_y columns)
        complex, unnormalised (scipy's ``rfft2``): mpi4py-fft's output array, valid until its next transform."""
        if not self.member:
            return np.zeros((nb, self.Mx, 0), np.complex128)
        return self._plan(nb).forward(normalize=False)

    def forward(self, a, keep=True):
        """(nb, x1 - x0, My) real, this rank's rows of nb planes -> (nb, f1 - f0) complex, their spectra's
        frequencies on this rank in the k_y-major order (a new array). Collective over the members. ``keep``:
        the plan kept for the next batch of nb planes, else freed."""
        nb = a.shape[0]
        self.inputs(nb)[...] = a
        out = np.ascontiguousarray(self.transform(nb).transpose(0, 2, 1)).reshape(nb, -1)
        if not keep and nb in self._plans:
            self._plans.pop(nb).destroy()
        return out

    def backward_inputs(self, nb):
        """(nb, Mx, k_y columns) complex: the inverse transform's input array, to be written in place."""
        if not self.member:
            return np.zeros((nb, self.Mx, 0), np.complex128)
        return self._plan(nb).backward.input_array

    def outputs(self, nb):
        """(nb, x1 - x0, My) float64: the inverse transform's output array (what ``run_backward`` fills)."""
        if not self.member:
            return np.zeros((nb, 0, self.My))
        return self._plan(nb).backward.output_array

    def run_backward(self, nb):
        """Collective over the members: the inverse of ``backward_inputs(nb)`` (which it overwrites) into
        ``outputs(nb)``, normalised (``irfft2``)."""
        if self.member:
            self._plan(nb).backward(normalize=True)
        return self.outputs(nb)

    def backward(self, s):
        """(nb, f1 - f0) complex, k_y-major -> (nb, x1 - x0, My) real (a new array): ``forward``'s inverse."""
        nb = s.shape[0]
        self.backward_inputs(nb)[...] = s.reshape(nb, self.nky, self.Mx).transpose(0, 2, 1)
        return self.run_backward(nb).copy()

    def flops(self, nb):
        """This rank's share of nb planes' 2-D real FFTs by the usual count, 2.5 N log2 N a plane of N = Mx My
        points (half the complex transform's 5 N log2 N): what -log_view's rate of the transforms divides."""
        n = self.Mx * self.My
        return nb * 2.5 * n * np.log2(max(n, 2)) / self.q if self.member else 0.0

    def destroy(self):
        """The members' sub-communicator freed (collective over them)."""
        from mpi4py import MPI
        self.forget()
        if self.sub is not None and self.sub != MPI.COMM_NULL:
            self.sub.Free()
        self.sub = None
