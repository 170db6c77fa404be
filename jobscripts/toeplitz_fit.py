#!/usr/bin/env python3
"""Fit the toeplitz store's time rates (petsc_ssi/bem/toeplitz.py RATES) to -log_view logs of toeplitz
runs (jobscripts/toeplitz_bench.sh), and print the model against each log.

    python jobscripts/toeplitz_fit.py [--check] [--products-rate R] LOG...
        (--check: the committed RATES, no fit; --products-rate: r_products held at R flop/s a rank, the other
        history terms fitted to what the products leave: on a few logs the products' and the per-step terms'
        counts are nearly collinear, and the free fit put r_products at infinity on 2026-11-29's)

Each log's option table rebuilds its set-up in this process (no assembly: the lattice, the interpolation
plan, the traction window), as `petsc-ssi estimate` does; ``toeplitz.estimate`` is then evaluated with one
rate at a time to get each term's count, and the rates are fitted by non-negative least squares on
relative errors: the kernels' build per side (t_kernel_byte, seconds per byte of the kernels a rank writes,
against both sides' 'weights' where the logs give the build's parts, else fitted with the next; t_pair_lag,
seconds per H kernel offset and lag, against the rest of the H side's 'kernels ... s'; g_pair_factor, a G
offset's seconds over an H offset's, against the rest of the G side's), the
history sum (event SSI_BEM_History) against the products (1 / r_products), the
per-step DOF term (t_step_dof), the per-step FFT-grid term (t_step_grid) and r_sums (the interpolated lags'
weighted states anchor by anchor: multi-linear hats, the sites); r_sums_span (over the anchors' common span: Chebyshev)
is the median over the logs that have it of the span's flops over the event SSI_BEM_HistInterp less its
anchors' kernel products. Oversubscribed runs are left out. The printed RATES line goes into
toeplitz.py by hand, with the logs' names and date in its comment.
"""
import contextlib
import io
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)
from calibrate import case_config, log_options, _nnls  # noqa: E402
from toeplitz_table import row  # noqa: E402


def terms(opts, ranks):
    """{term: count} of ``toeplitz.estimate`` for the case ``opts`` on ``ranks`` ranks."""
    from petsc_ssi.bem.halfspace import HalfSpace
    from petsc_ssi.bem.toeplitz import detect, estimate, kernel_offsets, traction_grid, RATES, block_of, step_lu_of
    PETSc, cfg = case_config(opts)
    with contextlib.redirect_stdout(io.StringIO()):
        if opts.get("problem") == "ssi":    # a coupled run: the soil of its set-up (the interface's tractions)
            from petsc_ssi.coupling.model import build_coupled
            from petsc_ssi.app.kinds import resolve
            cfg = resolve("ssi", ("estimate",))
            prob = build_coupled(cfg, PETSc.COMM_SELF)[0]
        else:
            prob = HalfSpace(cfg, PETSc.COMM_SELF, log=lambda m: None)
        plan = prob.interp_plan()
        ls = prob.lagset(plan)
    lat = detect(ls.VX, prob.mesh.nodes)
    lat.n_offsets = len(kernel_offsets(lat))
    glat = traction_grid(lat, ls.VT)
    big = 1e300
    args = (lat, prob.L, prob.n_steps, ranks, block_of(cfg), 3 * prob.mesh.n_nodes, 0.0)
    kw = dict(plan=plan, stabilized=cfg.scheme.startswith("stabili"), glat=glat,
              single=cfg.get("toeplitz_precision", "double") == "single")
    zero = {"r_products": big, "r_sums": big, "r_sums_span": big, "t_step_dof": 0.0, "t_step_grid": 0.0,
            "t_step_elem": 0.0, "t_pair_lag": 0.0, "t_kernel_byte": 0.0}
    one = lambda **r: estimate(*args, rates=dict(zero, **r), **kw)
    # the kernels' build per side: H's offsets and lags (glat=None) and G's, unweighted (g_pair_factor 1)
    # (two terms: the integrals and planes, t_pair_lag, 5 of 9 slots with real kernels, and the kernels' bytes a
    # rank writes, t_kernel_byte)
    pairs_h = estimate(*args, rates=dict(zero, t_pair_lag=1.0), **dict(kw, glat=None))[1]
    pairs_g = one(t_pair_lag=1.0, g_pair_factor=1.0)[1] - pairs_h
    bytes_h = estimate(*args, rates=dict(zero, t_kernel_byte=1.0), **dict(kw, glat=None))[1]
    bytes_g = one(t_kernel_byte=1.0)[1] - bytes_h
    return {"pairs_h": pairs_h, "pairs_g": pairs_g, "bytes_h": bytes_h, "bytes_g": bytes_g,
            "kept": one(t_kernel_byte=1.0)[2],      # (the kept states' transforms' first write, in the history's seconds)
            "prod": one(r_products=1.0)[2], "dof": one(t_step_dof=1.0)[2],
            "grid": one(t_step_grid=1.0)[2], "elem": one(t_step_elem=1.0)[2],
            "sums": one(r_sums=RATES["r_sums"], r_sums_span=RATES["r_sums_span"])[2],
            # the weighted states anchor by anchor (multi-linear hats), flops a rank
            "sums1": one(r_sums=1.0)[2],
            # the weighted states over the anchors' common span (Chebyshev), flops a rank, and the anchors'
            # kernel products of the same event (SSI_BEM_HistInterp), flops a rank (at r_products in the model)
            "span": one(r_sums_span=1.0)[2], "interp_prod": _interp_products(lat, glat, plan, prob.n_steps, ranks, kw, cfg),
            # a step's solve with the step matrix's factors (the runs' model, toeplitz.step_lu_of), seconds
            "solve": step_lu_of(cfg, prob, lat, ranks)[2]}


def _interp_products(lat, glat, plan, n_steps, ranks, kw, cfg):
    """Flops a rank of the interpolating matrices' kernel products (8 m F k per step that reads them, 4 with real
    kernels)."""
    from petsc_ssi.bem.toeplitz import interp_work, block_of
    if plan is None or not plan.active:
        return 0.0
    isteps = interp_work(plan, n_steps, block_of(cfg), kw["stabilized"])[0]
    from petsc_ssi.bem.toeplitz import is_point_symmetric
    return sum((4.0 if is_point_symmetric(g) else 8.0) * m * g.F * plan.k * isteps
               for g, m in ((lat, 144), (glat, 180)) if g is not None) / ranks


def main(logs, check=False, products_rate=None):
    """Fit the rates to ``logs`` and print the fitted model against each; ``check``: no fit, the committed
    RATES (and a step's solve, toeplitz.step_lu_of, as the runs predict it) against each log."""
    from petsc_ssi.bem.toeplitz import RATES
    runs = []
    for path in logs:
        text = open(path, errors="replace").read()
        opts = log_options(text)
        r = row(path)
        if not opts or opts.get("lag_store") != "toeplitz" or not r.get("kernels_s") or r["history_s"] != r["history_s"]:
            print(f"[toeplitz_fit] skip {path}: not a finished toeplitz run", file=sys.stderr)
            continue
        if int(r["ranks"]) > (os.cpu_count() or 1):
            print(f"[toeplitz_fit] skip {path}: oversubscribed", file=sys.stderr)
            continue
        m = re.findall(r"^SSI_BEM_Solve\s+(\d+)\s+\S+\s+(\S+)", text, re.M)      # the time loop's: the last
        r["solve_s"] = float(m[-1][1]) / int(m[-1][0]) if m else float("nan")
        runs.append((path, r, terms(opts, int(r["ranks"]))))
    kern = np.array([r["kernels_s"] for _, r, _ in runs], float)
    kh = np.array([r.get("kernels_h_s", r["kernels_s"]) for _, r, _ in runs], float)
    kg = np.array([r.get("kernels_g_s", 0.0) for _, r, _ in runs], float)
    hist = np.array([r["history_s"] for _, r, _ in runs], float)
    if check:
        fit = {k: RATES[k] for k in ("r_products", "t_step_dof", "t_step_grid", "t_step_elem", "t_pair_lag",
                                     "t_kernel_byte", "g_pair_factor", "r_sums")}
    else:
        fit = {}
        bh = np.array([t["bytes_h"] for *_, t in runs])
        bg = np.array([t["bytes_g"] for *_, t in runs])
        if all("kernels_weights_h_s" in r for _, r, _ in runs):
            # the logs give the build's parts (since 2026-12-03): t_kernel_byte from the weights (the kernels
            # written) of both sides, t_pair_lag from the rest of the H side's build
            wh = np.array([r["kernels_weights_h_s"] for _, r, _ in runs])
            wg = np.array([r["kernels_weights_g_s"] for _, r, _ in runs])
            # (least squares on the seconds, not their ratios: the first write of fresh memory, which this term
            # mostly is, costs more a byte the more the run needs: the H side's 0.89-1.53 s/GB where a rank wrote at
            # most 0.3 GB, 2.1-4.6 s/GB at 0.4-3 GB, the table's column, 2026-12-03; and the runs where the term
            # matters are the large ones)
            sel = bg > 0
            x, y = np.r_[bh, bg[sel]], np.r_[wh, wg[sel]]
            fit["t_kernel_byte"] = float(max(x @ y / (x @ x), 0.0))
            fit["t_pair_lag"] = float(_nnls(np.array([[t["pairs_h"]] for *_, t in runs]), kh - wh)[0])
        else:
            fit["t_pair_lag"], fit["t_kernel_byte"] = (float(v) for v in _nnls(
                np.array([[t["pairs_h"], t["bytes_h"]] for *_, t in runs]), kh))
        # G's offsets against the G side's own seconds less its bytes' (the logs that print them)
        gsel = [i for i, (*_, t) in enumerate(runs) if t["pairs_g"] > 0 and kg[i] > 0]
        gx = np.array([[fit["t_pair_lag"] * runs[i][2]["pairs_g"]] for i in gsel])
        parts = all("kernels_weights_g_s" in r for _, r, _ in runs)
        gy = np.array([kg[i] - runs[i][1]["kernels_weights_g_s"] if parts else max(kg[i] - fit["t_kernel_byte"] * bg[i], 1e-3)
                       for i in gsel])
        fit["g_pair_factor"] = float(_nnls(gx, gy)[0]) if gsel and gx.any() else RATES["g_pair_factor"]
        # the history less the weighted states over a common span (Chebyshev, at the committed r_sums_span, refitted
        # below from its own event) and the kept transforms' first write (at t_kernel_byte, fitted above); the
        # anchor-by-anchor weighted states (multi-linear: the sites) fitted as r_sums
        span_s = np.array([t["span"] for *_, t in runs]) / RATES["r_sums_span"] \
            + fit["t_kernel_byte"] * np.array([t["kept"] for *_, t in runs])
        S1 = np.array([[t["sums1"]] for *_, t in runs])
        if products_rate:           # r_products held (the fit's products and per-step terms are nearly collinear
            prod = np.array([t["prod"] for *_, t in runs]) / products_rate      # on few logs), the rest fitted
            A = np.hstack([np.array([[t["dof"], t["grid"], t["elem"]] for *_, t in runs]), S1])
            t_dof, t_grid, t_elem, inv_s = _nnls(A, hist - span_s - prod)
            inv_r = 1.0 / products_rate
        else:
            A = np.hstack([np.array([[t["prod"], t["dof"], t["grid"], t["elem"]] for *_, t in runs]), S1])
            inv_r, t_dof, t_grid, t_elem, inv_s = _nnls(A, hist - span_s)
        fit.update({"r_products": 1.0 / inv_r if inv_r > 0 else float("inf"), "t_step_dof": float(t_dof),
                    "t_step_grid": float(t_grid), "t_step_elem": float(t_elem),
                    "r_sums": 1.0 / inv_s if inv_s > 0 else RATES["r_sums"]})
    # r_sums_span from the logs whose far lags weigh states over a common span (Chebyshev): the span's flops
    # over the event SSI_BEM_HistInterp less its anchors' kernel products at r_products; the median of the logs
    spans = []
    for path, r, t in runs:
        m = re.search(r"^SSI_BEM_HistInterp\s+(\d+)\s+\S+\s+(\S+)", open(path, errors="replace").read(), re.M)
        if m and t["span"] > 1.0:          # (a run without a common span counts ~1e-290 of it: the zero rates' 1e300)
            left = float(m.group(2)) - t["interp_prod"] / fit["r_products"]
            spans.append((os.path.relpath(path, ROOT), t["span"] / left if left > 0 else float("nan")))
    for name, rate in spans:
        print(f"[toeplitz_fit] {name}: the weighted states over the common span at {rate / 1e9:.3g} GFlop/s a rank")
    fit["r_sums_span"] = RATES["r_sums_span"] if check or not spans else float(np.nanmedian([v for _, v in spans]))
    print("| log | ranks | dofs | kernels measured / model [s] | history measured / model [s] | a step solve measured / "
          "model [ms] | weights a GB a rank written, H / G [s/GB] | the rest of the build an offset and lag, H / G [us] |")
    print("|---|---|---|---|---|---|---|---|")
    for (path, r, t), k, h in zip(runs, kern, hist):
        mk = (fit["t_pair_lag"] * (t["pairs_h"] + fit["g_pair_factor"] * t["pairs_g"])
              + fit["t_kernel_byte"] * (t["bytes_h"] + t["bytes_g"]))
        mh = (t["prod"] / fit["r_products"] + fit["t_step_dof"] * t["dof"] + fit["t_step_grid"] * t["grid"]
              + fit["t_step_elem"] * t["elem"] + t["sums1"] / fit["r_sums"] + t["span"] / fit["r_sums_span"]
              + fit["t_kernel_byte"] * t["kept"])
        ms = 1e3 * t["solve"]
        # (the build's parts where the log gives them: the weights' seconds over the kernels' bytes a rank writes,
        # and the rest of each side's build over its offsets and lags a rank, G's unweighted)
        wpg = rest = "-"
        if "kernels_weights_h_s" in r:
            g = lambda a, b: f"{a / b:.3g}" if b > 0 else "-"
            wpg = (f"{g(r['kernels_weights_h_s'], t['bytes_h'] / 1e9)} / "
                   f"{g(r['kernels_weights_g_s'], t['bytes_g'] / 1e9)}")
            rest = (f"{g(1e6 * (r['kernels_h_s'] - r['kernels_weights_h_s']), t['pairs_h'])} / "
                    f"{g(1e6 * (r['kernels_g_s'] - r['kernels_weights_g_s']), t['pairs_g'])}")
        print(f"| {os.path.relpath(path, ROOT)} | {r['ranks']} | {r['dofs']} | {k:.3g} / {mk:.3g} ({100 * (mk / k - 1):+.0f} %) "
              f"| {h:.3g} / {mh:.3g} ({100 * (mh / h - 1):+.0f} %) | {1e3 * r['solve_s']:.3g} / {ms:.3g} | {wpg} | {rest} |")
    print(("committed: " if check else "fitted: ") + ", ".join(f'"{k}": {v:.3g}' for k, v in fit.items()))


if __name__ == "__main__":
    args = sys.argv[1:]
    rate = None
    if "--products-rate" in args:           # r_products held at this rate (flop/s a rank), the rest fitted
        i = args.index("--products-rate")
        rate = float(args[i + 1])
        args = args[:i] + args[i + 2:]
    main([a for a in args if a != "--check"], check="--check" in args, products_rate=rate)
