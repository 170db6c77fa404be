"""Table of jobscripts/lags_reuse.sh: per case and rank count, wall time and BEM set-up (assembly
or load) of the assembled and the loaded run, and the largest difference of their interface
displacement u_f and receiver series (max |loaded - assembled| / max |assembled|).
    python jobscripts/lags_reuse_table.py OUTDIR README.md CSV
rewrites the README text between <!-- lags-reuse:begin --> and <!-- lags-reuse:end -->."""
import csv
import glob
import json
import os
import sys

import h5py
import numpy as np

out, readme, csv_path = sys.argv[1:4]
rows = []
for rec in sorted(glob.glob(os.path.join(out, "*-assembled-n*.json"))):
    stem = rec[:-len(".json")]
    case, n = os.path.basename(stem).split("-assembled-n")
    a = json.load(open(rec))["stats"]
    b = json.load(open(stem.replace("-assembled-", "-loaded-") + ".json"))["stats"]
    diff = 0.0
    with h5py.File(stem + ".h5") as fa, h5py.File(stem.replace("-assembled-", "-loaded-") + ".h5") as fb:
        for k in ("interface/uf", "receivers/u"):
            x, y = fb[k][:], fa[k][:]
            diff = max(diff, float(np.abs(x - y).max() / max(np.abs(y).max(), 1e-300)))
    rows.append({"case": case, "ranks": int(n), "wall assembled [s]": round(a["wall_s"], 1),
                 "wall loaded [s]": round(b["wall_s"], 1), "BEM assembly [s]": round(a["assembly_s"], 1),
                 "BEM load [s]": round(b["assembly_s"], 2), "saved [s]": round(a["wall_s"] - b["wall_s"], 1),
                 "saved [%]": round(100 * (a["wall_s"] - b["wall_s"]) / a["wall_s"]),
                 "max rel. difference": f"{diff:.1e}"})
rows.sort(key=lambda r: (r["ranks"], r["case"].startswith("anti"), r["case"]))
cols = list(rows[0])
with open(csv_path, "w", newline="") as fh:
    w = csv.DictWriter(fh, cols)
    w.writeheader()
    w.writerows(rows)
table = "| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n"
table += "".join("| " + " | ".join(str(r[c]) for c in cols) + " |\n" for r in rows)
text = open(readme).read()
b, e = "<!-- lags-reuse:begin -->", "<!-- lags-reuse:end -->"
i, j = text.index(b) + len(b), text.index(e)
open(readme, "w").write(text[:i] + "\n" + table + text[j:])
print(table)
