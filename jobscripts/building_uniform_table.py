#!/usr/bin/env python3
"""Tables of jobscripts/building_uniform.sh (issue 41's building item) from its runs' logs (-log_view,
-memory_view, the run's own lines), JSON records and receivers:

- cost: per run the soil mesh, lag store, soil DOFs, steps, the run's wall (JSON), the -log_view stages
  (set-up, FEM assembly, BEM assembly, time loop) and events (the toeplitz kernels' build, the history
  sum, the step solves), the peak resident memory over the ranks (-memory_view, and the script's sampling)
  and the run's own estimate;
- receivers: for pairs of runs, per receiver and component, the relative difference of the peak values,
  (max|a| - max|b|) / max|b|, and the largest difference of the histories over b's peak, max|a - b| / max|b|
  (structure: accelerations and displacements x, z at A (roof centre) and B (foundation centre); soil:
  displacements x, z at the soil receivers on y = 0), with the first time at which |a - b| exceeds 1 % of
  b's peak (when an edge's reflection or the other mesh's waves first show).

    python jobscripts/building_uniform_table.py OUTDIR [README ... | --print]

README defaults to runs/building/README.md and jobscripts/README.md; the blocks between
<!-- building-uniform-cost:begin/end --> and <!-- building-uniform-receivers:begin/end --> are replaced.
CSVs: runs/building/building_uniform_cost.csv, runs/building/building_uniform_receivers.csv (every
quantity of every pair). ``--print``: the tables on stdout only (building_uniform.sh with another OUT).
"""
import csv
import json
import os
import re
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from logview import parse  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
MESH = {"today": "graded 36 x 36 m (building_soil.geo), 1 m load at x = 14.5",
        "today-load15": "graded 36 x 36 m (building_soil.geo), 1.2 m load at x = 15",
        "uniform-36": "uniform 36 x 37.2 m, 1.2 m cells, 1.2 m load at x = 15",
        "uniform-72": "uniform 72 x 73.2 m, 1.2 m cells, 1.2 m load at x = 15",
        "today-exact": "as today, every lag exact (-ssi_interp none)",
        "today-fine": "graded 36 x 36 m refined (cells <= 1.5 m), 1 m load at x = 14.5, every lag exact",
        "today-smooth": "as today-exact, a 0.1 s Hann pulse instead of the 25 ms box",
        "today-fine-smooth": "as today-fine, a 0.1 s Hann pulse",
        "uniform-36-smooth": "as uniform-36-area-exact, a 0.1 s Hann pulse",
        "uniform-72-smooth": "as uniform-72-area-exact, a 0.1 s Hann pulse",
        "uniform-108-smooth": "uniform 108 x 109.2 m, 1.2 m cells, today's load as an area, every lag exact, "
                              "a 0.1 s Hann pulse",
        "uniform-72-area-rule": "as uniform-72-area, far lags by the paper's rule (T_L = 0.3675 s, k = 27)",
        "today-smooth-dt2": "as today-smooth, dt 2.5 ms",
        "uniform-36-smooth-dt2": "as uniform-36-smooth, dt 2.5 ms",
        "today-load15-smooth": "as today-load15, every lag exact, a 0.1 s Hann pulse",
        "uniform-36-load15-smooth": "as uniform-36, every lag exact, a 0.1 s Hann pulse",
        "uniform-72-area": "uniform 72 x 73.2 m, 1.2 m cells, today's 1 m load at x = 14.5 as an area",
        "uniform-72-area-exact": "as uniform-72-area, every lag exact (-ssi_interp none)",
        "uniform-36-area-exact": "uniform 36 x 37.2 m, 1.2 m cells, today's load as an area, every lag exact",
        "uniform-72-fullrank": "as uniform-72, the step matrix's LU in full rank (-ssi_step_blr 0)",
        "uniform-72-fast": "as uniform-72, multi-linear far lags, single-precision transforms",
        "uniform-72-blr": "as uniform-72, the step matrix's MUMPS LU block low-rank (ICNTL(35) 2, CNTL(7) {eps})",
        "check-dense": "uniform 36 x 37.2 m, 6 steps", "check-toeplitz": "uniform 36 x 37.2 m, 6 steps"}
PAIRS = [("uniform-72-area-exact", "today-exact", "uniform 72 m vs today, the same load, every lag exact both"),
         ("uniform-72-area", "today", "uniform 72 m vs today, the same load, far lags interpolated as today"),
         ("today-fine", "today-exact", "today's graded mesh refined (cells <= 1.5 m) vs today, every lag exact both"),
         ("uniform-72-smooth", "today-smooth", "a 0.1 s Hann pulse: uniform 72 m vs today, every lag exact both"),
         ("uniform-36-smooth", "today-smooth", "a 0.1 s Hann pulse: uniform 1.2 m cells vs graded, the same extent"),
         ("uniform-72-smooth", "uniform-36-smooth", "a 0.1 s Hann pulse: extent 72 m vs 36 m (edge reflections)"),
         ("uniform-108-smooth", "uniform-72-smooth", "a 0.1 s Hann pulse: extent 108 m vs 72 m (edge reflections)"),
         ("uniform-108-smooth", "today-smooth", "a 0.1 s Hann pulse: uniform 108 m vs today, every lag exact both"),
         ("today-fine-smooth", "today-smooth", "a 0.1 s Hann pulse: today's graded mesh refined vs today"),
         ("today-smooth-dt2", "today-smooth", "a 0.1 s Hann pulse: today, dt 2.5 ms vs 5 ms"),
         ("uniform-36-smooth-dt2", "uniform-36-smooth", "a 0.1 s Hann pulse: uniform 36 m, dt 2.5 ms vs 5 ms"),
         ("uniform-36-smooth-dt2", "today-smooth-dt2", "a 0.1 s Hann pulse, dt 2.5 ms: uniform 1.2 m cells vs graded, "
          "the same extent"),
         ("uniform-36-load15-smooth", "today-load15-smooth", "a 0.1 s Hann pulse on the 1.2 m cell at x = 15 m (held by a "
          "cell on both): uniform 1.2 m cells vs graded, the same extent"),
         ("today", "today-exact", "today: its interpolated far lags vs every lag exact (graded 36 m)"),
         ("uniform-72-area", "uniform-72-area-exact", "uniform 72 m: interpolated far lags vs every lag exact"),
         ("uniform-72-area-rule", "uniform-72-area-exact", "uniform 72 m: the paper's rule (T_L = 0.3675 s, k = 27) vs "
          "every lag exact"),
         ("uniform-36-area-exact", "today-exact", "uniform 1.2 m cells vs graded, the same extent and load, exact lags"),
         ("uniform-72-area-exact", "uniform-36-area-exact", "extent 72 m vs 36 m (edge reflections), exact lags"),
         ("uniform-72", "today", "uniform 72 m (toeplitz) vs today"),
         ("today-load15", "today", "load: 1.2 m cell at x = 15 vs 1 m patch at 14.5 (graded mesh both)"),
         ("uniform-36", "today-load15", "uniform 1.2 m cells vs graded, same extent and load"),
         ("uniform-72", "uniform-36", "extent 72 m vs 36 m (edge reflections), uniform both"),
         ("uniform-72", "today-load15", "uniform 72 m vs graded 36 m, same load"),
         ("uniform-72-fast", "uniform-72", "multi-linear far lags, single transforms vs Chebyshev, double"),
         ("uniform-72-blr", "uniform-72", "block low-rank LU ({eps}) vs the run's default (1e-15) of the step matrix"),
         ("uniform-72", "uniform-72-fullrank", "the step matrix's LU block low-rank at 1e-15 (auto) vs full rank")]


def blr_eps(outdir):
    """The BLR run's dropping threshold, from its log's options (building_uniform.sh BLR_EPS)."""
    path = os.path.join(outdir, "uniform-72-blr.log")
    m = re.search(r"-ssi_bem_mat_mumps_cntl_7 (\S+)", open(path, errors="replace").read()) if os.path.exists(path) else None
    return m.group(1) if m else "?"


def cost_row(outdir, name):
    log = os.path.join(outdir, name + ".log")
    text = open(log, errors="replace").read()
    lv = parse(text)
    r = {"run": name, "soil mesh": MESH.get(name, name).replace("{eps}", blr_eps(outdir)),
         "store": "toeplitz" if "lag store: toeplitz" in text else "dense"}
    m = re.search(r"(\d+) DOFs", text)
    r["soil DOFs"] = int(m.group(1)) if m else ""
    m = re.search(r"dt \S+ s, (\d+) steps", text)
    r["steps"] = int(m.group(1)) if m else ""
    js = os.path.join(outdir, name + ".json")
    if os.path.exists(js):
        st = json.load(open(js)).get("stats", {})
        r["run wall [s]"] = round(st.get("wall_s", float("nan")), 1)
    r["-log_view total [s]"] = round(lv["total_s"], 1) if lv["total_s"] else ""
    st = lv["stages"]
    for key, col in (("SSI setup", "set-up [s]"), ("SSI FEM assembly", "FEM assembly [s]"),
                     ("SSI BEM assembly", "BEM assembly [s]"), ("SSI time loop", "time loop [s]")):
        r[col] = round(st[key], 1) if key in st else ""
    ev = lv["events"]
    for key, col in (("SSI_BEM_Toeplitz", "toeplitz kernels [s]"), ("SSI_BEM_History", "history sum [s]")):
        r[col] = round(ev[key][1], 1) if key in ev else ""
    r["peak over the ranks [GB]"] = round(lv["peak_rss_bytes"] / 1e9, 2) if lv["peak_rss_bytes"] else ""
    m = re.search(r"# sampled peak RSS over the ranks: (\S+) GB", text)
    r["sampled peak [GB]"] = float(m.group(1)) if m else ""
    m = re.search(r"toeplitz estimate: (\S+) GB over the ranks", text)
    r["toeplitz estimate [GB]"] = float(m.group(1)) if m else ""
    m = re.search(r"error: (.*)", text)
    r["note"] = m.group(1)[:160] if m else ""
    return r


def receivers(outdir, name):
    """{quantity: (t, history)} of a run: structure A, B (a, u; x, z) and the soil receivers (u; x, z)."""
    out = {}
    p = os.path.join(outdir, name + ".h5")
    with h5py.File(p[:-3] + "_structure.h5", "r") as f:
        r = f["receivers"]
        t, u, a, pts = r["t"][:], r["u"][:], r["acceleration"][:], r["points"][:]
    for i, lab in enumerate("AB"):
        for c, cn in ((0, "x"), (2, "z")):
            out[f"{lab} a_{cn}"] = (t, a[:, i, c])
            out[f"{lab} u_{cn}"] = (t, u[:, i, c])
    with h5py.File(p, "r") as f:
        r = f["receivers"]
        t, u, pts = r["t"][:], r["u"][:], r["points"][:]
    for i in range(u.shape[1]):
        for c, cn in ((0, "x"), (2, "z")):
            out[f"soil x = {pts[i][0]:g} m u_{cn}"] = (t, u[:, i, c])
    return out


def compare(ra, rb):
    rows = []
    for q in rb:
        if q not in ra:
            continue
        (ta, a), (tb, b) = ra[q], rb[q]
        end = min(ta[-1], tb[-1]) + 1e-9            # (peaks: each run's own samples over the common span)
        pa, pb = float(np.abs(a[ta <= end]).max()), float(np.abs(b[tb <= end]).max()) or 1e-300
        # histories at the times both runs sampled (runs of another dt: every other sample of the finer one)
        ia = np.searchsorted(ta, tb)
        ok = (ia < len(ta)) & (tb <= end)
        ok[ok] = np.abs(ta[ia[ok]] - tb[ok]) <= 1e-9 * max(1.0, float(tb[-1]))
        a, b, t = a[ia[ok]], b[ok], tb[ok]
        d = np.abs(a - b)
        over = np.nonzero(d > 0.01 * pb)[0]
        rows.append({"quantity": q, "peak diff [%]": 100 * (pa - pb) / pb,
                     "history diff [%]": 100 * float(d.max()) / pb,
                     "first t with diff > 1 % of peak [s]": float(t[over[0]]) if len(over) else float("nan")})
    return rows


def fmt(v):
    if isinstance(v, float):
        return "-" if not np.isfinite(v) else f"{v:.3g}"
    return str(v)


def md(rows, cols):
    s = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    s += ["| " + " | ".join(fmt(r.get(c, "")) for c in cols) + " |" for r in rows]
    return s


def put(path, tag, lines):
    begin, end = f"<!-- {tag}:begin -->", f"<!-- {tag}:end -->"
    text = open(path).read()
    if begin not in text:
        return
    text = text[:text.index(begin) + len(begin)] + "\n" + "\n".join(lines) + "\n" + text[text.index(end):]
    open(path, "w").write(text)


def main(outdir, *readmes):
    if readmes == ("--print",):          # (another OUT: the tables on stdout only, the READMEs and CSVs untouched)
        readmes, csvs = (), False
    else:
        csvs = True
    readmes = readmes if readmes or not csvs else (os.path.join(ROOT, "runs/building/README.md"),
                                                    os.path.join(HERE, "README.md"))
    names = [n for n in MESH if os.path.exists(os.path.join(outdir, n + ".log"))]
    cost = [cost_row(outdir, n) for n in names if not n.startswith("check-")]   # (the check: not a timing)
    ccols = ["run", "soil mesh", "store", "soil DOFs", "steps", "run wall [s]", "set-up [s]", "BEM assembly [s]",
             "toeplitz kernels [s]", "time loop [s]", "history sum [s]", "peak over the ranks [GB]",
             "sampled peak [GB]", "toeplitz estimate [GB]"]
    cost_md = md(cost, ccols)
    if csvs:
        with open(os.path.join(ROOT, "runs/building/building_uniform_cost.csv"), "w", newline="") as fh:
            w = csv.DictWriter(fh, list(cost[0]) if cost else ccols)
            w.writeheader()
            w.writerows(cost)
    rec = {}
    for n in names:
        try:
            rec[n] = receivers(outdir, n)
        except (OSError, KeyError):
            pass
    summary, detail = [], []
    for a, b, what in PAIRS:
        if a not in rec or b not in rec:
            continue
        what = what.replace("{eps}", blr_eps(outdir))
        rows = compare(rec[a], rec[b])
        for r in rows:
            detail.append(dict(pair=f"{a} vs {b}", **r))
        st = [r for r in rows if not r["quantity"].startswith("soil")]
        so = [r for r in rows if r["quantity"].startswith("soil")]
        big = lambda rs, k: max((abs(r[k]) for r in rs), default=float("nan"))      # noqa: E731
        worst = lambda rs: max(rs, key=lambda r: r["history diff [%]"])["quantity"] if rs else ""  # noqa: E731
        summary.append({"comparison": what, "a vs b": f"{a} vs {b}",
                        "structure: largest peak diff [%]": big(st, "peak diff [%]"),
                        "structure: largest history diff [%]": big(st, "history diff [%]"),
                        "soil: largest peak diff [%]": big(so, "peak diff [%]"),
                        "soil: largest history diff [%]": big(so, "history diff [%]"),
                        "largest history diff at": worst(rows)})
    scols = ["comparison", "a vs b", "structure: largest peak diff [%]", "structure: largest history diff [%]",
             "soil: largest peak diff [%]", "soil: largest history diff [%]", "largest history diff at"]
    rec_md = md(summary, scols)
    if detail:
        if csvs:
            with open(os.path.join(ROOT, "runs/building/building_uniform_receivers.csv"), "w", newline="") as fh:
                w = csv.DictWriter(fh, list(detail[0]))
                w.writeheader()
                w.writerows(detail)
        # the per-receiver detail of the pairs: one column pair per comparison
        pairs = list(dict.fromkeys(d["pair"] for d in detail))
        qs = list(dict.fromkeys(d["quantity"] for d in detail))
        cols = ["quantity"] + [f"{p}: {k}" for p in pairs for k in ("peak [%]", "history [%]")]
        rows = []
        for q in qs:
            r = {"quantity": q}
            for d in detail:
                if d["quantity"] == q:
                    r[f"{d['pair']}: peak [%]"] = d["peak diff [%]"]
                    r[f"{d['pair']}: history [%]"] = d["history diff [%]"]
            rows.append(r)
        rec_md += ["", "Per receiver (peak: (max|a| - max|b|) / max|b|; history: max|a - b| / max|b|; in %):", ""]
        rec_md += md(rows, cols)
        rec_md += ["", "First time at which |a - b| exceeds 1 % of b's peak [s]:", ""]
        cols = ["quantity"] + pairs
        rows = []
        for q in qs:
            r = {"quantity": q}
            for d in detail:
                if d["quantity"] == q:
                    r[d["pair"]] = d["first t with diff > 1 % of peak [s]"]
            rows.append(r)
        rec_md += md(rows, cols)
    if "check-dense" in rec and "check-toeplitz" in rec:       # exactness: over the largest value of each kind
        a, b = rec["check-toeplitz"], rec["check-dense"]
        kinds = {}
        for q in b:
            k = ("soil " if q.startswith("soil") else "structure ") + q.split()[-1].split("_")[0]
            kinds.setdefault(k, []).append(q)
        per = {k: max(float(np.abs(a[q][1] - b[q][1]).max()) for q in qs) /
               max(float(np.abs(b[q][1]).max()) for q in qs) for k, qs in kinds.items()}
        worst = max(per.values())
        rec_md += ["", f"Exactness on this case (`RUNS=check`: uniform-36's first {len(b[next(iter(b))][1]) - 1} "
                   f"steps, toeplitz against dense lag matrices, 2 ranks): largest difference of any receiver "
                   f"series over the largest value of its kind (structure displacements, structure accelerations, "
                   f"soil displacements, every component) {worst:.3g} ("
                   + ", ".join(f"{k} {v:.2g}" for k, v in per.items()) + ")."]
    for path in readmes:
        put(path, "building-uniform-cost", cost_md)
        put(path, "building-uniform-receivers", rec_md)
    print("\n".join(cost_md + [""] + rec_md))


if __name__ == "__main__":
    main(*sys.argv[1:])
