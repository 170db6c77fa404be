#!/usr/bin/env python3
"""Table, CSV and plot of jobscripts/toeplitz_bench.sh from its logs (-log_view, -memory_view and the
run's own lines): per run the lag store, dofs, steps, stored GB, build and history seconds, the
history's cost per step, the wall, the peak memory over the ranks, and the run's own estimate; the
whole model's receivers against the quarter model's.

    python jobscripts/toeplitz_table.py OUTDIR README CSV PNG [SCALING_README]
    python jobscripts/toeplitz_table.py OUTDIR --print      (the tables printed, the CSV and plots into OUTDIR:
                                                           toeplitz_bench.sh with another OUT than its own)

A table's rows whose run has no log in OUTDIR are kept as they stand (``merge``: a partial rerun,
PARTS=paper, does not drop the other parts' rows). The sites (runs site-<L>, issue 41's 100 m item) get their own table (between <!-- toeplitz-site:begin/end -->
in README and SCALING_README), with `petsc-ssi estimate`'s block (site-<L>.estimate) beside each run, the
interpolation's effect on the receivers (site-<L> against site-<L>-exact), and the plot PNG with
"_site" before its extension.
"""
import csv
import glob
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from logview import parse  # noqa: E402

BEGIN, END = "<!-- toeplitz:begin -->", "<!-- toeplitz:end -->"
COLS = ["run", "store", "ranks", "dofs", "steps", "stored_GB", "kernels_s", "history_s", "history_ms_per_step",
        "total_s", "peak_GB", "sampled_peak_GB", "est_GB", "est_kernels_s", "est_history_s", "note"]


def row(log):
    text = open(log).read()
    lv = parse(text)
    name = os.path.basename(log)[:-4]
    r = {"run": name, "store": "toeplitz" if "lag store: toeplitz" in text else "dense", "ranks": lv["ranks"] or ""}
    m = re.search(r"(\d+) DOFs", text)
    r["dofs"] = int(m.group(1)) if m else ""
    m = re.search(r"dt \S+ s, (\d+) steps", text)
    r["steps"] = int(m.group(1)) if m else ""
    m = re.search(r"\(([\d.e+-]+) GB with the kept states' transforms; kernels ([\d.e+-]+) s[:)]", text)
    if m:
        r["stored_GB"], r["kernels_s"] = float(m.group(1)), float(m.group(2))
        r["kernels_h_s"], r["kernels_g_s"] = r["kernels_s"], 0.0
        g = re.search(r"G lags as \d+ kernels on the traction elements' .*?, ([\d.e+-]+) GB\)", text)
        if g:                                   # the G side's kernels and kept transforms (issue 41 G on the store)
            r["stored_GB"] = round(r["stored_GB"] + float(g.group(1)), 4)
            gs = re.search(r"G lags as \d+ kernels on the traction elements' .*?kernels ([\d.e+-]+) s", text)
            if gs:                              # kernels_s: both sides' build, as the estimate's kernels
                r["kernels_g_s"] = float(gs.group(1))
                r["kernels_s"] = round(r["kernels_s"] + r["kernels_g_s"], 3)
        # the build's parts on rank 0 (logs since 2026-12-03: 'kernels T s: integrals a s, ...'), both sides summed,
        # and the weights (the kernels' bytes written) per side: kernels_weights_h_s, kernels_weights_g_s
        for part in ("integrals", "planes", "transforms", "weights"):
            v = re.findall(rf"kernels [\d.e+-]+ s: .*?\b{part} ([\d.e+-]+) s", text)
            if v:
                r[f"kernels_{part}_s"] = round(sum(float(x) for x in v), 3)
                if part == "weights":
                    r["kernels_weights_h_s"] = float(v[0])
                    r["kernels_weights_g_s"] = float(v[1]) if len(v) > 1 else 0.0
    else:
        m = re.search(r"stored (\S+) GB", text)
        r["stored_GB"] = float(m.group(1)) if m else ""
        r["kernels_s"] = round(lv["stages"].get("SSI BEM assembly", float("nan")), 2) if lv["stages"] else ""
    ev = lv["events"]
    h = ev.get("SSI_BEM_History", (0, float("nan")))[1]
    r["history_s"] = round(h, 2)
    r["history_ms_per_step"] = round(1e3 * h / r["steps"], 2) if r["steps"] and h == h else ""
    r["total_s"] = round(lv["total_s"], 2) if lv["total_s"] else ""
    r["peak_GB"] = round(lv["peak_rss_bytes"] / 1e9, 2) if lv["peak_rss_bytes"] else ""
    m = re.search(r"toeplitz estimate: (\S+) GB over the ranks .*kernels (\S+) s, history sum (\S+) s", text)
    if m:
        r["est_GB"], r["est_kernels_s"], r["est_history_s"] = (float(m.group(i)) for i in (1, 2, 3))
    m = re.search(r"# sampled peak RSS over the ranks: (\S+) GB", text)     # (toeplitz_bench.sh's own sampling)
    r["sampled_peak_GB"] = float(m.group(1)) if m else ""
    m = re.search(r"error: (.*)", text)
    r["note"] = ("refused: " + m.group(1)[:160]) if m else ""
    m = re.search(r"# (stopped by the script: .*)", text)
    if m:
        r["note"] = m.group(1)
    return r


SITE_BEGIN, SITE_END = "<!-- toeplitz-site:begin -->", "<!-- toeplitz-site:end -->"
SITE_COLS = ["run", "dofs", "steps", "kernels", "stored_GB", "kernels_s", "history_s", "history_ms_per_step",
             "total_s", "peak_GB", "sampled_peak_GB", "est_GB", "est_history_ms_per_step", "cli_GB", "cli_history_s",
             "cli_setup_s", "note"]


def site_row(outdir, r):
    """A site run's row: its log's numbers and `petsc-ssi estimate`'s block for the same options."""
    log = open(os.path.join(outdir, r["run"] + ".log")).read()
    m = re.search(r"(\d+) history kernels K'_d in Fourier space(?: and the (\d+) interpolating)?", log)
    s = dict(r)
    s["kernels"] = (f"{m.group(1)} + {m.group(2)}" if m.group(2) else m.group(1)) if m else ""
    s["est_history_ms_per_step"] = (round(1e3 * r["est_history_s"] / r["steps"], 2)
                                    if r.get("est_history_s") not in (None, "") and r["steps"] else "")
    est = os.path.join(outdir, r["run"] + ".estimate")
    if os.path.exists(est):
        text = open(est).read()
        # (ranks | kernels_s history_s [factor_s solve_s [steps_s] total] | GB | GB with the processes |)
        m = re.search(r"\[ssi\]\s+\d+ \|\s+(\S+)\s+(\S+)(?:\s+\S+\s+\S+(?:\s+\S+)?\s+\S+)? \|\s+(\S+) \|\s+(\S+) \|",
                      text)
        if m:
            s["cli_history_s"], s["cli_GB"] = float(m.group(2)), float(m.group(4))
        m = re.search(r"model set-up took (\S+) s", text)
        s["cli_setup_s"] = float(m.group(1)) if m else ""
    return s


def site_accuracy(outdir):
    """The interpolated site runs against their exact sibling: per receiver the largest difference over
    the run relative to that receiver's peak |u|."""
    import h5py
    import numpy as np
    out = []
    for exact in sorted(glob.glob(os.path.join(outdir, "site-*-exact.h5"))):
        other = exact.replace("-exact.h5", ".h5")
        try:
            with h5py.File(exact) as a, h5py.File(other) as b:
                ua, ub, pts = a["receivers/u"][...], b["receivers/u"][...], a["receivers/points"][...]
        except (OSError, KeyError):
            continue
        for i in range(ua.shape[1]):
            err = float(np.abs(ub[:, i] - ua[:, i]).max() / np.abs(ua[:, i]).max())
            out.append(f"{os.path.basename(other)[:-3]} against {os.path.basename(exact)[:-3]}: receiver at "
                       f"({pts[i][0]:g}, {pts[i][1]:g}) m, largest difference {err:.3g} of its peak |u|")
    return out


def site_plot(rows, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    N = np.array([r["dofs"] for r in rows], float)
    t = np.array([r["history_ms_per_step"] for r in rows], float)
    est = np.array([r["est_history_ms_per_step"] if r["est_history_ms_per_step"] != "" else np.nan for r in rows])
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(N, t, "o-", label="measured (-log_view SSI_BEM_History / steps)")
    ax.loglog(N, est, "s--", label="the run's estimate (bem/toeplitz.py)")
    ax.loglog(N, t[0] * (N * np.log(N)) / (N[0] * np.log(N[0])), ":", label="N log N through the first point")
    ax.set_xlabel("soil DOFs N [-]")
    ax.set_ylabel("history sum per step [ms]")
    ax.set_title("toeplitz store, interpolated far lags: sites of 1 m elements, 0.3 s", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=120)


def sites(rows, outdir, png, paths):
    sr = sorted((r for r in rows if re.fullmatch(r"site-\d+", r["run"])), key=lambda r: r["dofs"] or 0)
    if not sr:
        return []
    sr = [site_row(outdir, r) for r in sr]
    md = ["| " + " | ".join(SITE_COLS) + " |", "|" + "---|" * len(SITE_COLS)]
    md += ["| " + " | ".join(str(r.get(c, "")) for c in SITE_COLS) + " |" for r in sr]
    acc = site_accuracy(outdir)
    if acc:
        md += [""] + ["- " + a for a in acc]
    ok = [r for r in sr if r.get("history_ms_per_step") not in ("", None)]
    if len(ok) >= 2:
        site_plot(ok, png)
    for path in paths:
        put(path, SITE_BEGIN, SITE_END, md)
    return md


def receivers_agree(outdir):
    """Largest difference of the whole model's receivers from the quarter model's, relative to their peak."""
    import h5py
    import numpy as np
    try:
        with h5py.File(os.path.join(outdir, "paper-whole-toeplitz.h5")) as a, \
                h5py.File(os.path.join(outdir, "paper-quarter-toeplitz.h5")) as b:
            ua, ub = a["receivers/u"][...], b["receivers/u"][...]
        return float(np.abs(ua - ub).max() / np.abs(ub).max())
    except (OSError, KeyError):
        return None


def _first_cell(line):
    return line.split("|")[1].strip() if line.startswith("| ") else None


def merge(old_lines, lines):
    """``lines`` (a table: header, separator, rows, then other lines) merged into ``old_lines`` (the block as
    it stands): the old rows in their order, each replaced by the new row of its run (first cell), the new
    runs' rows after them; the old table's other lines kept where the new table has no line that begins
    alike (40 characters). A rerun of some parts of the benchmark (PARTS=paper) into a directory without
    the other parts' logs keeps their rows instead of dropping them."""
    if len(lines) < 2 or len(old_lines) < 2:
        return lines
    if old_lines[0] != lines[0]:           # other columns: the old rows would shift under the new header
        dropped = [_first_cell(ln) for ln in old_lines[2:] if _first_cell(ln)]
        print(f"[toeplitz_table] the table's columns changed: its old rows are not kept ({', '.join(dropped)})")
        return lines
    new_rows = {_first_cell(ln): ln for ln in lines[2:] if _first_cell(ln)}
    old_rows = [ln for ln in old_lines[2:] if _first_cell(ln)]
    kept = [_first_cell(ln) for ln in old_rows if _first_cell(ln) not in new_rows]
    if not kept:
        return lines
    rows = [new_rows.get(_first_cell(ln), ln) for ln in old_rows]
    rows += [ln for n, ln in new_rows.items() if n not in {_first_cell(r) for r in old_rows}]
    extra = [ln for ln in lines[2:] if not _first_cell(ln)]
    heads = {ln[:40] for ln in extra if ln.strip()}
    old_extra = [ln for ln in old_lines[2:] if not _first_cell(ln) and ln.strip() and ln[:40] not in heads]
    print(f"[toeplitz_table] kept {len(kept)} row(s) without a log here: {', '.join(kept)}")
    tail = extra + ([""] if old_extra and not any(ln.strip() == "" for ln in extra) else []) + old_extra
    return lines[:2] + rows + tail


def put(path, begin, end, lines, keep=True):
    """The block begin..end of the file at ``path`` (appended when missing) set to ``lines``, merged with its
    old rows (``merge``) unless ``keep`` is False."""
    text = open(path).read()
    if begin in text and keep:
        old = text[text.index(begin) + len(begin):text.index(end)].strip("\n").split("\n")
        lines = merge(old, lines)
    block = begin + "\n" + "\n".join(lines) + "\n" + end
    if begin in text:
        text = text[:text.index(begin)] + block + text[text.index(end) + len(end):]
    else:
        text += "\n" + block + "\n"
    open(path, "w").write(text)


def scaling(rows, path):
    """The paper's whole case at 1, 2, 4 ranks: wall, kernels, history, speed-up of the history sum."""
    sc = sorted((r for r in rows if r["run"].startswith("scale-n")), key=lambda r: r["ranks"] or 0)
    if not sc:
        return
    h1 = sc[0]["history_s"]
    t1 = sc[0]["total_s"]
    lines = ["| ranks | kernels [s] | history sum [s] | history per step [ms] | history speed-up [-] | total [s] | "
             "total speed-up [-] | peak over the ranks [GB] | sampled peak [GB] |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in sc:
        sp = round(h1 / r["history_s"], 2) if r["history_s"] else ""
        st = round(t1 / r["total_s"], 2) if r["total_s"] else ""
        lines.append(f"| {r['ranks']} | {r.get('kernels_s', '')} | {r['history_s']} | {r['history_ms_per_step']} | "
                     f"{sp} | {r['total_s']} | {st} | {r['peak_GB']} | {r.get('sampled_peak_GB', '')} |")
    # (not merged: its speed-ups are against this run's first row)
    put(path, "<!-- toeplitz-scaling:begin -->", "<!-- toeplitz-scaling:end -->", lines, keep=False)


def write_csv(rows, path):
    """The rows' CSV, with the rows of the CSV already at ``path`` whose run has no new row (as ``merge``
    keeps the tables' rows), when its columns are these."""
    if not rows:
        return
    names = {r["run"] for r in rows}
    old = []
    if os.path.exists(path):
        with open(path, newline="") as f:
            rd = csv.reader(f)
            head = next(rd, [])
            if [h.split(" [")[0] for h in head] == COLS:
                old = [dict(zip(COLS, r)) for r in rd if r and r[0] not in names]
    rows = list(rows) + old
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, COLS)
        w.writerow({c: c + {"stored_GB": " [GB]", "kernels_s": " [s]", "history_s": " [s]",
                            "history_ms_per_step": " [ms]", "total_s": " [s]", "peak_GB": " [GB]",
                            "sampled_peak_GB": " [GB]", "est_GB": " [GB]", "est_kernels_s": " [s]", "est_history_s": " [s]"}.get(c, "")
                    for c in COLS})
        for r in rows:
            w.writerow({c: r.get(c, "") for c in COLS})


def main(outdir, readme, csvpath, png, scaling_readme=None):
    everything = [row(p) for p in sorted(glob.glob(os.path.join(outdir, "*.log")))]
    base, ext = os.path.splitext(png)
    site_md = sites(everything, outdir, base + "_site" + ext, [p for p in (readme, scaling_readme) if p])
    write_csv([r for r in everything if r["run"].startswith("site-")], os.path.splitext(csvpath)[0] + "_site.csv")
    rows = [r for r in everything if not r["run"].startswith("site-")]
    print("\n".join(site_md))
    if not rows:                # (PARTS=site: the other tables stay as they are)
        return
    if scaling_readme:
        scaling(rows, scaling_readme)
    if all(r["run"].startswith("scale-") for r in rows):     # (PARTS=scale: only the scaling table is new)
        return
    write_csv(rows, csvpath)
    agree = receivers_agree(outdir)
    md = ["| " + " | ".join(COLS) + " |", "|" + "---|" * len(COLS)]
    md += ["| " + " | ".join(str(r.get(c, "")) for c in COLS) + " |" for r in rows]
    if agree is not None:
        md.append("")
        md.append(f"Whole model's receivers against the quarter model's (toeplitz both): largest difference "
                  f"{agree:.3g} of their peak.")
    grid = [r for r in rows if r["run"].startswith("grid-") and r.get("history_ms_per_step") not in ("", None)]
    if grid:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np
        N = np.array([r["dofs"] for r in grid], float)
        t = np.array([r["history_ms_per_step"] for r in grid], float)
        est = np.array([1e3 * r.get("est_history_s", np.nan) / r["steps"] for r in grid], float)
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.loglog(N, t, "o-", label="measured (-log_view SSI_BEM_History / steps)")
        ax.loglog(N, est, "s--", label="run's estimate (bem/toeplitz.py)")
        ref = t[0] * (N * np.log(N)) / (N[0] * np.log(N[0]))
        ax.loglog(N, ref, ":", label="N log N through the first point")
        ax.set_xlabel("soil DOFs N [-]")
        ax.set_ylabel("history sum per step [ms]")
        ax.set_title("toeplitz lag store: cost per step (whole grids, 1 m elements)")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(png, dpi=120)
    if readme:
        put(readme, BEGIN, END, md)
    print("\n".join(md))


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[2] == "--print":
        main(sys.argv[1], None, os.path.join(sys.argv[1], "toeplitz_bench.csv"),
             os.path.join(sys.argv[1], "toeplitz_cost_per_step.png"))
    else:
        main(*sys.argv[1:6])
