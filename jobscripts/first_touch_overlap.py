#!/usr/bin/env python3
"""Can the first touch of the lag arrays hide behind the assembly's arithmetic? (issue 29)

Each of PROCS fresh processes (2: one per core, as the ranks of a 2-rank run) allocates GB
gigabytes (numpy's huge-page advice on, as the lag arrays are) and, in mode

  seq: populates them (madvise MADV_POPULATE_WRITE: every page faulted in for writing, the
       contents untouched, so a thread may run it ahead of a writer without a race), then runs
       SECONDS of numpy arithmetic;
  ovl: runs the same arithmetic for SECONDS while a second thread populates the array.

It prints per process the wall time, the populate time and the arithmetic done (iterations).
If the page faults cost the host's time rather than this virtual CPU's, 'ovl' would finish the
same arithmetic in about SECONDS; if they cost this CPU's time, 'ovl' does proportionally less
arithmetic in its SECONDS (no gain). Alternates seq and ovl REPEAT times, 4 s apart.

    python jobscripts/first_touch_overlap.py [GB] [SECONDS] [REPEAT] [PROCS]  (default 3 3 2 2)

Needs Linux >= 5.14 (MADV_POPULATE_WRITE); exits with a message where madvise refuses it."""
import subprocess
import sys
import time

CHILD = r"""
import sys, time, ctypes, threading
import numpy as np
from numpy.core.multiarray import _set_madvise_hugepage
_set_madvise_hugepage(True)
MADV_POPULATE_WRITE = 23
libc = ctypes.CDLL("libc.so.6", use_errno=True)
libc.madvise.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
mode, gb, sec = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
a = np.empty(int(gb * 2**30 / 8))

def populate():
    t = time.perf_counter()
    p, end = (a.ctypes.data + 4095) & ~4095, (a.ctypes.data + a.nbytes) & ~4095
    while p < end:
        n = min(64 << 20, end - p)
        if libc.madvise(p, n, MADV_POPULATE_WRITE):
            sys.exit(f"madvise(MADV_POPULATE_WRITE) failed: errno {ctypes.get_errno()}")
        p += n
    return time.perf_counter() - t

def arithmetic(sec):
    x, k, t = np.random.default_rng(0).random((300, 300)), 0, time.perf_counter()
    while time.perf_counter() - t < sec:
        for _ in range(50):
            x = np.sin(x) * 0.5 + 0.1
        k += 1
    return k

t0 = time.perf_counter()
if mode == "seq":
    tp = populate()
    k = arithmetic(sec)
else:
    res = {}
    th = threading.Thread(target=lambda: res.setdefault("tp", populate()))
    th.start()
    k = arithmetic(sec)
    th.join()
    tp = res["tp"]
print(f"{mode} wall {time.perf_counter() - t0:.2f} s, populate {tp:.2f} s, arithmetic {k} iterations")
"""


def main():
    gb, sec, repeat, procs = (float(sys.argv[1]) if len(sys.argv) > 1 else 3.0,
                              float(sys.argv[2]) if len(sys.argv) > 2 else 3.0,
                              int(sys.argv[3]) if len(sys.argv) > 3 else 2,
                              int(sys.argv[4]) if len(sys.argv) > 4 else 2)
    for _ in range(repeat):
        for mode in ("seq", "ovl"):
            time.sleep(4)
            ps = [subprocess.Popen([sys.executable, "-c", CHILD, mode, str(gb), str(sec)],
                                   stdout=subprocess.PIPE, text=True) for _ in range(procs)]
            for p in ps:
                out, _ = p.communicate()
                if p.returncode:
                    sys.exit(p.returncode)
                print(out.strip(), flush=True)


if __name__ == "__main__":
    main()
