"""How fast this machine hands out new memory: a copy of SIZE_GB (default 1) into a new array (its pages touched for
the first time), then the same copy three times more into the same array (its pages resident), in GB/s of bytes read
and written. On the virtual machines of this project the first copy has run at 0.11 GB/s against 13 GB/s (2026-11-30):
a run that allocates GBs then pays seconds per GB before any work, and its walls are not comparable with a run's on a
machine that has its memory already (jobscripts/README.md; bench_env.sh's warm-up run is for this).

    python jobscripts/first_touch.py [SIZE_GB]"""
import sys
import time

import numpy as np


def main():
    gb = float(sys.argv[1]) if len(sys.argv) > 1 else 1.0
    a = np.ones(int(gb * 1e9 / 8))
    b = np.empty_like(a)
    for i in range(4):
        t = time.perf_counter()
        np.copyto(b, a)
        dt = time.perf_counter() - t
        print(f"[first_touch] copy {i + 1} of {a.nbytes / 1e9:.3g} GB ({'new pages' if i == 0 else 'resident'}): "
              f"{2 * a.nbytes / dt / 1e9:.3g} GB/s")


if __name__ == "__main__":
    main()
