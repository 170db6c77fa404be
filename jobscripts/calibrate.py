#!/usr/bin/env python3
"""Fit the machine constants of the cost model (petsc_ssi/bem/cost.py) to
-log_view/-memory_view logs of BEM runs.

  python jobscripts/calibrate.py [--out petsc_ssi/estimate_constants.json]
                                 [--machine NAME] [--cores N] LOG...

Each log must hold PETSc's option table (every -log_view log does): the case
is rebuilt from it in this process (set-up only, no assembly) and the model
counts the run's work (blocks, bytes streamed, products, ...). The constants
are then fitted by non-negative least squares on relative errors, stage by
stage: assembly, factorisation, history sum, solve, set-up, the rest, and the
peak memory. Oversubscribed runs (more ranks than cores) are not fitted: the
model's oversubscription factor (ranks / cores) is a guess, checked with
--check. A log written by the scaling drivers starts with a
'# scaling: ... cores_per_node=C' line; other logs are taken as one-node runs
on a machine of --cores cores (default: this machine's).

On a cluster: run jobscripts/strong_scaling.sh and weak_scaling.sh there
(jobscripts/slurm.sbatch or pbs.sh), then
  python jobscripts/calibrate.py --machine mycluster --out mycluster.json out/scaling/*.log
and give the table to the estimate: -ssi_estimate_constants mycluster.json.
"""
import argparse
import contextlib
import importlib
import io
import json
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)
from logview import parse  # noqa: E402

_CACHE = {}


def log_options(text):
    """The -ssi_ options of PETSc's option table of a log: {name: value}."""
    m = re.search(r"#PETSc Option Table entries:\n(.*?)#End of PETSc Option Table entries", text, re.S)
    if not m:
        return None
    opts = {}
    for line in m.group(1).splitlines():
        # from PETSc 3.19 each entry ends with where it came from: "-ssi_dt 0.005 # (source: command line)"
        line = re.sub(r"\s*# \(source: [^)]*\)\s*$", "", line.strip())
        if not line.startswith("-ssi_"):
            continue
        key, _, val = line[1:].partition(" ")
        if re.match(r"ssi_(bem|fem|coupling|modes)_(ksp|pc|mat)", key):
            continue
        opts[key[len("ssi_"):]] = val.strip()
    if "partition" not in opts:      # the run's own line (-ssi_partition's default); none before it existed: equal
        m = re.search(r"-ssi_partition (\w+) \(estimated work", text)
        opts["partition"] = m.group(1) if m else "equal"
    return opts


def log_meta(text, cores_default):
    m = re.search(r"^# scaling: (.*)$", text, re.M)
    meta = dict(kv.split("=", 1) for kv in m.group(1).split()) if m else {}
    return {"study": meta.get("study", ""), "case": meta.get("case", ""),
            "cores": int(meta.get("cores_per_node", cores_default)),
            "nodes": int(meta.get("nodes", 1)), "oversubscribed": int(meta.get("oversubscribed", 0))}


def measured(text):
    lv = parse(text)
    st, ev = lv["stages"], lv["events"]
    e = lambda k: ev.get(k, (0, 0.0))[1]
    asm = st.get("SSI BEM assembly", float("nan"))
    loop = st.get("SSI BEM time loop", float("nan"))
    setup = st.get("SSI BEM setup", float("nan"))
    tot = lv["total_s"]
    return {"ranks": lv["ranks"], "total": tot, "setup": setup, "assembly": asm - e("SSI_BEM_Factor"),
            "assembly_stage": asm, "kernels": e("SSI_BEM_Assembly"), "factor": e("SSI_BEM_Factor"),
            "history": e("SSI_BEM_History"), "hist_panel": e("SSI_BEM_HistPanel"), "solve": e("SSI_BEM_Solve"),
            "loop": loop,
            "rest": tot - setup - asm - loop if tot else float("nan"),
            "loop_rest": loop - e("SSI_BEM_History") - e("SSI_BEM_Solve"),
            "peak": lv["peak_rss_bytes"], "peak_rank": lv.get("peak_rss_max_rank_bytes")}


def case_config(opts):
    """(PETSc, cfg): this process's options database holding the -ssi_ options ``opts`` of a log (and no
    others), resolved as `petsc-ssi estimate` resolves them (common, bem, estimate)."""
    from petsc_ssi.petsc import init
    PETSc = init([sys.argv[0]])
    from petsc_ssi import options
    importlib.import_module("petsc_ssi.app.estimate")        # (registers the options)
    db = PETSc.Options()
    for k in list(db.getAll()):
        if k.startswith("ssi_"):
            db.delValue(k)
    for k, v in opts.items():
        db.setValue("ssi_" + k, v)
    db.setValue("ssi_warn_beta", "0")
    return PETSc, options.resolve(("common", "bem", "estimate"))


def counts(opts, ranks):
    """The model's counts of the case ``opts`` for rank counts ``ranks`` (in-process set-up)."""
    key = (tuple(sorted((k, v) for k, v in opts.items() if k not in ("output",))), tuple(ranks))
    if key in _CACHE:
        return _CACHE[key]
    from petsc_ssi.app import estimate
    PETSc, cfg = case_config(opts)
    with contextlib.redirect_stdout(io.StringIO()):
        _, _, cnt = estimate.count_run(cfg, PETSc.COMM_SELF, sorted(set(ranks)), 0.0)
    _CACHE[key] = cnt
    return cnt


def load(logs, cores_default):
    """[(path, meta, measured, counts)] of the BEM logs that finished."""
    out = []
    for path in logs:
        text = open(path, errors="replace").read()
        opts = log_options(text)
        if not opts or opts.get("problem", "bem") != "bem" or "SSI BEM time loop" not in text:
            print(f"[calibrate] skip {path}: no finished BEM run with an option table", file=sys.stderr)
            continue
        meas = measured(text)
        meta = log_meta(text, cores_default)
        meta["plot"] = "plot" in opts and opts["plot"] in ("", "1", "true", "yes", "on")
        cnt = counts(opts, [meas["ranks"]])
        out.append((path, meta, meas, cnt))
    return out


def terms(meta, meas, cnt):
    """Model terms of one run (estimate.features), with the run's placement."""
    from petsc_ssi.bem.cost import features
    p = meas["ranks"]
    q = int(np.ceil(p / float(meta["nodes"])))
    mx, over, m = features(cnt, p, q, meta["cores"])
    return p, q, mx, over, m


def _nnls(A, b):
    from scipy.optimize import nnls
    w = 1.0 / np.maximum(np.abs(b), 1e-3)        # relative errors
    x, _ = nnls(A * w[:, None], b * w)
    return x


def fit(runs):
    """Constants of estimate.py fitted to ``runs`` (see the module docstring)."""
    from petsc_ssi.bem.cost import FALLBACK
    c = dict(FALLBACK)
    rows = [(meta, meas, cnt) + terms(meta, meas, cnt) for _, meta, meas, cnt in runs]
    arr = lambda f: np.array([f(*r) for r in rows], float)
    # assembly (stage minus the factorisation inside it)
    # kernels (event SSI_BEM_Assembly: integration and triplets) and the Mat build
    # (the rest of the stage) separately, as -log_view splits them
    A = np.stack([arr(lambda *r: 1.0), arr(lambda me, ms, cn, p, q, mx, o, m: o * mx["B"]),
                  arr(lambda me, ms, cn, p, q, mx, o, m: o * mx["I"])], 1)
    c["a0"], c["a_blk"], c["a_int"] = _nnls(A, arr(lambda me, ms, *r: ms["kernels"]))
    A = np.stack([arr(lambda me, ms, cn, p, q, mx, o, m: o * mx["D"]),
                  arr(lambda me, ms, cn, p, q, mx, o, m: o * mx["S"]),
                  arr(lambda me, ms, cn, p, q, mx, o, m: o * (cn.Lx + cn.k))], 1)
    c["a_dense"], c["a_sparse"], c["a_lag"] = _nnls(A, arr(lambda me, ms, *r: ms["assembly"] - ms["kernels"]))
    # factorisation, solve
    N15 = arr(lambda me, ms, cn, *r: cn.N ** 1.5)
    c["c_fac"] = float(_nnls(N15[:, None], arr(lambda me, ms, *r: ms["factor"]))[0])
    nlogn = lambda cn: cn.N * np.log(max(cn.N, 2))
    A = np.stack([arr(lambda me, ms, cn, *r: cn.steps * nlogn(cn)),
                  arr(lambda me, ms, cn, p, *r: cn.steps * nlogn(cn) * (p - 1))], 1)
    s, sk = _nnls(A, arr(lambda me, ms, *r: ms["solve"]))
    c["c_sol_nlogn"], c["kappa"] = float(s), float(sk / s) if s > 0 else 0.0
    # time-blocked history sum: the panel products (event SSI_BEM_HistPanel) against their flops,
    # dense and block-sparse, each width's flops scaled by the kernel's relative rate at that width
    # (cost.panel_width_factor), with the contention of m ranks on a node (sigma_panel, on a grid);
    # the rest of the history sum as the per-step sum below
    from petsc_ssi.bem.cost import FALLBACK, panel_width_factor as pwf
    col = lambda kind, K: arr(lambda me, ms, cn, p, q, mx, o, m: o * (mx[K + "b"] / pwf(cn.block, kind)
                                                                   + mx[K + "s"] / pwf(cn.sub, kind)))
    A0 = np.stack([col("dense", "FD"), col("sparse", "FS")], 1)
    mm = arr(lambda me, ms, cn, p, q, mx, o, m: m)
    panel = arr(lambda me, ms, *r: ms.get("hist_panel", 0.0))
    has = (A0.sum(1) > 0) & (panel > 0)
    best = (None, 0.0, (0.0, 0.0))
    if has.sum() >= 2:
        for sp in np.linspace(0.0, 1.5, 61):
            A = A0[has] * (1 + sp * (mm[has] - 1))[:, None]
            x = _nnls(A, panel[has])
            err = np.sum(((A @ x - panel[has]) / panel[has]) ** 2)
            if best[0] is None or err < best[0]:
                best = (err, sp, x)
    _, c["sigma_panel"], (ird, irs) = best
    c["r_panel_dense"] = 1.0 / ird if ird > 0 and A0[has, 0].any() else FALLBACK["r_panel_dense"]
    c["r_panel_sparse"] = 1.0 / irs if irs > 0 and A0[has, 1].any() else FALLBACK["r_panel_sparse"]
    # history: bytes over bandwidth with contention sigma (grid), products
    hist = arr(lambda me, ms, *r: ms["history"] - ms.get("hist_panel", 0.0))
    best = None
    for sigma in np.linspace(0.0, 1.5, 61):
        A = np.stack([arr(lambda me, ms, cn, p, q, mx, o, m: o * mx["HD"] * (1 + sigma * (m - 1))),
                      arr(lambda me, ms, cn, p, q, mx, o, m: o * mx["HS"] * (1 + sigma * (m - 1))),
                      arr(lambda me, ms, cn, p, q, mx, o, m: o * mx["P"]),
                      arr(lambda me, ms, cn, p, q, mx, o, m: o * mx["P"] * (p > 1))], 1)
        x = _nnls(A, hist)
        err = np.sum(((A @ x - hist) / hist) ** 2)
        if best is None or err < best[0]:
            best = (err, sigma, x)
    _, c["sigma"], (ibd, ibs, c["c_op"], c["c_op_mpi"]) = best
    c["b_dense"] = 1.0 / ibd if ibd > 0 else 1e12
    c["b_sparse"] = 1.0 / ibs if ibs > 0 else 1e12
    # set-up, the rest of the time loop, the rest of the run
    A = np.stack([arr(lambda *r: 1.0), arr(lambda me, ms, cn, p, *r: cn.N * cn.Ev / p)], 1)
    c["s0"], c["s1"] = _nnls(A, arr(lambda me, ms, *r: ms["setup"]))
    c["c_step"] = float(_nnls(arr(lambda me, ms, cn, *r: cn.steps)[:, None],
                              arr(lambda me, ms, *r: max(ms["loop_rest"], 0.0)))[0])
    A = np.stack([arr(lambda *r: 1.0), arr(lambda me, *r: 1.0 if me["plot"] else 0.0)], 1)
    c["c_main"], c["c_plot"] = _nnls(A, arr(lambda me, ms, *r: max(ms["rest"], 0.0)))
    # memory: p m0 + gamma max(rho (T + c_cache C), build); rho, c_cache on a grid (m_asm = 0)
    peak = arr(lambda me, ms, *r: ms["peak"])
    best = None
    for cc in np.linspace(0.0, 1.5, 16):
        for rho in np.linspace(0.5, 1.5, 21):
            def col(me, ms, cn, p, *r):
                rk = cn.per_rank[p]
                return max(rho * sum(x["trip"] + cc * x["C"] for x in rk), sum(x["build"] for x in rk))
            A = np.stack([arr(lambda me, ms, cn, p, *r: p), arr(col)], 1)
            x = _nnls(A, peak)
            err = np.sum(((A @ x - peak) / peak) ** 2)
            if best is None or err < best[0]:
                best = (err, cc, rho, x)
    _, c["c_cache"], c["rho_trip"], (c["m0"], c["gamma"]) = best
    c["m_asm"] = 0.0
    return {k: float(v) for k, v in c.items()}


def compare(runs, c):
    """Rows of predicted vs measured per run (dict per run)."""
    from petsc_ssi.bem.cost import predict
    out = []
    for path, meta, meas, cnt in runs:
        p, q, *_ = terms(meta, meas, cnt)
        cnt.plot = meta["plot"]
        t = predict(cnt, c, p, q, meta["cores"])
        row = {"log": os.path.relpath(path, ROOT), "ranks": p, "oversubscribed": meta["oversubscribed"],
               "dofs": 3 * cnt.N, "steps": cnt.steps, "lags": cnt.Lx + cnt.k}
        for key, mkey in (("assembly", "assembly"), ("history", "history"), ("total", "total")):
            row[f"{key}_s"] = round(meas[mkey], 2)
            row[f"{key}_model_s"] = round(t[key], 2)
            row[f"{key}_err_pct"] = round(100 * (t[key] - meas[mkey]) / meas[mkey], 1)
        row["peak_GB"] = round(meas["peak"] / 1e9, 3)
        row["peak_model_GB"] = round(t["peak_bytes"] / 1e9, 3)
        row["peak_err_pct"] = round(100 * (t["peak_bytes"] - meas["peak"]) / meas["peak"], 1)
        out.append(row)
    return out


CHECK_BEGIN, CHECK_END = "<!-- model:begin -->", "<!-- model:end -->"
CHECK_COLS = ["set", "log", "ranks", "oversubscribed", "dofs", "steps", "lags", "assembly_s", "assembly_model_s",
              "assembly_err_pct", "history_s", "history_model_s", "history_err_pct", "total_s", "total_model_s",
              "total_err_pct", "peak_GB", "peak_model_GB", "peak_err_pct"]


def check(runs, table, csv_path, readme):
    """Predicted against measured for ``runs`` with a constants table: CSV and
    the README table (logs the table was fitted to are marked 'fit')."""
    import csv
    rows = compare(runs, table["constants"])
    fitted = set(table.get("logs", []))
    for r in rows:
        r["set"] = "fit" if r["log"] in fitted else "held out"
    rows.sort(key=lambda r: (r["set"] != "held out", r["log"]))
    os.makedirs(os.path.dirname(os.path.abspath(csv_path)), exist_ok=True)
    with open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=CHECK_COLS, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    summ = []
    for st in ("held out", "fit"):
        rs = [r for r in rows if r["set"] == st]
        if not rs:
            continue
        parts = []
        for k, name in (("total", "total time"), ("assembly", "assembly"), ("history", "history sum"),
                        ("peak", "peak memory")):
            e = np.abs([r[f"{k}_err_pct"] for r in rs])
            parts.append(f"{name} mean {e.mean():.1f}% / max {e.max():.1f}%")
        n30 = sum(1 for r in rs if abs(r["total_err_pct"]) <= 30 and abs(r["peak_err_pct"]) <= 30)
        summ.append(f"- **{st}** ({len(rs)} runs; {n30} within 30% in both time and memory): " + "; ".join(parts))
    md = ["| " + " | ".join(CHECK_COLS) + " |", "|" + "---|" * len(CHECK_COLS)]
    for r in rows:
        md.append("| " + " | ".join(str(r.get(c, "")) for c in CHECK_COLS) + " |")
    block = (f"Constants: `{os.path.relpath(table.get('_path', ''), ROOT)}` ({table.get('machine', '?')}, "
             f"{table.get('fitted_from', '?')}).\n\n" + "\n".join(summ) + "\n\n" + "\n".join(md))
    if readme and os.path.exists(readme):
        text = open(readme).read()
        if CHECK_BEGIN in text and CHECK_END in text:
            pre, rest = text.split(CHECK_BEGIN, 1)
            _, post = rest.split(CHECK_END, 1)
            open(readme, "w").write(pre + CHECK_BEGIN + "\n" + block + "\n" + CHECK_END + post)
    print("\n".join(summ))
    return rows


def fit_assembly_kernels(runs, c):
    """Only the assembly's kernel line (event SSI_BEM_Assembly: a0 + a_blk B + a_int I, I the integrated
    pair-lags), every other constant as in ``c``: fitted to logs of flat Pekeris grids (few distinct pair
    geometries: B identifies a_blk) together with graded building soils (many: I identifies a_int),
    which the full fit's Pekeris logs alone leave unidentified. Returns the new table's constants."""
    rows = [(meta, meas, cnt) + terms(meta, meas, cnt) for _, meta, meas, cnt in runs]
    A = np.array([[1.0, o * mx["B"], o * mx["I"]] for me, ms, cn, p, q, mx, o, m in rows], float)
    b = np.array([ms["kernels"] for me, ms, cn, p, q, mx, o, m in rows], float)
    out = dict(c)
    out["a0"], out["a_blk"], out["a_int"] = (float(v) for v in _nnls(A, b))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("logs", nargs="+")
    ap.add_argument("--out", default=os.path.join(ROOT, "petsc_ssi", "estimate_constants.json"))
    ap.add_argument("--machine", default=os.uname().nodename)
    ap.add_argument("--cores", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--check", action="store_true",
                    help="do not fit: compare the model (constants --out) with the logs, write --csv and the README table")
    ap.add_argument("--csv", default=os.path.join(HERE, "results", "model_check.csv"))
    ap.add_argument("--assembly-only", action="store_true",
                    help="fit only the assembly's kernel line a0 + a_blk B + a_int I (I: integrated pair-lags) to the "
                         "logs, the other constants kept from --out, which is rewritten with the logs added to its list")
    ap.add_argument("--readme", default=os.path.join(HERE, "README.md"))
    a = ap.parse_args(argv)
    runs = load(a.logs, a.cores)
    if a.check:
        with open(a.out) as fh:
            table = json.load(fh)
        table["_path"] = a.out
        check(runs, table, a.csv, a.readme)
        return
    if a.assembly_only:
        with open(a.out) as fh:
            table = json.load(fh)
        table["constants"] = fit_assembly_kernels(runs, table["constants"])
        table["logs"] = list(dict.fromkeys(table.get("logs", []) + [r[0] for r in runs]))
        table["fitted_from"] = (table.get("fitted_from", "").split("; the assembly's kernel line")[0]
                                + f"; the assembly's kernel line refitted to {len(runs)} logs in "
                                + ", ".join(sorted({os.path.dirname(r[0]) for r in runs})))
        with open(a.out, "w") as fh:
            json.dump(table, fh, indent=1)
            fh.write("\n")
        k = table["constants"]
        print(f"[calibrate] a0 = {k['a0']:.4g} s, a_blk = {k['a_blk']:.4g} s per block, a_int = {k['a_int']:.4g} s per "
              f"integrated pair-lag from {len(runs)} logs -> {a.out}")
        return
    over = [r for r in runs if r[1]["oversubscribed"]]
    runs = [r for r in runs if not r[1]["oversubscribed"]]
    for r in over:
        print(f"[calibrate] not fitted (oversubscribed: more ranks than cores): {r[0]}")
    if len(runs) < 4:
        raise SystemExit("calibrate: need at least 4 finished BEM logs (with -log_view) to fit the constants")
    c = fit(runs)
    rows = compare(runs, c)
    for r in rows:
        print(f"{r['log']:48s} p={r['ranks']} total {r['total_s']:8.2f} model {r['total_model_s']:8.2f} "
              f"({r['total_err_pct']:+.1f}%)  peak {r['peak_GB']:.3g} model {r['peak_model_GB']:.3g} GB "
              f"({r['peak_err_pct']:+.1f}%)")
    worst = {k: max(abs(r[f"{k}_err_pct"]) for r in rows) for k in ("total", "peak")}
    table = {"machine": a.machine, "cores_per_node": a.cores,
             "fitted_from": f"{len(runs)} logs in " + ", ".join(sorted({os.path.dirname(r['log']) for r in rows})),
             "max_abs_error_pct_on_fit": worst,
             "logs": [r["log"] for r in rows],
             "constants": c}
    with open(a.out, "w") as fh:
        json.dump(table, fh, indent=1)
        fh.write("\n")
    print(f"[calibrate] {len(runs)} logs -> {a.out}; largest error on these logs: total time "
          f"{worst['total']:.1f}%, peak memory {worst['peak']:.1f}%")


if __name__ == "__main__":
    main()
