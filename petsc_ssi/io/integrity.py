"""Checksums of the CONTENT of files the code reads back (issue 30): -ssi_lags_save's lag files and
checkpoints. A file with damaged bytes is refused in one line naming it instead of being used.

The data are cut into pieces of a fixed size (``CHUNK`` bytes, independent of the rank count) and
each piece gets a CRC32 (zlib); piece j is read and summed by rank j mod P, and the P lists of
(piece, CRC) are allgathered -- a few bytes per piece, no data gathered -- so the same list comes
out on any number of ranks, and a file saved on 4 ranks is checked on 1 or 2.

  ``file_crcs``      the pieces of a whole file (the lag file: PETSc binary, every byte is data)
  ``dataset_crcs``   the pieces of every dataset of an HDF5 file, along its first axis (a
                     checkpoint: the data of each dataset, not its HDF5 bookkeeping)

Cost: one more read of the file (at save, just written and mostly in the page cache; at load,
before PETSc reads it, which then finds it in the cache) and CRC32 at ~1.8 GB/s per core; the
measured times are in the README (-ssi_lags_save).
"""
import os
import zlib

import numpy as np

from ..petsc import collective

CHUNK = 8 << 20          # bytes per checksummed piece


def _spread(n, comm):
    """The pieces 0..n-1 this rank sums."""
    return range(comm.getRank(), n, comm.getSize())


def _gather(mine, n, comm):
    """{piece: crc} of every rank -> the list of the n CRCs (every rank)."""
    out = [0] * n
    for part in comm.tompi4py().allgather(mine):
        for j, c in part.items():
            out[j] = c
    return out


def file_crcs(path, comm, chunk=CHUNK):
    """Collective: [CRC32 of bytes [j chunk, (j+1) chunk) of ``path``] for every piece j."""
    size = comm.tompi4py().bcast(os.path.getsize(path) if comm.getRank() == 0 else None, root=0)
    n = max(1, -(-size // chunk))
    mine = {}
    with collective(comm, f"checksumming {path}", "{what}: {error}"):
        with open(path, "rb") as fh:
            for j in _spread(n, comm):
                fh.seek(j * chunk)
                mine[j] = zlib.crc32(fh.read(chunk)) & 0xFFFFFFFF
    return _gather(mine, n, comm)


def first_bad_piece(saved, now, chunk=CHUNK):
    """The byte offset of the first piece whose CRC differs (or of a piece missing), or None."""
    saved = [int(c) for c in saved]
    for j in range(max(len(saved), len(now))):
        if j >= len(saved) or j >= len(now) or saved[j] != int(now[j]):
            return j * chunk
    return None


def _h5(path):
    import h5py
    try:
        return h5py.File(path, "r", locking=False)
    except (TypeError, ValueError):
        return h5py.File(path, "r")


def _pieces(ds, chunk):
    """[(row0, row1)] of a dataset cut along its first axis into pieces of about ``chunk`` bytes
    (a scalar dataset: one piece, (None, None))."""
    if ds.shape == () or ds.shape is None:
        return [(None, None)]
    rows = ds.shape[0]
    row_bytes = max(1, int(np.prod(ds.shape[1:], dtype=np.int64)) * ds.dtype.itemsize)
    per = max(1, chunk // row_bytes)
    return [(r, min(r + per, rows)) for r in range(0, max(rows, 1), per)] or [(0, 0)]


def _piece_bytes(ds, r0, r1):
    a = ds[()] if r0 is None else ds[r0:r1]
    if isinstance(a, bytes):
        return a
    return np.ascontiguousarray(a).tobytes()


def dataset_crcs(path, comm, chunk=CHUNK):
    """Collective: {dataset name: [CRC32 of each piece of its data]} of every dataset of the HDF5
    file ``path`` (groups walked; pieces along the first axis, ``_pieces``)."""
    import h5py
    mine, layout = {}, []
    with collective(comm, f"checksumming {path}", "{what}: {error}"):
        with _h5(path) as f:
            names = []
            f.visititems(lambda name, obj: names.append(name) if isinstance(obj, h5py.Dataset) else None)
            for name in sorted(names):
                ds = f[name]
                for r0, r1 in _pieces(ds, chunk):
                    layout.append((name, r0, r1))
            for j in _spread(len(layout), comm):
                name, r0, r1 = layout[j]
                mine[j] = zlib.crc32(_piece_bytes(f[name], r0, r1)) & 0xFFFFFFFF
    crcs = _gather(mine, len(layout), comm)
    out = {}
    for (name, _, _), c in zip(layout, crcs):
        out.setdefault(name, []).append(c)
    return out


def check_datasets(path, comm, saved, chunk=CHUNK):
    """Collective: the first dataset of ``path`` whose content differs from ``saved`` ({name: CRC
    list}, as ``dataset_crcs`` made it at save), as a phrase, or None."""
    now = dataset_crcs(path, comm, chunk)
    for name in sorted(set(saved) | set(now)):
        if name not in now:
            return f"the dataset {name} is missing"
        if name not in saved:
            return f"the dataset {name} has no checksum"
        off = first_bad_piece(saved[name], now[name], chunk)
        if off is not None:
            return f"the data of {name} differ from their checksum (CRC32 of its piece at byte {off} of the data)"
    return None
