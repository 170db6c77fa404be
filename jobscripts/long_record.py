#!/usr/bin/env python3
"""The long-record benchmark's tables (jobscripts/long_record.sh; issue 28): per rank count the
stages from -log_view (set-up, FEM assembly, BEM assembly and interface matrices, time loop and its
parts, output), the peak resident memory (-memory_view: the largest rank and the sum), the
estimate of `petsc-ssi estimate` beside each with its error, and the per-step wall time (the
run's timing/step_wall) as a PNG: whether the cost per step stays flat over the record.

    python jobscripts/long_record.py out/bench/long_record     (prints the table, writes
        jobscripts/results/long_record.csv and long_record_steps.png, and the README block)
"""
import glob
import os
import re
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from logview import parse, write_csv, put_block  # noqa: E402


def _seconds(text):
    """fmt_time's text ('27.3s', '1m57s', '2h03m') in seconds."""
    m = re.fullmatch(r"(?:(\d+)h)?(?:(\d+)m)?(?:([\d.]+)s)?", text.strip())
    if not m or not any(m.groups()):
        raise ValueError(text)
    h, mi, s = (float(g) if g else 0.0 for g in m.groups())
    return 3600 * h + 60 * mi + s


def estimate_rows(path):
    """{ranks: {'total_s', 'peak_GB', 'assembly_s', 'loop_s', ...}} from the estimate's table."""
    rows, head = {}, None
    for line in open(path):
        if "ranks nodes |" in line:
            head = line.split("|")[1].split()
            continue
        if head is None or not re.match(r"\[ssi\]\s+\d+\s+\d+\s+\|", line):
            continue
        parts = line.split("|")
        p = int(parts[0].split()[1])
        vals = dict(zip(head, (float(v) for v in parts[1].split())))
        mem = parts[3].split()
        rows[p] = {"total_s": _seconds(parts[2]), "peak_GB": float(mem[0]), **vals}
    return rows


def run_row(d, n):
    base = os.path.join(d, f"paper-building-n{n}")
    text = open(base + ".log_view").read() + "\n" + open(base + ".log").read()
    lv = parse(text)
    st, ev = lv["stages"], lv["events"]
    get = lambda name: ev.get(name, (0, 0.0))[1]
    row = {"ranks": n, "wall_s": lv["total_s"], "setup_s": st.get("SSI setup", 0.0),
           "fem_assembly_s": st.get("SSI FEM assembly", 0.0), "bem_assembly_and_interface_s": st.get("SSI BEM assembly", 0.0),
           "bem_lags_s": get("SSI_BEM_Assembly"), "interface_matrices_s": get("SSI_Capacitance"),
           "time_loop_s": st.get("SSI time loop", 0.0), "history_s": get("SSI_BEM_History"),
           "bem_solve_s": get("SSI_BEM_Solve"), "fem_step_s": get("SSI_FEM_Step"), "contact_s": get("SSI_Contact"),
           "output_s": get("SSI_IO"), "peak_rss_sum_GB": (lv["peak_rss_bytes"] or np.nan) / 1e9,
           "peak_rss_max_rank_GB": (lv.get("peak_rss_max_rank_bytes") or np.nan) / 1e9}
    with h5py.File(base + ".h5", "r") as f:
        w = f["timing/step_wall"][()]
        row["steps"] = len(w)
        row["output_MB"] = os.path.getsize(base + ".h5") / 1e6 + sum(
            os.path.getsize(p) / 1e6 for p in glob.glob(base + "_structure.h5"))
    k = max(len(w) // 10, 1)
    row["step_first_tenth_ms"] = 1e3 * float(np.nanmean(w[:k]))
    row["step_last_tenth_ms"] = 1e3 * float(np.nanmean(w[-k:]))
    return row, w


def main(d):
    est = estimate_rows(os.path.join(d, "estimate.log"))
    rows, walls = [], {}
    for path in sorted(glob.glob(os.path.join(d, "paper-building-n*.log_view"))):
        n = int(re.search(r"-n(\d+)\.log_view$", path).group(1))
        row, w = run_row(d, n)
        e = est.get(n)
        if e:
            row["estimate_total_s"] = e["total_s"]
            row["estimate_error_total_pct"] = 100.0 * (e["total_s"] / row["wall_s"] - 1.0)
            row["estimate_peak_GB"] = e["peak_GB"]
            row["estimate_error_peak_pct"] = 100.0 * (e["peak_GB"] / row["peak_rss_sum_GB"] - 1.0)
            row["estimate_loop_s"] = e.get("time_loop_s", np.nan)
            row["estimate_assembly_s"] = e.get("assembly_s", np.nan)
        rows.append(row)
        walls[n] = w
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    write_csv(os.path.join(HERE, "results", "long_record.csv"), rows)
    lines = ["| ranks | steps | wall [s] | set-up [s] | BEM lags [s] | interface matrices [s] | time loop [s] "
             "(history / BEM solve / FEM / contact / output) | step, first / last tenth [ms] | peak memory, largest "
             "rank / all ranks [GB] | output [MB] | estimate: wall [s] (error) | estimate: memory [GB] (error) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        est_t = (f"{r['estimate_total_s']:.0f} ({r['estimate_error_total_pct']:+.0f} %)"
                 if "estimate_total_s" in r else "-")
        est_m = (f"{r['estimate_peak_GB']:.2f} ({r['estimate_error_peak_pct']:+.0f} %)"
                 if "estimate_peak_GB" in r else "-")
        lines.append(f"| {r['ranks']} | {r['steps']} | {r['wall_s']:.0f} | {r['setup_s']:.1f} | {r['bem_lags_s']:.1f} | "
                     f"{r['interface_matrices_s']:.1f} | {r['time_loop_s']:.0f} ({r['history_s']:.0f} / "
                     f"{r['bem_solve_s']:.1f} / {r['fem_step_s']:.1f} / {r['contact_s']:.1f} / {r['output_s']:.1f}) | "
                     f"{r['step_first_tenth_ms']:.0f} / {r['step_last_tenth_ms']:.0f} | {r['peak_rss_max_rank_GB']:.2f} / "
                     f"{r['peak_rss_sum_GB']:.2f} | {r['output_MB']:.1f} | {est_t} | {est_m} |")
    block = "\n".join(lines)
    print(block)
    put_block("long-record", block, [os.path.join(HERE, "README.md")])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4))
    for n, w in sorted(walls.items()):
        m = 240 if len(w) > 2400 else 24                # a running mean over whole history blocks (24 steps)
        wm = np.convolve(np.nan_to_num(w, nan=np.nanmedian(w)), np.ones(m) / m, mode="valid")
        k = np.arange(len(wm)) + (m + 1) / 2.0          # the centre step of each window
        ax.plot(k, 1e3 * wm, label=f"{n} rank{'s' if n > 1 else ''} (mean of {m} steps)")
    ax.set_xlabel("step [-] (dt = 5 ms)")
    ax.set_ylabel("wall time per step [ms]")
    ax.set_title("the paper's building under 30 s of record: cost per step")
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "results", "long_record_steps.png"), dpi=120)
    return rows


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/bench/long_record")
