"""Reusable lag matrices: ``-ssi_lags_save FILE`` and ``-ssi_lags_load FILE``.

The lag matrices depend on the soil mesh, its material, dt, the scheme, the symmetry planes, the
interpolation plan, the quadrature options, the lags kept in single precision (-ssi_lag_single_from)
and which soil nodes carry traction unknowns (the load and prescribed-displacement regions, or a
structure's interface): not on the loads' size or
history, the structure, or the receivers. A parameter study over those, or a restart, can skip
the assembly by loading the matrices a first run saved.

``FILE`` is a PETSc binary file with the step matrix (after the symmetry rows and columns are
set), the exact lags H_l and G_l and the interpolating matrices HI_j, GI_j, in that order, each
in the storage it had: MATDENSE as it is; the package's block-sparse and split dense lags
(bem/bsr.py) as an MPIAIJ holding only their block pattern's entries (on a flat surface 4 of 9 a
block of H, 5 of G: 48 and 60 B a block in the file, a full MPIBAIJ took 108), H_1's free term as
an MPIAIJ of its own after it; an empty lag is not written. ``FILE.json``
lists them and holds the key (``lag_key``: the values above, SHA-256 of the mesh and of the
traction nodes) and the CRC32 of every 8 MiB piece of ``FILE``'s bytes (``io.integrity``: summed
by the ranks in turn, no gather), written last, so a save that was cut short has no ``.json`` and
is refused. Loading checks the key and the checksums before any heavy work (one line naming the
first entry that differs, or the file and the byte offset of the damaged piece); the
matrices load on any number of ranks (rows by the run's node ranges). A run with loaded matrices
is bitwise the run that saved them when the solves are deterministic (one rank, or
-ssi_reproducible; ``tests/bem/test_lagstore.py``).

On the toeplitz store (``bem.toeplitz``) the file holds the step matrix, lags 1-2 (H and G) and, after them,
each side's kernels (the exact lags' K9, K18 and the interpolating matrices' anchors A9, A18) as one MPI Vec
each, frequency-major: (frequencies of the whole spectrum in the k_y-major order of ``bem.pfft``, rows, columns,
parts), the lanes' padding dropped (``to_file``), its shape and FFT grid in ``FILE.json``. Each rank writes its slab and reads the slab of the loading run's
rank count (``from_file``), so the file loads on any number of ranks, as the dense store's does; the loading
run integrates nothing (``tests/bem/test_toeplitz.py``). A toeplitz file of an earlier layout (the saving
run's lane groups, its rank count in the key; or the k_x-major order before the transforms went over the ranks,
key ``toeplitz_kernels`` "frequency-major") is refused in one line.
"""
import hashlib
import json
import os

import numpy as np

from ..petsc import init, collective, collective_io, SSIError

FORMAT = 3          # 3: lags in their block pattern (2: full MPIBAIJ blocks; 1: no CRC32s; both refused)

# the toeplitz kernels' order in the file: frequency-major, k_y-major (``bem.pfft``: each rank's slab a run of it)
KERNEL_LAYOUT = "frequency-major, k_y-major"


def _h(a):
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()


def lag_key(cfg, prob, plan):
    """{name: text}: everything the lag matrices depend on (module docstring)."""
    reg = prob.regions
    key = {"mesh_nodes": _h(np.asarray(prob.mesh.nodes, float)), "mesh_cells": _h(np.asarray(prob.mesh.cells, np.int64)),
           "cp": repr(float(cfg.cp)), "cs": repr(float(cfg.cs)), "rho": repr(float(cfg.rho)), "dt": repr(float(prob.dt)),
           "scheme": str(cfg.scheme), "symmetry": str(cfg.symmetry), "lags": str(prob.L), "exact_lags": str(plan.Lx),
           "traction_nodes": _h(np.asarray(reg.tnode, np.int64)), "load_nodes": str(reg.n_load),
           "disp_nodes": _h(np.asarray(reg.disp_nodes, np.int64))}
    sf = int(cfg.get("lag_single_from") or 0)
    top = max([plan.Lx] + ([plan.kernel_time(j)[0] for j in range(plan.k)] if plan.active else []))
    if 0 < sf <= top:         # (absent when no stored matrix is single: such files are of double runs)
        key["single_from"] = str(sf)
    for k, v in sorted(prob.quad_options().items()):
        if k != "cache_share":
            key["quadrature_" + k] = str(v)
    if plan.active:
        key["interp"] = f"{plan.method} k={plan.k} T_L={plan.TL!r} grading={cfg.interp_grading!r}"
        key["interp_times"] = " ".join(f"{lag}:{toff!r}" for lag, toff in (plan.kernel_time(j) for j in range(plan.k)))
    else:
        key["interp"] = "none"
    if getattr(prob, "lattice", None) is not None:      # the toeplitz store: its kernels frequency-major
        key["lag_store"] = "toeplitz"
        key["toeplitz_kernels"] = KERNEL_LAYOUT
    return key


def _difference(saved, now):
    """The first entry (in ``lag_key``'s order: mesh, material, dt, ...) that differs."""
    absent = {"lag_store": "dense"}                 # (a dense store's key has no lag_store entry)
    for name in list(now) + [k for k in saved if k not in now]:
        a, b = saved.get(name, absent.get(name)), now.get(name, absent.get(name))
        if a != b:
            return f"{name} differs ({a} there, {b} here)"
    return None


def _read_json(path, comm, what):
    data = None
    with collective(comm, f"{what} {path}", "{what}: cannot read " + f"{path}.json" + " ({error})"):
        if comm.getRank() == 0:
            if not os.path.isfile(path) or not os.path.isfile(path + ".json"):
                raise SSIError(f"{what} {path}: no such file, or its {os.path.basename(path)}.json is missing "
                               "(a save that did not finish)")
            with open(path + ".json") as fh:
                data = json.load(fh)
            if data.get("format") == 1:
                raise SSIError(f"{what} {path}: a lag file of an older petsc-ssi without checksums of its content "
                               "(format 1): save it again with -ssi_lags_save")
            if data.get("format") == 2:
                raise SSIError(f"{what} {path}: a lag file of an older petsc-ssi with full 3x3 blocks (format 2; "
                               "this one stores each lag's block pattern): save it again with -ssi_lags_save")
            if data.get("format") != FORMAT or "key" not in data or "crc32" not in data:
                raise SSIError(f"{what} {path}: not a petsc-ssi lag file (format {FORMAT})")
            if os.path.getsize(path) != data.get("bytes"):
                raise SSIError(f"{what} {path}: {os.path.getsize(path)} bytes, {path}.json says {data.get('bytes')} "
                               "(a truncated or replaced file)")
    return comm.tompi4py().bcast(data, root=0)


def verify(path, comm, manifest, what="-ssi_lags_load"):
    """Collective: the CRC32 of every piece of ``path`` against its manifest's; SSIError in one line
    naming the file and the damaged piece's offset."""
    import time
    from ..io.integrity import file_crcs, first_bad_piece
    from ..petsc import printf
    t0 = time.perf_counter()
    chunk = int(manifest.get("crc32_chunk", 0)) or 1
    off = first_bad_piece(manifest["crc32"], file_crcs(path, comm, chunk), chunk)
    if off is not None:
        raise SSIError(f"{what} {path}: the content differs from the checksum saved with it (CRC32 of the "
                       f"{chunk} bytes at offset {off}): a damaged file; save it again with -ssi_lags_save")
    printf(f"[ssi] {what} {path}: content checked against its CRC32s ({manifest['bytes'] / 1e9:.3g} GB in "
           f"{time.perf_counter() - t0:.2f} s)")


def check(cfg, comm, prob, plan):
    """Collective, before any heavy work: -ssi_lags_load's key against this run (SSIError naming
    what differs; returns its manifest) and content (``verify``), and -ssi_lags_save's location (writable, not replacing a
    file without -ssi_output_overwrite). Returns the manifest or None."""
    manifest = None
    if cfg.get("lags_load"):
        manifest = _read_json(cfg.lags_load, comm, "-ssi_lags_load")
        if manifest["key"].get("lag_store") == "toeplitz" and manifest["key"].get("toeplitz_kernels") == "frequency-major":
            raise SSIError(f"-ssi_lags_load {cfg.lags_load}: a toeplitz lag file of an older petsc-ssi (its kernels k_x-major, "
                           "before the FFTs went over the ranks): save it again with -ssi_lags_save")
        if manifest["key"].get("lag_store") == "toeplitz" and "ranks" in manifest["key"]:
            raise SSIError(f"-ssi_lags_load {cfg.lags_load}: a toeplitz lag file of an older petsc-ssi (its kernels in "
                           f"the lane groups of its {manifest['key']['ranks']} ranks; files now load on any number "
                           "of ranks): save it again with -ssi_lags_save")
        diff = _difference(manifest["key"], lag_key(cfg, prob, plan))
        if diff:
            raise SSIError(f"-ssi_lags_load {cfg.lags_load}: the saved lag matrices are of another soil problem: "
                           f"{diff}")
        verify(cfg.lags_load, comm, manifest)
    if cfg.get("lags_save"):
        from ..io.output import check_output
        if cfg.get("lags_load"):
            raise SSIError("-ssi_lags_save with -ssi_lags_load: the loaded matrices are already saved")
        check_output(cfg.lags_save, comm, bool(cfg.get("output_overwrite")), what="-ssi_lags_save")
    return manifest


def _mats(march):
    """[(name, Mat or None)] in file order."""
    out = [("A", march.A)]
    out += [(f"H{i + 1}", M) for i, M in enumerate(march.H)]
    out += [(f"G{i + 1}", M) for i, M in enumerate(march.G)]
    out += [(f"HI{i + 1}", M) for i, M in enumerate(march.HI)]
    out += [(f"GI{i + 1}", M) for i, M in enumerate(march.GI)]
    return out


def _kind(M):
    """The manifest's name of a Mat's storage: 'empty', 'dense' (MATDENSE), 'aij' (the step matrix),
    'bsr<m>' (block-sparse, pattern m: bsr.PATTERNS) or 'split<m>' (bsr.DenseSplit), '+diag' when
    a free term follows it in the file."""
    from . import bsr
    if M is None:
        return "empty"
    ctx = bsr.context(M)
    if ctx is not None:
        return f"{ctx.kind.replace('dense', 'split')}{ctx.pattern}" + ("+diag" if ctx.diag is not None else "")
    t = M.getType()
    return "dense" if "dense" in t else ("baij" if "baij" in t else "aij")


def save(path, comm, march, key):
    """Collective: the Marcher's matrices to ``path`` (PETSc binary) and ``path``.json; returns (bytes,
    seconds of the checksums)."""
    PETSc = init()
    tmp = path + ".tmp"
    mats = _mats(march)
    viewer = PETSc.Viewer().createBinary(tmp, mode="w", comm=comm)

    def write():
        from . import bsr
        for _, M in mats:
            if M is None:
                continue
            ctx = bsr.context(M)
            if ctx is None:
                M.view(viewer)
                continue
            for make in (ctx.to_aij, ctx.diag_aij if ctx.diag is not None else None):
                if make is not None:              # its pattern's entries as MPIAIJ, one lag at a time
                    A = make()
                    A.view(viewer)
                    A.destroy()
    kernels = _kernel_arrays(march)

    def write_kernels():
        for _, a, slab, _ in kernels:           # (each rank's frequencies of a side's kernels, one MPI Vec; one
            f = to_file(a, slab)                # kernel converted at a time: a copy of one, not of all)
            v = PETSc.Vec().createWithArray(f.ravel(), comm=comm)
            v.view(viewer)
            v.destroy()
            del f
    collective_io(write, f"-ssi_lags_save {path}: writing the matrices", comm)
    collective_io(write_kernels, f"-ssi_lags_save {path}: writing the toeplitz kernels", comm)
    collective_io(viewer.destroy, f"-ssi_lags_save {path}: closing the file", comm)
    import time
    from ..io.integrity import file_crcs, CHUNK
    kshapes = [[comm.tompi4py().allreduce(slab)] + list(a.shape[1:-1]) for _, a, slab, _ in kernels]  # (whole spectrum)
    t0 = time.perf_counter()
    crcs = file_crcs(tmp, comm, CHUNK)           # of the bytes as written, every rank its pieces
    t_crc = time.perf_counter() - t0
    size = 0
    with collective(comm, f"-ssi_lags_save {path}", "{what}: {error}"):
        if comm.getRank() == 0:
            if os.path.exists(tmp + ".info"):
                os.remove(tmp + ".info")
            if os.path.exists(path + ".json"):
                os.remove(path + ".json")          # the old key must not describe the new matrices
            os.replace(tmp, path)
            size = os.path.getsize(path)
            manifest = {"format": FORMAT, "key": key, "mats": [[n, _kind(M)] for n, M in mats],
                        "ranks": comm.getSize(), "bytes": size, "crc32_chunk": CHUNK, "crc32": crcs}
            if kernels:
                manifest["kernels"] = [[n, shapes, list(grid)] for (n, _, _, grid), shapes in zip(kernels, kshapes)]
            with open(path + ".json.tmp", "w") as fh:
                json.dump(manifest, fh, indent=1)
            os.replace(path + ".json.tmp", path + ".json")
    return comm.tompi4py().bcast(size, root=0), t_crc


def load(path, comm, manifest, node_range, n_nodes, n_t, tcol_loc, single_from=0, interp_lags=(), fft_ranks=0):
    """Collective: (A, H, G, HI, GI) from ``path`` in this run's layout (rows: the nodes
    ``node_range`` of ``n_nodes``; G's columns the ``n_t`` traction nodes, ``tcol_loc`` here).
    ``single_from`` > 0: block-sparse lags from it on (``interp_lags``: the lag index of each
    interpolating matrix) back to float32 as each is read, so that no more than one of them is
    held in double at a time. ``fft_ranks``: -ssi_toeplitz_fft_ranks (the toeplitz kernels' slabs, ``pfft``)."""
    PETSc = init()
    nloc = node_range[1] - node_range[0]
    types = {"dense": PETSc.Mat.Type.DENSE, "baij": PETSc.Mat.Type.BAIJ, "aij": PETSc.Mat.Type.AIJ}

    def aij(cols):
        M = PETSc.Mat().create(comm=comm)
        M.setSizes(((3 * nloc, 3 * n_nodes), cols))
        M.setType(PETSc.Mat.Type.AIJ)
        M.load(viewer)
        return M
    viewer = PETSc.Viewer().createBinary(path, mode="r", comm=comm)
    out = {"A": [], "H": [], "G": [], "HI": [], "GI": []}

    def read():
        for name, kind in manifest["mats"]:
            group = name.rstrip("0123456789")
            if kind == "empty":
                out[group].append(None)
                continue
            cols = (3 * tcol_loc, 3 * n_t) if group in ("G", "GI") else (3 * nloc, 3 * n_nodes)
            if kind.startswith(("bsr", "split")):
                from . import bsr
                base, _, extra = kind.partition("+")              # e.g. "split4+diag": storage, pattern, free term
                storage, pattern = base.rstrip("0123456789"), int(base[len(base.rstrip("0123456789")):])
                M = aij(cols)
                D = aij(cols) if extra == "diag" else None
                M = bsr.from_aij(M, pattern, D, dense=storage == "split")
                if group in ("H", "HI") and storage == "bsr" and pattern == bsr.FULL:   # a split H, split again
                    M = bsr.split_flat(bsr.context(M)).mat
                idx = int(name[len(group):])
                lag = interp_lags[idx - 1] if group in ("HI", "GI") else idx
                if kind.startswith("bsr") and 0 < single_from <= lag:
                    bsr.context(M).to_single()
                out[group].append(M)
                continue
            M = PETSc.Mat().create(comm=comm)
            M.setSizes(((3 * nloc, 3 * n_nodes), cols), bsize=3)
            M.setType(types[kind])
            M.load(viewer)
            out[group].append(M)
    kernels = {}

    def read_kernels():
        from .pfft import slab_counts
        r, p = comm.getRank(), comm.getSize()
        for name, shape, (Mx, My) in manifest.get("kernels", []):
            F = int(shape[0])
            mine = (int(slab_counts(Mx, My, p, fft_ranks)[r]),) + tuple(shape[1:])   # (``ToeplitzHistory``'s slab here)
            v = PETSc.Vec().create(comm=comm)
            v.setSizes((int(np.prod(mine)), PETSc.DECIDE))
            v.setType(PETSc.Vec.Type.MPI)
            v.load(viewer)
            kernels[name] = from_file(v.getArray(readonly=True).reshape(mine))
            kernels[name.split(":")[0] + ":F"] = F      # (the side's spectrum and FFT grid, checked against the run's)
            kernels[name.split(":")[0] + ":grid"] = (int(Mx), int(My))
            v.destroy()
    collective_io(read, f"-ssi_lags_load {path}: reading the matrices (a truncated or changed file?)", comm)
    collective_io(read_kernels, f"-ssi_lags_load {path}: reading the toeplitz kernels (a truncated or changed file?)",
                  comm)
    viewer.destroy()
    if manifest.get("kernels"):
        return out["A"][0], out["H"], out["G"], out["HI"], out["GI"], kernels
    return out["A"][0], out["H"], out["G"], out["HI"], out["GI"]


def _kernel_arrays(march):
    """[(name, this rank's array in lanes, its frequencies, the FFT grid (Mx, My))] of the toeplitz store's kernels (``bem.toeplitz``:
    per side u and p, K9, K18 of the exact lags and A9, A18 of the interpolating matrices' anchors), in file
    order; [] on the dense store."""
    out = []
    for tz in getattr(march, "toeplitz", []):
        out += [(f"{tz.side}:{n}", getattr(tz, n), tz.f1 - tz.f0, (int(tz.lat.Mx), int(tz.lat.My)))
                for n in ("K9", "K18", "A9", "A18")]
    return out


def to_file(a, slab):
    """A kernel's lanes (groups, rows, columns, parts, FW) -> (slab, rows, columns, parts) float64, frequency
    g FW + q from lane q of group g, the last group's padding dropped: the file's layout, which no rank count
    shapes."""
    return np.ascontiguousarray(np.moveaxis(a, -1, 1).reshape((a.shape[0] * a.shape[-1],) + a.shape[1:-1])[:slab],
                                dtype=np.float64)


def from_file(X):
    """``to_file``'s inverse: (slab, rows, columns, parts) -> the lanes (groups, rows, columns, parts, FW), the
    last group padded with zeros."""
    from .lanes import FW, n_groups
    rest = X.shape[1:]
    out = np.zeros((n_groups(X.shape[0]),) + rest + (FW,))
    for q in range(FW):                             # (lane q: frequencies q, q + FW, ...; no copy of the whole)
        xs = X[q::FW]
        out[:len(xs), ..., q] = xs
    return out
