#!/usr/bin/env python3
"""The first write of fresh memory by PROCS processes at once (as the ranks of a run write their lag
arrays), with numpy's huge-page advice on and off, alternating REPEAT times: seconds per GB and
kernel (sys) seconds of each process, and the change of /proc/vmstat's compaction counters over
each trial (compact_stall: the kernel compacting memory on the spot). Issue 29's first-touch
section (jobscripts/README.md): on this VM the advised writes cost 2.3 s/GB without a compaction
stall (memory handed back to the host by free page reporting), 0.4-0.5 s/GB without the advice.

    python jobscripts/first_touch_pair.py [GB] [REPEAT] [PROCS]      (default 3.5 2 2)"""
import subprocess
import sys

CHILD = r"""
import sys, time, resource
import numpy as np
from numpy.core.multiarray import _set_madvise_hugepage
_set_madvise_hugepage(sys.argv[1] == "on")
gb = float(sys.argv[2])
t = time.perf_counter()
a = np.empty(int(gb * 2**30 / 8))
a[:] = 1.0
d = time.perf_counter() - t
print(f"advice {sys.argv[1]}: {d / gb:.3f} s/GB, sys {resource.getrusage(resource.RUSAGE_SELF).ru_stime:.2f} s")
"""


def vmstat():
    out = {}
    for line in open("/proc/vmstat"):
        k, v = line.split()
        if k.startswith("compact_") or k.startswith("thp_fault"):
            out[k] = int(v)
    return out


def main():
    gb = float(sys.argv[1]) if len(sys.argv) > 1 else 3.5
    repeat = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    procs = int(sys.argv[3]) if len(sys.argv) > 3 else 2
    for _ in range(repeat):
        for mode in ("on", "off"):
            before = vmstat()
            ps = [subprocess.Popen([sys.executable, "-c", CHILD, mode, str(gb)], stdout=subprocess.PIPE, text=True)
                  for _ in range(procs)]
            lines = [p.communicate()[0].strip() for p in ps]
            after = vmstat()
            delta = {k: after[k] - before.get(k, 0) for k in ("compact_stall", "thp_fault_alloc", "thp_fault_fallback")
                     if k in after}
            print(" | ".join(lines), "|", delta, flush=True)


if __name__ == "__main__":
    main()
