#!/usr/bin/env python3
"""The first write of fresh memory against its size: PROCS fresh processes at once (as the ranks of
a run) each map SIZE MB (private anonymous memory), advise it huge (MADV_HUGEPAGE) or small
(MADV_NOHUGEPAGE) and write every byte once; seconds per GB of each, for each size and advice in
turn with a pause between trials. Why -ssi_huge_pages auto decides from the machine and not from a
probe (issue 29, jobscripts/README.md's first-touch section): on the development VM, whose balloon
reports free pages to its host, the first few hundred MB of huge pages came cheap and the GBs after
them did not, so a small probe would have chosen huge pages for a run that writes GBs.

    python jobscripts/first_touch_sizes.py [PROCS] [SIZES_MB...]     (default 2  64 256 1024 2048)"""
import subprocess
import sys
import time

CHILD = r"""
import mmap, sys, time
import numpy as np
mb, advice = int(sys.argv[1]), sys.argv[2]
m = mmap.mmap(-1, mb << 20, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS)
m.madvise(mmap.MADV_HUGEPAGE if advice == "huge" else mmap.MADV_NOHUGEPAGE)
a = np.frombuffer(m, np.float64)
t = time.perf_counter()
a[:] = 1.0
print(f"{(time.perf_counter() - t) / (mb / 1024):.3f}")
"""


def main():
    procs = int(sys.argv[1]) if len(sys.argv) > 1 else 2
    sizes = [int(s) for s in sys.argv[2:]] or [64, 256, 1024, 2048]
    print(f"{procs} processes at once, each writing SIZE MB of fresh private memory once; s/GB of each")
    print("| size [MB] | huge pages (MADV_HUGEPAGE) [s/GB] | small pages (MADV_NOHUGEPAGE) [s/GB] |")
    print("|---|---|---|")
    for mb in sizes:
        row = []
        for advice in ("huge", "small"):
            ps = [subprocess.Popen([sys.executable, "-c", CHILD, str(mb), advice], stdout=subprocess.PIPE, text=True)
                  for _ in range(procs)]
            row.append(" ".join(p.communicate()[0].strip() for p in ps))
            time.sleep(2)
        print(f"| {mb} | {row[0]} | {row[1]} |", flush=True)


if __name__ == "__main__":
    main()
