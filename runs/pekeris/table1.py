#!/usr/bin/env python3
"""Reproduce the paper's Table 1: interpolated BEM error and savings.

For r = 5 m and 15 m and tau_L = c_s T_L / r = 0.5, 1, 1.5, with the paper's
k (r = 5 m: 18, 17, 15; r = 15 m: 15, 10, 6), multi-linear (ML, grading 1) and
Chebyshev-Lagrange (CL) interpolation, on the paper's case (paper.opts, run to
tau = 2.5 at r = 15 m). Each run is made here with -log_view -memory_view:

  error (%)        relative L2 error over the whole run (to tau = 2.5 at
                   r = 15 m, i.e. tau = 7.5 at r = 5 m) of the vertical (z)
                   and horizontal (radial, x) displacement at the column's
                   receiver, interpolated vs non-interpolated run; and the
                   same over tau <= 2.5 at that receiver (the paper's plots)
  saved CPU (%)    1 - total time / total time of the non-interpolated run
                   (-log_view "Time (sec)", all stages)
  peak error (%)   |max |u_i| - max |u_e|| / max |u_e| over tau <= 2.5 at the
                   column's receiver (the paper discusses the "maximum response")
  The paper does not define its error (Section 2.1 and Table 1 say only
  "error"); the three measures are given side by side.
  k5 rows          the tau_L = 1.5 columns again with k set by the paper's
                   words, "one exact matrix every 5 steps", over this run's
                   interpolation interval [T_L, T_N] (T_N = last lag time of
                   the run, 0.118 s): k = ceil((T_N - T_L) / (5 dt)), the rule
                   of -ssi_interp auto. The paper's k put its nodes 5 steps
                   apart only if its T_N was 0.072-0.094 s (k - 1 = (T_N - T_L)
                   / (5 dt)); over our interval the same k puts them 7-9 steps
                   apart.
  paper_T_N_implied_s  T_L + 5 dt (k - 1) with the paper's k: the end of the
                   paper's interpolation interval if its nodes were 5 steps apart
  All runs store every lag block-sparse (-ssi_lag_storage sparse; the exact
  run of this case must, to fit in 24 GB), so the savings compare like with like.
  saved memory (%) 1 - stored lag-matrix bytes / those of the non-interpolated
                   run (PETSc MatGetInfo, from the run's JSON record); the peak
                   process memory (-memory_view) is in the CSV too

Usage: python runs/pekeris/table1.py [--ranks N] [--out DIR]
Writes runs/pekeris/table1.csv and the table between <!-- table1:begin/end -->
in runs/pekeris/README.md. Runs whose log exists are not repeated.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys

import numpy as np

from petsc_ssi.launch import child_env

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "jobscripts"))
from logview import parse  # noqa: E402

CS = 316.0
DT = 7.5e-4
T_END = 0.1187          # paper.opts
PAPER = {  # (method, r, tau_L): (k, vertical %, horizontal %, saved CPU %, saved memory %)
    ("ML", 5, 0.5): (18, 72.5, 73.4, 80, 76), ("ML", 5, 1.0): (17, 8.1, 9.4, 76, 71),
    ("ML", 5, 1.5): (15, 1.3, 0.8, 71, 65), ("ML", 15, 0.5): (15, 85.5, 83.8, 71, 65),
    ("ML", 15, 1.0): (10, 71.0, 68.5, 54, 53), ("ML", 15, 1.5): (6, 0.4, 0.2, 15, 19),
    ("CL", 5, 0.5): (18, 55.3, 59.6, 79, 76), ("CL", 5, 1.0): (17, 47.2, 47.3, 75, 72),
    ("CL", 5, 1.5): (15, 0.6, 0.8, 71, 62), ("CL", 15, 0.5): (15, 58.4, 59.3, 71, 65),
    ("CL", 15, 1.0): (10, 15.2, 16.7, 54, 62), ("CL", 15, 1.5): (6, 0.7, 0.6, 15, 17),
}


def run(name, extra, out, ranks):
    log = os.path.join(out, name + ".log")
    h5 = os.path.join(out, name + ".h5")
    if not os.path.exists(log) or "petsc-ssi: error" in open(log).read() or "done in" not in open(log).read():
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(ranks), sys.executable, "-m",
               "petsc_ssi", "-options_file", os.path.join(HERE, "paper.opts"), "-ssi_output", h5, "-ssi_output_overwrite",
               "-ssi_output_stride", "0", "-ssi_lag_storage", "sparse", "-log_view", "-memory_view"] + extra
        print("[table1]", " ".join(cmd), flush=True)
        with open(log, "w") as fh:
            subprocess.run(cmd, stdout=fh, stderr=subprocess.STDOUT, cwd=ROOT, check=True, env=child_env())
    lv = parse(open(log).read())
    rec = json.load(open(h5[:-3] + ".json"))
    import h5py
    with h5py.File(h5, "r") as f:
        u = f["receivers/u"][:]
    st = rec["stats"]
    return {"time": lv["total_s"], "peak": lv["peak_rss_bytes"],
            "lag_bytes": st["lag_bytes"], "u": u}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ranks", type=int, default=1)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "table1"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    ref = run("exact", [], a.out, a.ranks)
    n_steps = int(math.ceil(T_END / DT - 1e-9))
    TN = n_steps * DT                      # last lag time of the run: lag L = n_steps + 1
    rows = []
    cases = [(key, val[0], "paper's k") for key, val in PAPER.items()]
    cases += [(key, int(math.ceil((TN - key[2] * key[1] / CS) / (5 * DT))), "k5") for key in PAPER if key[2] == 1.5]
    for (meth, r, tl), k, kind in cases:
        pv, ph, pc, pm = PAPER[(meth, r, tl)][1:]
        T_L = tl * r / CS
        m = {"ML": "linear", "CL": "chebyshev"}[meth]
        name = f"{meth}-r{r}-tau{tl}" + ("" if kind == "paper's k" else f"-k{k}")
        res = run(name, ["-ssi_interp", m, "-ssi_interp_tl", repr(T_L), "-ssi_interp_k", str(k)], a.out, a.ranks)
        rec = 0 if r == 5 else 1
        win = slice(0, int(2.5 * r / CS / DT) + 1)          # tau = c_s t / r <= 2.5, the paper's plots
        ui, ue = res["u"][:, rec, :], ref["u"][:, rec, :]
        err = lambda c, m=slice(None): 100 * np.linalg.norm(ui[m, c] - ue[m, c]) / np.linalg.norm(ue[m, c])
        peak = lambda c: 100 * abs(np.abs(ui[win, c]).max() - np.abs(ue[win, c]).max()) / np.abs(ue[win, c]).max()
        rows.append({"method": meth, "r_m": r, "tau_L": tl, "T_L_s": round(T_L, 5), "T_N_s": round(TN, 5), "k": k,
                     "k_rule": kind, "node_spacing_steps": round((TN - T_L) / max(k - 1, 1) / DT, 1),
                     "err_vertical_pct": round(err(2), 2), "err_horizontal_pct": round(err(0), 2),
                     "err_vertical_tau25_pct": round(err(2, win), 2),
                     "err_horizontal_tau25_pct": round(err(0, win), 2),
                     "peak_err_vertical_tau25_pct": round(peak(2), 2),
                     "peak_err_horizontal_tau25_pct": round(peak(0), 2),
                     "saved_cpu_pct": round(100 * (1 - res["time"] / ref["time"]), 1),
                     "saved_lag_memory_pct": round(100 * (1 - res["lag_bytes"] / ref["lag_bytes"]), 1),
                     "saved_peak_memory_pct": round(100 * (1 - res["peak"] / ref["peak"]), 1)
                     if res["peak"] and ref["peak"] else "",
                     "paper_err_vertical_pct": pv, "paper_err_horizontal_pct": ph,
                     "paper_T_N_implied_s": round(T_L + 5 * DT * (PAPER[(meth, r, tl)][0] - 1), 4),
                     "paper_saved_cpu_pct": pc, "paper_saved_memory_pct": pm})
        write(rows, ref, a.ranks)       # after every run: partial results survive


def _cmp(ours, paper):
    """'below' / 'above' per component (vertical, horizontal)."""
    return " and ".join(f"{c} {'at or below' if o <= p else 'above'}" for c, o, p in
                        zip(("vertical", "horizontal"), ours, paper))


def sentence(x, rows):
    """One line per row: where ours and the paper's differ, and why (from this run's numbers)."""
    ours = (x["err_vertical_tau25_pct"], x["err_horizontal_tau25_pct"])
    paper = (x["paper_err_vertical_pct"], x["paper_err_horizontal_pct"])
    peak = (x["peak_err_vertical_tau25_pct"], x["peak_err_horizontal_tau25_pct"])
    head = (f"{x['method']}, r = {x['r_m']} m, tau_L = {x['tau_L']}, k = {x['k']} ({x['k_rule']}, nodes "
            f"{x['node_spacing_steps']} steps apart): L2 over tau <= 2.5 {ours[0]} / {ours[1]} % against the "
            f"paper's {paper[0]} / {paper[1]} % ({_cmp(ours, paper)}). ")
    if x["tau_L"] < 1.08:
        return head + ("T_L lies before the Rayleigh arrival (tau = 1.09), inside the pulse the lag matrices carry, "
                       "and the interpolant misses it (runs/pekeris/matrix_history.py): the error is set by where the "
                       f"nodes fall on that pulse, and ours fall elsewhere (our interval runs to T_N = {x['T_N_s']} s, "
                       f"the paper's k imply {x['paper_T_N_implied_s']} s), so the two agree in kind (large), not in "
                       "value.")
    if x["k_rule"] == "k5":
        pk = (f"The peak error is {peak[0]} / {peak[1]} %" + (": zero where the peak comes before T_L (the "
              "interpolation changes nothing before T_L); the paper's peak lies between the S and Rayleigh arrivals "
              "(its Section 2.1), before tau_L = 1.5, so its non-zero errors are not a peak measure" if 0.0 in peak else "") + ". ")
        return head + pk + ("What remains is not the spacing: the paper defines neither its "
                       f"error measure nor its T_N (its k imply T_N = {x['paper_T_N_implied_s']} s for this column, "
                       f"ours is {x['T_N_s']} s), and the whole-run error here ({x['err_vertical_pct']} / "
                       f"{x['err_horizontal_pct']} %) shows how much the measure's window alone changes.")
    k5 = [y for y in rows if y["k_rule"] == "k5" and (y["method"], y["r_m"], y["tau_L"]) ==
          (x["method"], x["r_m"], x["tau_L"])]
    why = (f"With the paper's k our nodes are {x['node_spacing_steps']} steps apart, not the paper's 5, because our "
           f"interval runs to T_N = {x['T_N_s']} s (the paper's k imply {x['paper_T_N_implied_s']} s).")
    if k5:
        y = k5[0]
        why += (f" At 5 steps (k = {y['k']}) ours is {y['err_vertical_tau25_pct']} / "
                f"{y['err_horizontal_tau25_pct']} % (the k5 row).")
    return head + why


def write(rows, ref, ranks):
    with open(os.path.join(HERE, "table1.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = ["| method | r (m) | tau_L | k (rule; node spacing, steps) | vertical / horizontal error %, tau <= 2.5 "
             "| (paper) | whole run | peak error, tau <= 2.5 | saved CPU % (paper) | saved lag memory % (paper) "
             "| saved peak memory % |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for x in rows:
        lines.append(f"| {x['method']} | {x['r_m']} | {x['tau_L']} | {x['k']} ({x['k_rule']}; "
                     f"{x['node_spacing_steps']}) | {x['err_vertical_tau25_pct']} / {x['err_horizontal_tau25_pct']} "
                     f"| ({x['paper_err_vertical_pct']} / {x['paper_err_horizontal_pct']}) | "
                     f"{x['err_vertical_pct']} / {x['err_horizontal_pct']} | "
                     f"{x['peak_err_vertical_tau25_pct']} / {x['peak_err_horizontal_tau25_pct']} | "
                     f"{x['saved_cpu_pct']} ({x['paper_saved_cpu_pct']}) | "
                     f"{x['saved_lag_memory_pct']} ({x['paper_saved_memory_pct']}) | "
                     f"{x['saved_peak_memory_pct']} |")
    lines.append(f"\nNon-interpolated reference: {ref['time']:.1f} s total, lag matrices "
                 f"{ref['lag_bytes'] / 1e9:.2f} GB, peak memory {ref['peak'] / 1e9:.2f} GB, {ranks} rank(s).\n")
    lines += [f"- {sentence(x, rows)}" for x in rows]
    table = "\n".join(lines)
    readme = os.path.join(HERE, "README.md")
    text = open(readme).read()
    b, e = "<!-- table1:begin -->", "<!-- table1:end -->"
    i, j = text.index(b) + len(b), text.index(e)
    open(readme, "w").write(text[:i] + "\n" + table + "\n" + text[j:])
    print(table)


if __name__ == "__main__":
    main()
