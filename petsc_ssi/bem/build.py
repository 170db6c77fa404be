"""Assembly of a BEM run: the lag matrices (exact and interpolating) into PETSc Mats, the step
matrix factorised once, all handed to a ``Marcher`` (``build_marcher``); or the matrices of
-ssi_lags_load read back instead of assembled. Collective."""
import os
import time

import numpy as np

from ..petsc import init, printf
from ..monitor import event, fmt_time
from . import symmetry
# (lagmats, numba's kernels, is imported where a lag matrix is built: bem/lagset.py)
from .march import Marcher
from .cost import history_block


def _block_of(cfg, comm, H, G, HI, GI):
    """history_block from this run's Mats (None: empty): per stored matrix the bytes of its H and
    of its G (read by the same panel products), dense or block-sparse, summed over the ranks."""
    from . import lagmats
    from . import bsr
    Hs, Gs = list(H) + list(HI), list(G) + [None] * (len(H) - len(G)) + list(GI) + [None] * (len(HI) - len(GI))
    d = np.zeros((3, len(Hs)))              # dense bytes, block-sparse bytes, block-sparse values
    for i, (Hm, Gm) in enumerate(zip(Hs, Gs)):
        for M in (Hm, Gm):
            if M is None:
                continue
            ctx = bsr.context(M)
            sparse = ctx is not None and ctx.kind == "bsr"
            d[1 if sparse else 0, i] += lagmats.mat_bytes(M)
            if sparse:
                d[2, i] += ctx.entries
    tot = np.zeros_like(d)
    comm.tompi4py().Allreduce(d, tot)
    return history_block(cfg, tot[0], tot[1], tot[2])


def _say_block(march):
    if march.block > 1:
        subs = (f" in sub-blocks of {march.sub} (-ssi_history_sub)" if march.sub < march.block else "")
        printf(f"[ssi] history sum: time-blocked, {march.block} steps per block{subs} (-ssi_history_block; 1: step "
               "by step)")
    else:
        printf("[ssi] history sum: step by step (-ssi_history_block 1)")


def _traction_cols_local(comm, nt):
    """This rank's traction nodes of G's columns (PETSc's default split of 3 nt DOFs in blocks of 3)."""
    if not nt:
        return 0
    PETSc = init()
    pl = PETSc.Vec().createMPI((PETSc.DECIDE, 3 * nt), bsize=3, comm=comm)
    n = pl.getLocalSize() // 3
    pl.destroy()
    return n


def build_marcher(cfg, comm, prob, plan, ls, known_u, known_p, log=printf):
    """Collective: assemble the lag matrices (exact and interpolating), factorise
    the step matrix and hand the Mats to a Marcher, with the area loads' lag vectors
    (``bem.area``, -ssi_load_area). Returns (marcher, info)."""
    march, info = _build_marcher(cfg, comm, prob, plan, ls, known_u, known_p, log)
    areas = getattr(prob, "areas", [])
    if areas:
        from .area import build as build_areas
        with event("SSI_BEM_Area"):
            march.area = build_areas(ls, areas, prob.n_steps, march.zero_local)
    return march, info


def _build_marcher(cfg, comm, prob, plan, ls, known_u, known_p, log):
    from . import lagmats
    from .. import numba_cache_warm
    if not numba_cache_warm() and not os.environ.get("PETSC_SSI_WARMUP"):
        from .lagset import announce_compile
        announce_compile()
    t0 = time.perf_counter()
    if getattr(prob, "lattice", None) is not None:
        return _toeplitz_marcher(cfg, comm, prob, plan, ls, known_u, known_p, log, t0)
    if cfg.get("lags_load"):
        return _load_marcher(cfg, comm, prob, plan, ls, known_u, known_p, log, t0)
    single = int(cfg.lag_single_from)
    ls.assemble(monitor=cfg.monitor, lag_hi=plan.Lx, single_from=single)
    N = prob.mesh.n_nodes
    r0, r1 = ls.node_range
    march = Marcher(comm, ls, cfg.scheme, known_u, known_p, log=log, blr=float(cfg.step_blr),
                    mirror=cfg.get("step_mirror", "auto"),
                    zero_dofs=symmetry.zero_dofs(prob.mesh.nodes, prob.planes, prob.h))  # step matrix first
    with event("SSI_BEM_LagMats"):
        H, hinfo = lagmats.build(comm, ls.H, plan.Lx, ls.node_range, N, N, r1 - r0, cfg.lag_storage,
                                 prob.lag_fill)
        nt = prob.regions.n_t
        if nt:
            tcol_loc = _traction_cols_local(comm, nt)
            G, ginfo = lagmats.build(comm, ls.G, plan.Lx, ls.node_range, N, nt, tcol_loc, "dense")
        else:
            G = [None] * plan.Lx
    HI, GI = _interpolating_lags(cfg, comm, prob, plan, ls, tcol_loc if nt else None)
    t_asm = time.perf_counter() - t0
    info = _assembly_report(cfg, comm, plan, ls, N, (H, G, HI, GI), hinfo, t_asm)
    b, sub = _block_of(cfg, comm, H, G, HI, GI)
    march.set_lags(H, G, plan, HI, GI, block=b, sub=sub)
    _say_block(march)
    ls.H = ls.G = None   # the triplets are in the Mats now
    _save_lags(cfg, comm, prob, plan, march)
    return march, info


def _save_lags(cfg, comm, prob, plan, march):
    """Collective: -ssi_lags_save (``lagstore.save``: the matrices, and the toeplitz store's kernels), one line."""
    if not cfg.get("lags_save"):
        return
    from . import lagstore
    t1 = time.perf_counter()
    size, t_crc = lagstore.save(cfg.lags_save, comm, march, lagstore.lag_key(cfg, prob, plan))
    what = "lag matrices and toeplitz kernels" if march.toeplitz else "lag matrices"
    printf(f"[ssi] {what} saved to {cfg.lags_save} ({size / 1e9:.3g} GB in "
           f"{fmt_time(time.perf_counter() - t1)}, of which {t_crc:.2f} s the CRC32 checksums of its content; "
           f"-ssi_lags_load {cfg.lags_save} reuses them)")


def _interpolating_lags(cfg, comm, prob, plan, ls, tcol_loc):
    """Collective: the lag matrices (HI, GI) at the interpolation plan's kernel times (none without
    interpolation; GI's None without traction columns, ``tcol_loc`` None); ``ls.kernel_evaluations``
    then counts the exact lags' and theirs."""
    from . import lagmats
    N, nt = prob.mesh.n_nodes, prob.regions.n_t
    r0, r1 = ls.node_range
    single = int(cfg.lag_single_from)
    nev = ls.kernel_evaluations
    HI, GI = [], []
    for j in range(plan.k if plan.active else 0):
        lag, toff = plan.kernel_time(j)
        hb, gb = ls.assemble(monitor=False, lag_lo=lag, lag_hi=lag, toff=toff, single_from=single)
        nev += ls.kernel_evaluations
        HI.append(lagmats.build_one(comm, hb, lag, ls.node_range, N, N, r1 - r0, cfg.lag_storage,
                                    prob.lag_fill)[0])
        GI.append(lagmats.build_one(comm, gb, lag, ls.node_range, N, nt, tcol_loc, "dense")[0] if nt else None)
    ls.kernel_evaluations = nev
    return HI, GI


def _assembly_report(cfg, comm, plan, ls, N, mats, hinfo, t_asm):
    """Collective: the assembly's line (and the interpolating matrices' memory) and the run's info
    {t_asm, mem_exact, mem_interp, ndense, nbaij, nsingle, fill, mem}; ``mats``: (H, G, HI, GI)."""
    from . import lagmats
    H, G, HI, GI = mats
    mem_exact = comm.tompi4py().allreduce(sum(lagmats.mat_bytes(A) for A in H + G))
    mem_interp = comm.tompi4py().allreduce(sum(lagmats.mat_bytes(A) for A in HI + GI))
    mem = mem_exact + mem_interp
    ndense = sum(1 for i in hinfo if i[1] == "dense")
    nbaij = sum(1 for i in hinfo if i[1] == "baij")
    nsingle = sum(1 for i in hinfo if i[1] == "single")
    blocks = sum(i[2] for i in hinfo)
    fill = blocks / float(plan.Lx * N * N)
    if plan.active:
        printf(f"[ssi] memory: {plan.Lx} exact lags {mem_exact / 1e9:.3g} GB, {plan.k} interpolating "
               f"matrices {mem_interp / 1e9:.3g} GB (T_N = {plan.TN:.4g} s, T_L = {plan.TL:.4g} s)")
    single_txt = f", {nsingle} single-precision block-sparse" if nsingle else ""
    printf(f"[ssi] assembly {fmt_time(t_asm)}: {plan.Lx} exact lags ({ndense} dense, {nbaij} block-sparse"
           f"{single_txt}), "
           f"mean block fill {100 * fill:.1f}%, stored {mem / 1e9:.3g} GB, "
           f"{ls.kernel_evaluations:.3g} kernel evaluations, {ls.cache_hits} element pairs reused "
           f"(cache {ls.cache_bytes / 1e6:.3g} MB)"
           + ("; lag arrays in 4 kB pages (-ssi_huge_pages: this machine hands free memory back to its host)"
              if ls.opts.get("small_pages") and cfg.get("huge_pages", "auto") == "auto" else ""))
    return {"t_asm": t_asm, "mem_exact": mem_exact, "mem_interp": mem_interp, "ndense": ndense,
            "nbaij": nbaij, "nsingle": nsingle, "fill": fill, "mem": mem}


def _load_marcher(cfg, comm, prob, plan, ls, known_u, known_p, log, t0):
    """Collective: build_marcher with the matrices of -ssi_lags_load (checked in ``prepare``)."""
    from . import lagmats
    from . import lagstore
    N = prob.mesh.n_nodes
    nt = prob.regions.n_t
    tcol_loc = _traction_cols_local(comm, nt)
    # (the file holds float32 values as doubles, PETSc's scalar: float32 again as each is read)
    A, H, G, HI, GI = lagstore.load(cfg.lags_load, comm, prob.lags_manifest, ls.node_range, N, nt, tcol_loc,
                                    single_from=int(cfg.lag_single_from),
                                    interp_lags=[plan.kernel_time(j)[0] for j in range(plan.k if plan.active else 0)])
    march = Marcher(comm, ls, cfg.scheme, known_u, known_p, log=log, blr=float(cfg.step_blr),
                    mirror=cfg.get("step_mirror", "auto"),
                    zero_dofs=symmetry.zero_dofs(prob.mesh.nodes, prob.planes, prob.h), A=A)
    if not nt:
        G = [None] * plan.Lx
    t_asm = time.perf_counter() - t0
    mpi = comm.tompi4py()
    mem_exact = mpi.allreduce(sum(lagmats.mat_bytes(M) for M in H + G))
    mem_interp = mpi.allreduce(sum(lagmats.mat_bytes(M) for M in HI + GI))
    kinds = dict(prob.lags_manifest["mats"])
    ndense = sum(1 for i in range(plan.Lx) if kinds.get(f"H{i + 1}", "").startswith(("dense", "split")))
    from . import bsr
    nsingle = sum(1 for M in H if bsr.context(M) is not None and bsr.context(M).kind == "bsr"
                  and bsr.context(M).dtype == np.float32)
    nbaij = sum(1 for i in range(plan.Lx) if kinds.get(f"H{i + 1}", "").startswith("bsr")) - nsingle
    ls.kernel_evaluations = ls.cache_hits = 0
    ls.cache_bytes = 0.0
    printf(f"[ssi] lag matrices loaded from {cfg.lags_load} in {fmt_time(t_asm)} (no assembly): {plan.Lx} exact "
           f"lags ({ndense} dense, {nbaij} block-sparse" + (f", {nsingle} single-precision block-sparse" if nsingle
                                                               else "") + ")"
           + (f", {plan.k} interpolating matrices" if plan.active else "")
           + f", stored {(mem_exact + mem_interp) / 1e9:.3g} GB")
    b, sub = _block_of(cfg, comm, H, G, HI, GI)
    march.set_lags(H, G, plan, HI, GI, block=b, sub=sub)
    _say_block(march)
    ls.H = ls.G = None
    return march, {"t_asm": t_asm, "mem_exact": mem_exact, "mem_interp": mem_interp, "ndense": ndense,
                   "nbaij": nbaij, "nsingle": nsingle, "fill": float("nan"), "mem": mem_exact + mem_interp}


def _traction_g(comm, prob, plan, ls, lag_hi, storage, fill, lag_lo=1, toff=0.0):
    """Collective: the G lags lag_lo..lag_hi (at kernel times l dt + toff), from an assembly over the
    elements that carry traction columns only (the others add nothing to G; the same elements in the
    same order: the same blocks), stored as ``storage`` (-ssi_lag_storage, auto by default; ``fill`` its
    threshold; the toeplitz store calls it): lags 1-2 reach only the soil nodes near the traction elements, where a dense Mat of every soil node's rows was read in full at each
    step (the uniform 72 m building, 484 traction nodes: 2 x 0.29 GB; block-sparse, its first 80 steps'
    MatMults 2.9 -> 1.4 s and the lags' panel products, 1.8 s, gone: jobscripts/README.md)."""
    from . import lagmats
    nt = prob.regions.n_t
    tl = ls.restricted(np.any(ls.VT >= 0, axis=1))
    tcol_loc = _traction_cols_local(comm, nt)
    _, gb = tl.assemble(monitor=False, lag_lo=lag_lo, lag_hi=lag_hi, toff=toff, quiet=True, keep_h=False)
    N = prob.mesh.n_nodes
    if lag_lo == lag_hi and lag_lo > 1:
        return [lagmats.build_one(comm, gb, lag_lo, ls.node_range, N, nt, tcol_loc, storage, fill)[0]], tl
    return lagmats.build(comm, gb, lag_hi, ls.node_range, N, nt, tcol_loc, storage, fill)[0], tl


def _toeplitz_loaded(cfg, comm, prob, plan, ls, known_u, known_p, log, zero):
    """Collective: (march, H, G, kernels) of -ssi_lags_load on the toeplitz store: the step matrix and lags 1-2
    read back, the kernels' arrays as ``lagstore.load`` gives them ({side:name: this rank's slab})."""
    from . import lagstore
    N, nt = prob.mesh.n_nodes, prob.regions.n_t
    tcol_loc = _traction_cols_local(comm, nt)
    A, H, G, _, _, kern = lagstore.load(cfg.lags_load, comm, prob.lags_manifest, ls.node_range, N, nt, tcol_loc,
                                        fft_ranks=int(cfg.get("toeplitz_fft_ranks", 0) or 0))
    march = Marcher(comm, ls, cfg.scheme, known_u, known_p, log=log, blr=float(cfg.step_blr),
                    mirror=cfg.get("step_mirror", "auto"), zero_dofs=zero, A=A)
    ls.cache_hits, ls.cache_bytes = 0, 0.0
    return march, list(H) + [None] * (plan.Lx - len(H)), list(G) + [None] * (plan.Lx - len(G)), kern


def _toeplitz_assembled(cfg, comm, prob, plan, ls, known_u, known_p, log, zero):
    """Collective: (march, H, G, kernel evaluations) of the toeplitz store's lags 1-2, assembled: the step
    matrix factorised, H's and (with tractions) G's lags 1-2 as Mats, the later lags None (kernels)."""
    from . import lagmats
    N = prob.mesh.n_nodes
    r0, r1 = ls.node_range
    ls.assemble(monitor=cfg.monitor, lag_hi=2)
    nev = ls.kernel_evaluations
    march = Marcher(comm, ls, cfg.scheme, known_u, known_p, log=log, blr=float(cfg.step_blr),
                    mirror=cfg.get("step_mirror", "auto"), zero_dofs=zero)
    with event("SSI_BEM_LagMats"):
        H, _ = lagmats.build(comm, ls.H, 2, ls.node_range, N, N, r1 - r0, cfg.lag_storage, prob.lag_fill)
        H = list(H) + [None] * (plan.Lx - 2)
        G = [None] * plan.Lx
        if prob.regions.n_t:
            g, tl = _traction_g(comm, prob, plan, ls, min(2, plan.Lx), cfg.lag_storage, prob.lag_fill)
            G[:len(g)] = g
            nev += tl.kernel_evaluations
    return march, H, G, nev


def _toeplitz_marcher(cfg, comm, prob, plan, ls, known_u, known_p, log, t0):
    """Collective: build_marcher on a uniform flat grid (-ssi_lag_store toeplitz, ``bem.toeplitz``):
    lags 1 and 2 assembled as always (H and, with tractions, G: the step matrix and the known values'
    terms), the H lags of the history sum beyond them as FFT kernels on the grid, the G lags as FFT
    kernels on the window of the traction elements (``toeplitz.traction_grid``). With -ssi_lags_load the step
    matrix, lags 1-2 and the kernels are read back from a file a toeplitz run saved (on any number of ranks)
    (``lagstore``), nothing assembled or integrated."""
    from . import lagmats
    from .toeplitz import ToeplitzHistory, traction_grid, block_of
    k = plan.k if plan.active else 0
    zero = symmetry.zero_dofs(prob.mesh.nodes, prob.planes, prob.h)
    if cfg.get("lags_load"):
        march, H, G, kern = _toeplitz_loaded(cfg, comm, prob, plan, ls, known_u, known_p, log, zero)
        nev = 0
    else:
        march, H, G, nev = _toeplitz_assembled(cfg, comm, prob, plan, ls, known_u, known_p, log, zero)
        kern = None
    ls.H = ls.G = None
    b, sub = _block_of(cfg, comm, H, G, [None] * k, [])
    march.set_lags(H, G, plan, [None] * k, [None] * k if prob.regions.n_t else [], block=b, sub=sub)
    grids = [("u", prob.lattice)]
    glat = traction_grid(prob.lattice, ls.VT) if prob.regions.n_t else None
    if glat is not None:
        grids.append(("p", glat))
    with event("SSI_BEM_Toeplitz"):
        for side, lat in grids:
            march.toeplitz.append(ToeplitzHistory(comm, ls, lat, log, block=block_of(cfg), side=side,
                                                  precision=cfg.get("toeplitz_precision", "double"),
                                                  fft_ranks=int(cfg.get("toeplitz_fft_ranks", 0) or 0))
                                  .build(march, plan, monitor=cfg.monitor,
                                         kernels=None if kern is None else {n.split(":")[1]: a for n, a in
                                                                            kern.items() if n.startswith(side + ":")}))
    th = march.toeplitz[0]
    ls.kernel_evaluations = nev + sum(t.nev for t in march.toeplitz)
    t_asm = time.perf_counter() - t0
    mem_g = comm.tompi4py().allreduce(sum(lagmats.mat_bytes(A) for A in [M for M in H + G if M is not None]))
    tz_bytes = sum(t.bytes for t in march.toeplitz)
    mem = mem_g + tz_bytes
    gside = (f"; G lags as {march.toeplitz[1].D} kernels on the traction elements' {glat.in_n[0]} x "
             f"{glat.in_n[1]} window (FFT grid {glat.Mx} x {glat.My}, {march.toeplitz[1].build_text()}, "
             f"{march.toeplitz[1].bytes / 1e9:.3g} GB)"
             if glat is not None else "")
    printf(f"[ssi] assembly {fmt_time(t_asm)}: lag store toeplitz on the {prob.lattice.describe()}: "
           f"{th.D} history kernels K'_d in Fourier space"
           + (f" and the {th.k} interpolating matrices' kernels (the far lags' states weighted per step, {th.R} "
              "steps kept)" if th.k else "")
           + f" ({th.bytes / 1e9:.3g} GB with the kept states' transforms; "
           f"{th.build_text()}){gside}, step matrix and G lags 1-2 {mem_g / 1e9:.3g} GB, "
           f"{ls.kernel_evaluations:.3g} kernel evaluations; kept transforms in "
           f"{cfg.get('toeplitz_precision', 'double')} precision (-ssi_toeplitz_precision)"
           + "".join(f"; {t.spec['what']} kernels real (point-symmetric offsets: half the products)"
                     for t in march.toeplitz if t.real))
    printf(f"[ssi] history sum: in Fourier space, time-blocked, {th.block} steps per block (-ssi_history_block)"
           + ("; -ssi_history_sub is the dense store's and is not used here" if int(cfg.get("history_sub") or 0) else ""))
    printf("[ssi] toeplitz transforms: mpi4py-fft slabs over the ranks, "
           + "; ".join(f"{t.spec['what']} on {t.fft.q} of {comm.getSize()} rank(s)"
                       + (" (-ssi_toeplitz_fft_ranks, or a slab decomposition's most, min(Mx, My // 2 + 1): the "
                          "others hold no frequencies of this side)" if t.fft.q < comm.getSize() else "")
                       for t in march.toeplitz))
    if kern is not None:
        printf(f"[ssi] lag matrices and toeplitz kernels loaded from {cfg.lags_load} (no assembly, no kernel "
               "integrals)")
    _save_lags(cfg, comm, prob, plan, march)
    return march, {"t_asm": t_asm, "mem_exact": mem, "mem_interp": 0.0, "ndense": 0, "nbaij": 0, "nsingle": 0,
                   "fill": float("nan"), "mem": mem}
