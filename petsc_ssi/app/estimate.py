"""``petsc-ssi estimate``: the predicted time per stage and memory of a BEM run, per rank count,
and whether it fits the nodes, without assembling (the model: ``petsc_ssi.bem.cost``)."""
import math
import os
import time

from ..options import register, SSIError
from ..monitor import fmt_time
from ..bem.cost import Counts, bem_solve_seconds, load_constants, predict
from .kinds import problem_kind, resolve

G = "estimate"
register("estimate_ranks", "str", "1,2,4", "", "estimate: rank counts to predict, e.g. '1,2,4,8,16'", G)
register("estimate_ranks_per_node", "int", 0, "", "estimate: MPI ranks per node (0: the cores of this machine)", G,
         validator=lambda v: None if v >= 0 else "must be >= 0")
register("estimate_cores_per_node", "int", 0, "", "estimate: cores per node (0: this machine's); more ranks than "
         "cores on a node are oversubscribed", G, validator=lambda v: None if v >= 0 else "must be >= 0")
register("estimate_node_memory", "real", 0.0, "GB", "estimate: memory of one node (0: this machine's)", G,
         validator=lambda v: None if v >= 0 else "must be >= 0")


def parse_ranks(text):
    try:
        r = sorted({int(s) for s in str(text).split(",") if s.strip()})
    except ValueError:
        raise SSIError(f"-ssi_estimate_ranks '{text}': expected rank counts 'p1,p2,...'") from None
    if not r or r[0] < 1:
        raise SSIError(f"-ssi_estimate_ranks '{text}': expected positive rank counts")
    return r


def count_run(cfg, comm, ranks, node_mem, coupled=None):
    """Collective: the BEM set-up of a run without assembly, and its counts. ``coupled``: the
    (prob, model, iface, integrator) of ``coupling.model.build_coupled`` for -ssi_problem ssi (the
    soil with the interface as its traction region, as the coupled run assembles it)."""
    from ..bem.halfspace import HalfSpace
    from ..sysmem import machine_memory
    quiet = lambda m: None
    t0 = time.perf_counter()
    prob = coupled[0] if coupled is not None else HalfSpace(cfg, comm, log=quiet)
    prob.warn_diffraction()             # the run says it at its set-up (HalfSpace.prepare), one line
    plan = prob.interp_plan()
    ls = prob.lagset(plan)
    limit = cfg.memory_limit * 1e9 if cfg.memory_limit > 0 else 0.8 * (node_mem or machine_memory())
    cnt = Counts(prob, plan, ls, ranks, limit, comm)
    cnt.setup_s = time.perf_counter() - t0
    cnt.lagset = ls
    return prob, plan, cnt


def report(cfg, comm, out=None):
    """Collective: print the estimate block (rank 0) and return its numbers."""
    from ..petsc import printf
    from ..sysmem import machine_memory
    out = out or printf
    ranks = parse_ranks(cfg.estimate_ranks)
    cores = cfg.estimate_cores_per_node or (os.cpu_count() or 1)
    q = cfg.estimate_ranks_per_node or cores
    node_mem = cfg.estimate_node_memory * 1e9 if cfg.estimate_node_memory > 0 else machine_memory()
    c, source = load_constants(cfg.estimate_constants)
    coupled = cc = None
    if problem_kind() == "ssi":
        from ..coupling.model import build_coupled
        from ..coupling.cost import CoupledCounts
        coupled = build_coupled(cfg, comm)
        cc = CoupledCounts(cfg, comm, *coupled)
    tz = _toeplitz_report(cfg, comm, ranks, cores, q, node_mem, coupled, cc, c)
    if tz is not None:                  # a uniform flat grid: the run takes the toeplitz store
        lines, rows = tz
        out("\n".join(lines))
        return {"counts": None, "rows": rows}
    prob, plan, cnt = count_run(cfg, comm, ranks, node_mem, coupled)
    cnt.area_bytes = ab = prob.area_bytes()
    nd = int(cnt.storage.sum())
    n1 = int(cnt.single.sum())
    ns = len(cnt.storage) - nd - n1
    what = ("coupled run (models petsc_ssi/bem/cost.py and petsc_ssi/coupling/cost.py" if cc is not None
            else "BEM run (model petsc_ssi/bem/cost.py")
    lines = [f"[ssi] estimate of this {what}; constants {source})",
             f"[ssi]   {3 * cnt.N} DOFs ({cnt.N} nodes), {cnt.Ev} elements with images, {cnt.steps} steps, "
             f"{cnt.nt} traction nodes; lags stored {cnt.Lx + cnt.k} ({cnt.Lx} exact + {cnt.k} interpolating, "
             f"of {cnt.L} the run reaches): {nd} dense, {ns} block-sparse"
             + (f", {n1} single-precision block-sparse" if n1 else "")
             + (" (all block-sparse: the dense choice would not fit the limit)" if cnt.fill > 1 else ""),
             f"[ssi]   lag matrices {cnt.lag_bytes() / 1e9:.3g} GB; {cnt.nb_total_used().sum():.4g} blocks "
             f"assembled; node: {cores} cores, {node_mem / 1e9:.3g} GB, {q} ranks per node",
             ]
    lines += _area_line(ab)
    if cc is not None:
        from ..coupling.cost import describe
        lines.append(describe(cc))
    lines.append("[ssi]   ranks nodes | setup_s assembly_s factor_s history_s solve_s "
                 + ("coupling_setup_s coupling_loop_s " if cc is not None else "")
                 + "time_loop_s | total | peak_GB GB/rank_max GB/node | fits")
    rows = []
    for p in ranks:
        t = predict(cnt, c, p, q, cores)
        if ab:                              # (the area loads' vectors, made after the assembly, beside the stored
            steady = p * c["m0"] + t["lag_bytes"] + ab          # lags: the run's max(peak, lags + them))
            t["peak_bytes"] = max(t["peak_bytes"], steady)
            t["peak_rank_bytes"] = max(t["peak_rank_bytes"], steady / p)
        if cc is not None:            # the structure, the interface matrices and the coupled step
            bem_solve = bem_solve_seconds(c, cnt.N, p)
            add = cc.predict(c, p, bem_solve)
            t.update(add)
            t["loop"] += add["cpl_loop"]
            t["total"] += add["cpl_setup"] + add["cpl_loop"]
            t["peak_bytes"] += add["cpl_bytes"]
            t["peak_rank_bytes"] += add["cpl_bytes"] / p
        nodes = int(math.ceil(p / float(q)))
        per_node = t["peak_bytes"] / p * min(q, p)
        per_node = max(per_node, t["peak_rank_bytes"] * min(q, p) if p == 1 else per_node)
        fits = per_node <= 0.9 * node_mem
        refuse = _refuses(cnt, p, q)
        flag = "yes" if fits else "NO"
        if refuse:
            flag += "; the run's memory check would refuse it (-ssi_memory_limit)"
        if min(q, p) > cores:
            flag += f" (oversubscribed: {min(q, p)} ranks on {cores} cores)"
        t.update({"ranks": p, "nodes": nodes, "node_bytes": per_node, "fits": fits})
        rows.append(t)
        lines.append(f"[ssi]   {p:5d} {nodes:5d} | {t['setup']:7.3g} {t['assembly']:10.4g} {t['factor']:8.3g} "
                     f"{t['history']:9.4g} {t['solve']:7.3g} "
                     + (f"{t['cpl_setup']:16.4g} {t['cpl_loop']:15.4g} " if cc is not None else "")
                     + f"{t['loop']:11.4g} | {fmt_time(t['total']):>7} | "
                     f"{t['peak_bytes'] / 1e9:7.3g} {t['peak_rank_bytes'] / 1e9:11.3g} {per_node / 1e9:7.3g} | {flag}")
    lines.append(_verdict(rows, node_mem))
    lines += _toeplitz_lines(cfg, prob, cnt, ranks)
    lines.append(f"[ssi]   (model set-up took {cnt.setup_s:.3g} s on {comm.getSize()} rank(s); times are "
                 f"-log_view times; the model's measured error: jobscripts/README.md)")
    out("\n".join(lines))
    return {"counts": cnt, "rows": rows}


def _verdict(rows, node_mem, what="the node memory", advice="-ssi_interp, symmetry or a coarser mesh"):
    """The estimate's last line: the fewest ranks that fit and the fastest of those, or what to change."""
    ok = [r for r in rows if r["fits"]]
    if ok:
        best = min(ok, key=lambda r: r["total"])
        nodes = best.get("nodes", 1)
        return (f"[ssi]   verdict: fits {what} from {ok[0]['ranks']} rank(s); fastest predicted "
                f"{fmt_time(best['total'])} on {best['ranks']} rank(s)"
                + (f" on {nodes} nodes (-ssi_estimate_ranks_per_node, -ssi_estimate_cores_per_node)"
                   if nodes > 1 else ""))
    return (f"[ssi]   verdict: does NOT fit {what} ({node_mem / 1e9:.3g} GB per node) at any of these rank counts: "
            f"use fewer ranks per node, more nodes, {advice}")


def _toeplitz_report(cfg, comm, ranks, cores, q, node_mem, coupled=None, cc=None, c=None):
    """Collective: the estimate block of a run the toeplitz store takes (-ssi_lag_store toeplitz or auto on
    a uniform flat grid), or None (not such a grid: the dense model's block follows). The dense model's
    counts are not made: its element-pair tables hold every (node, element) pair (O(N^2) on a whole
    grid: minutes and GBs on a 60 m site), and the run does not store those matrices. Coupled
    (``coupled``: build_coupled's tuple, ``cc``: its CoupledCounts, ``c``: the constants), the soil is the
    coupled set-up's and the coupling's set-up and steps are added (``CoupledCounts.predict``), with the step
    matrix's factorisation and the steps' solves in the total (``toeplitz.step_lu``: the factors' entries on
    a uniform grid, in the mirror-symmetric blocks the run would use, ``mirror.blocks_of``); the assembly of
    lags 1-2 (seconds on the 72 m building) is not modelled."""
    from ..bem.halfspace import HalfSpace
    from ..bem.toeplitz import detect, estimate as tz_estimate, kernel_offsets, traction_grid, block_of
    from ..bem.lagset import load_kernels
    from ..sysmem import process_rss
    from ..petsc import SSIError
    if cfg.get("lag_store", "dense") == "dense":
        return None
    t0 = time.perf_counter()
    prob = coupled[0] if coupled is not None else HalfSpace(cfg, comm, log=lambda m: None)
    prob.warn_diffraction()
    plan = prob.interp_plan()
    ls = prob.lagset(plan)
    try:
        if not ls.flat:
            raise SSIError("the surface is not flat")
        lat = detect(ls.VX, prob.mesh.nodes, n_cells=prob.mesh.n_cells)
    except SSIError:
        return None
    lat.n_offsets = len(kernel_offsets(lat))
    ab = prob.area_bytes()
    beside = ab
    if coupled is not None:             # (the coupled run decides auto's plan with its interface matrices beside)
        from ..coupling.model import interface_bytes
        beside += interface_bytes(cfg, prob, coupled[1], coupled[2], comm.getSize())
    plan, ls = prob.toeplitz_plan(ls, plan, beside, lattice=lat)   # (-ssi_interp auto: as the run chooses)
    glat = traction_grid(lat, ls.VT)
    single = cfg.get("toeplitz_precision", "double") == "single"
    g = prob.toeplitz_side_bytes(ls, plan)
    load_kernels()                      # the process measured with the compiled kernels it will hold
    rss = process_rss()
    limit = cfg.memory_limit * 1e9 if cfg.memory_limit > 0 else 0.8 * node_mem
    k = plan.k if plan.active else 0
    N = prob.mesh.n_nodes
    lines = [f"[ssi] estimate of this {'coupled' if cc is not None else 'BEM'} run on the toeplitz lag store (model "
             "petsc_ssi/bem/toeplitz.py estimate" + (" and petsc_ssi/coupling/cost.py" if cc is not None else "")
             + "; the dense lag matrices' model is not counted on a uniform grid)",
             f"[ssi]   {3 * N} DOFs ({N} nodes), {len(ls.Vc)} elements with images, {prob.n_steps} steps, "
             f"{prob.regions.n_t} traction nodes; {lat.describe()}; kernels: {plan.Lx} exact lags + {k} "
             f"interpolating (of {prob.L} the run reaches), states kept {prob.L} ("
             f"{'single' if single else 'double'} precision transforms)"
             + (f"; G kernels on the traction elements' {glat.in_n[0]} x {glat.in_n[1]} window (FFT grid "
                f"{glat.Mx} x {glat.My})" if glat is not None else ""),
             "[ssi]   ranks | kernels_s history_s factor_s solve_s steps_s total | GB over the ranks beside the "
             "processes | with the processes (this one's resident size each) | fits"]
    for i, ln in enumerate(_area_line(ab)):
        lines.insert(2 + i, ln)
    if cc is not None:
        from ..coupling.cost import describe
        lines.insert(2, describe(cc))
        lines[-1] = ("[ssi]   ranks | kernels_s history_s factor_s solve_s steps_s coupling_setup_s coupling_loop_s total "
                     "| GB over the ranks beside the processes | with the processes (this one's resident size each) | fits")
    # the step matrix's LU (toeplitz.step_lu_of): its entries, mirror blocks; a solve a step in the loop
    from ..bem.toeplitz import step_lu_of, loop_rest
    kappa = c.get("kappa") if c is not None else None       # (the coupled estimate's constants, else the run's)
    # steps_s: the march's own work a step, a seismic wave's and the field snapshots (toeplitz.loop_rest)
    rest = loop_rest(cfg, prob.n_steps, N)
    ent, _, _, rho, nblk = step_lu_of(cfg, prob, lat, 2)
    lines.insert(3 if cc is not None else 2,
                 f"[ssi]   step matrix: {ent / 1e6:.3g} M entries in its LU's factors modelled (reach {rho:.3g} node "
                 "spacings" + (f", {nblk} mirror-symmetric blocks, bem/mirror.py" if nblk > 1 else "")
                 + "; toeplitz.step_lu)")
    rows = []
    for p in ranks:
        b, tb, th = tz_estimate(lat, prob.L, prob.n_steps, p, block_of(cfg), 3 * N, g, plan=plan,
                                stabilized=cfg.scheme.startswith("stabili"), glat=glat, single=single,
                                fft_ranks=int(cfg.get("toeplitz_fft_ranks", 0) or 0), reach=rho)
        b += ab
        _, fac, one, _, _ = step_lu_of(cfg, prob, lat, p, kappa=kappa)
        solves_s = prob.n_steps * one
        total = tb + th + fac + solves_s + rest
        if cc is not None:            # the structure, the interface matrices and the coupled steps
            add = cc.predict(c, p, one)
            b += add["cpl_bytes"]
            total += add["cpl_setup"] + add["cpl_loop"]
            cpl = (f" {fac:8.3g} {solves_s:7.3g} {rest:7.3g} {add['cpl_setup']:16.4g} {add['cpl_loop']:15.4g} "
                   f"{fmt_time(total):>7}")
        else:
            cpl = f" {fac:8.3g} {solves_s:7.3g} {rest:7.3g} {fmt_time(total):>7}"
        tot = b + p * rss
        per_node = tot / p * min(q, p)
        fits = per_node <= limit
        flag = "yes" if fits else "NO: the run's memory check would refuse it (-ssi_memory_limit)"
        if min(q, p) > cores:
            flag += f" (oversubscribed: {min(q, p)} ranks on {cores} cores)"
        lines.append(f"[ssi]   {p:5d} | {tb:9.3g} {th:9.3g}{cpl} | {b / 1e9:7.3g} | {tot / 1e9:7.3g} | {flag}")
        rows.append({"ranks": p, "nodes": int(math.ceil(p / float(q))), "total": total, "node_bytes": per_node,
                     "fits": fits, "bytes": b})
    lines.append(_verdict(rows, limit, what="the run's memory limit",
                          advice="-ssi_toeplitz_precision single, -ssi_interp, symmetry or a coarser mesh"))
    lines.append(f"[ssi]   (model set-up took {time.perf_counter() - t0:.3g} s on {comm.getSize()} rank(s); the "
                 "node's limit: 80 % of its memory or -ssi_memory_limit, as the run's check)")
    return lines, rows


def _toeplitz_lines(cfg, prob, cnt, ranks):
    """The toeplitz lag store's estimate (bem/toeplitz.py) per rank count, where -ssi_lag_store asks for it
    and the surface is a uniform flat grid (else the reason, one line)."""
    if cfg.get("lag_store", "dense") == "dense":
        return []
    from ..bem.toeplitz import detect, estimate as tz_estimate, kernel_offsets, traction_grid, block_of, step_lu_of, \
        loop_rest
    from ..petsc import SSIError
    try:
        if not cnt.lagset.flat:
            raise SSIError("the surface is not flat")
        lat = detect(cnt.lagset.VX, prob.mesh.nodes, n_cells=prob.mesh.n_cells)
    except SSIError as e:
        return [f"[ssi]   toeplitz lag store: not on this surface ({str(e).split(': ', 1)[-1]}); the rows above hold"]
    lat.n_offsets = len(kernel_offsets(lat))
    glat = traction_grid(lat, cnt.lagset.VT)
    out = [f"[ssi]   toeplitz lag store ({lat.describe()}): ranks | kernels_s history_s factor_s solve_s steps_s | GB "
           "over the ranks beside the processes"]
    rest = loop_rest(cfg, prob.n_steps, prob.mesh.n_nodes)
    g = prob.toeplitz_side_bytes(cnt.lagset, prob.plan)
    for p in ranks:
        _, fac, one, rho, _ = step_lu_of(cfg, prob, lat, p)
        b, tb, th = tz_estimate(lat, prob.L, prob.n_steps, p, block_of(cfg), 3 * prob.mesh.n_nodes, g,
                                plan=prob.plan, stabilized=cfg.scheme.startswith("stabili"), glat=glat,
                                single=cfg.get("toeplitz_precision", "double") == "single",
                                fft_ranks=int(cfg.get("toeplitz_fft_ranks", 0) or 0), reach=rho)
        out.append(f"[ssi]   {p:5d} | {tb:9.3g} {th:9.3g} {fac:8.3g} {prob.n_steps * one:7.3g} {rest:7.3g} | "
                   f"{b / 1e9:7.3g}")
    return out


def _refuses(cnt, p, q):
    """Whether the run's own check (HalfSpace.check_memory: the estimated peak shared
    by the ranks, the most loaded node's part against the per-node limit) refuses it."""
    used = cnt.nb_total_used()
    peak = cnt.peak_rule(used, cnt.storage, p)
    ab = getattr(cnt, "area_bytes", 0.0)
    if ab:                      # (HalfSpace._lag_memory: max(the assembly's peak, the stored lags + the area vectors))
        peak = max(peak, cnt.lag_bytes() + ab)
    return peak * min(q, p) / float(p) > cnt.limit


def _area_line(ab):
    """The estimate's line of the area loads' lag vectors (``HalfSpace.area_bytes``, the run's own count: one
    column a lag a node row per symmetry image, an upper bound), or none."""
    if not ab:
        return []
    return [f"[ssi]   area loads (-ssi_load_area): {ab / 1e9:.3g} GB of lag vectors over the ranks, beside the "
            "stored lags in the peaks below"]


def main():
    """Collective: print the predicted cost (time per stage, memory, whether it fits the nodes) of
    the case the options describe, without assembling (``bem.cost``)."""
    from ..petsc import init
    kind = problem_kind()
    if kind == "fem":
        raise SSIError("petsc-ssi estimate models the BEM half-space (-ssi_problem bem, and the BEM part of "
                       "-ssi_problem ssi); the FEM structure alone is cheap: run it with -log_view")
    cfg = resolve(kind, ("estimate",))
    return report(cfg, init().COMM_WORLD)
