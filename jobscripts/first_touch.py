#!/usr/bin/env python3
"""What it costs this machine to write memory for the first time: the cost the assembly pays for
every stored lag block (the block buckets and the element cache are fresh arrays), and the main
source of run-to-run spread in the scaling tables.

numpy (1.18 on, on Linux) advises the kernel to back arrays of 4 MB and more with transparent huge
pages (madvise MADV_HUGEPAGE). Where /sys/kernel/mm/transparent_hugepage/defrag is 'madvise' (as
here), a fault in such an array may compact memory on the spot to find a free 2 MB page. Each
trial is a fresh process that writes GB gigabytes into a new numpy array, with numpy's huge-page
advice on and off, alternating, REPEAT times each; it reports seconds per GB and the huge pages the
array got, and the same array written a second time (pages already present: the memory bandwidth
that is left). Writes jobscripts/results/first_touch.csv and the table between
<!-- first_touch:begin/end --> in jobscripts/README.md.

    python jobscripts/first_touch.py [GB] [REPEAT]       (default 2 GB, 5 times; under a minute)"""
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from logview import write_csv, put_block  # noqa: E402

CHILD = r"""
import sys, time
import numpy as np
from numpy.core.multiarray import _set_madvise_hugepage
_set_madvise_hugepage(sys.argv[1] == "on")
gb = float(sys.argv[2])
t = time.perf_counter()
a = np.empty(int(gb * 1e9) // 8)
a[:] = 1.0
first = time.perf_counter() - t
t = time.perf_counter()
a[:] = 2.0
second = time.perf_counter() - t
huge = 0
with open("/proc/self/smaps_rollup") as fh:
    for line in fh:
        if line.startswith("AnonHugePages:"):
            huge = int(line.split()[1]) * 1024
print(first / gb, second / gb, huge / (gb * 1e9))
"""


def sysfs(name):
    try:
        with open(f"/sys/kernel/mm/transparent_hugepage/{name}") as fh:
            return fh.read().strip()
    except OSError:
        return "n/a"


def main():
    gb = float(sys.argv[1]) if len(sys.argv) > 1 else 2.0
    repeat = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    res = {"on": [], "off": []}
    for i in range(repeat):
        for advice in ("on", "off"):
            out = subprocess.run([sys.executable, "-c", CHILD, advice, str(gb)], check=True,
                                 capture_output=True, text=True).stdout.split()
            res[advice].append([float(v) for v in out])
            print(f"[first_touch] trial {i + 1} advice {advice}: first write {float(out[0]):.3f} s/GB, "
                  f"second {float(out[1]):.3f} s/GB, huge pages {100 * float(out[2]):.0f} %", flush=True)
    rows = []
    for advice in ("on", "off"):
        a = np.array(res[advice])
        rows.append({"numpy_hugepage_advice": advice, "gb": gb, "trials": repeat,
                     "first_min_s_per_gb": round(float(a[:, 0].min()), 3),
                     "first_median_s_per_gb": round(float(np.median(a[:, 0])), 3),
                     "first_max_s_per_gb": round(float(a[:, 0].max()), 3),
                     "second_median_s_per_gb": round(float(np.median(a[:, 1])), 3),
                     "huge_page_share_median": round(float(np.median(a[:, 2])), 3),
                     "every_first_s_per_gb": " ".join(f"{v:.2f}" for v in a[:, 0]),
                     "thp_enabled": sysfs("enabled"), "thp_defrag": sysfs("defrag")})
    write_csv(os.path.join(HERE, "results", "first_touch.csv"), rows)
    lines = [f"Transparent huge pages: enabled `{rows[0]['thp_enabled']}`, defrag `{rows[0]['thp_defrag']}`; "
             f"{repeat} fresh processes each writing {gb:g} GB.", "",
             "| numpy huge-page advice | first write, s/GB: fastest / median / slowest | every trial | "
             "second write, s/GB (median) | huge pages (median share) |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['numpy_hugepage_advice']} | {r['first_min_s_per_gb']} / {r['first_median_s_per_gb']} / "
                     f"{r['first_max_s_per_gb']} | {r['every_first_s_per_gb']} | {r['second_median_s_per_gb']} | "
                     f"{100 * r['huge_page_share_median']:.0f} % |")
    block = "\n".join(lines)
    print(block)
    put_block("first_touch", block + "\n", [os.path.join(HERE, "README.md")])


if __name__ == "__main__":
    main()
