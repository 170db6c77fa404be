"""The toeplitz lag store against the dense one (issue 41): per case, both runs and the largest difference
of every recorded field over the run's largest value of its kind (tests/bem/test_history_block.py
``scales``: the measure the exactness tests bound by 1e-12); with -ssi_toeplitz_precision single, how far
single-precision kept transforms move the answer from double.

    PYTHONPATH=. .venv/bin/python jobscripts/toeplitz_exact.py [OUTDIR]

prints one line per case (cases, grids and options: the default-tier tests' own, tests/bem/test_toeplitz.py)."""
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests"))
sys.path.insert(0, os.path.join(ROOT, "tests", "bem"))
from helpers import cli                                                      # noqa: E402
from test_history_block import BEM, DISP, INTERP, fields, scales             # noqa: E402
from test_toeplitz import SLOW_SITE, INTERP_CASES, TZ                       # noqa: E402

SINGLE = ["-ssi_toeplitz_precision", "single"]
CASES = [  # (name, options, ranks of the toeplitz run, options of the toeplitz run only)
    ("load, stabilised", BEM, 1, []),
    ("load, plain", BEM + ["-ssi_scheme", "plain"], 1, []),
    ("load, stabilised, -n 2", BEM, 2, ["-ssi_reproducible"]),
    ("load, multi-linear beyond T_L, symmetry x,y", BEM + INTERP + ["-ssi_symmetry", "x=sym,y=sym"], 1, []),
    ("load, Chebyshev beyond T_L, -n 2", SLOW_SITE + INTERP_CASES["chebyshev"][0], 2, ["-ssi_reproducible"]),
    ("load, multi-linear graded, plain", SLOW_SITE + INTERP_CASES["linear graded, T_L in a block, plain"][0], 1, []),
    ("prescribed motion, stabilised", DISP, 1, []),
    ("prescribed motion, plain, -n 2", DISP + ["-ssi_scheme", "plain"], 2, ["-ssi_reproducible"]),
    ("load, stabilised: single against double transforms", BEM, 1, SINGLE),
    ("prescribed motion: single against double transforms", DISP, 1, SINGLE),
]


def worst(a, b):
    A, B = fields(a), fields(b)
    S = scales(A)
    return max((np.abs(A[k] - B[k]).max() / S[k], k) for k in A if S[k] > 0)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "/tmp/toeplitz_exact"
    os.makedirs(out, exist_ok=True)
    for i, (name, args, n, extra) in enumerate(CASES):
        ref, tz = os.path.join(out, f"{i}-ref.h5"), os.path.join(out, f"{i}-tz.h5")
        base = args + TZ if extra is SINGLE else args        # single: against the toeplitz store in double
        cli(base + ["-ssi_output", ref, "-ssi_output_overwrite"])
        log = cli(args + TZ + extra + ["-ssi_output", tz, "-ssi_output_overwrite"], nranks=n).stdout
        assert "G lags as" in log, log[-2000:]            # (the G history on the store too)
        r, k = worst(ref, tz)
        print(f"{name:55s} {r:9.2e}  ({k})", flush=True)


if __name__ == "__main__":
    main()
