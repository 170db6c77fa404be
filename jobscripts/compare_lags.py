#!/usr/bin/env python3
"""Compare two lag-matrix files written by -ssi_lags_save (e.g. the same case assembled by two
versions of the code): the same list of matrices, each of the same storage, the same stored blocks
and the same values. Prints one line per file pair and exits 1 on any difference beyond --rtol
(default 0: bit for bit).

  python jobscripts/compare_lags.py A.lags B.lags [--rtol 1e-14]
"""
import argparse
import json
import sys

import numpy as np


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--rtol", type=float, default=0.0)
    args = ap.parse_args(argv)
    from petsc4py import PETSc
    ma, mb = (json.load(open(p + ".json")) for p in (args.a, args.b))
    if ma["mats"] != mb["mats"]:
        print(f"{args.a} vs {args.b}: different matrix lists")
        return 1
    va = PETSc.Viewer().createBinary(args.a, mode="r", comm=PETSc.COMM_SELF)
    vb = PETSc.Viewer().createBinary(args.b, mode="r", comm=PETSc.COMM_SELF)
    types = {"dense": PETSc.Mat.Type.SEQDENSE, "baij": PETSc.Mat.Type.SEQBAIJ, "aij": PETSc.Mat.Type.SEQAIJ}
    worst, nz, n = 0.0, 0, 0
    for name, kind in ma["mats"]:
        if kind == "empty":
            continue
        # the package's block-sparse and split dense lags ('bsr4', 'split5+diag', ...: bem/lagstore.py)
        # are in the file as an AIJ of their pattern's entries, and H_1's free term ('+diag') as another
        parts = ["aij", "aij"] if kind.endswith("+diag") else ["aij"] if kind.startswith(("bsr", "split")) else [kind]
        for part, t in enumerate(parts):
            A, B = (PETSc.Mat().create(comm=PETSc.COMM_SELF) for _ in range(2))
            for M, v in ((A, va), (B, vb)):
                M.setType(types[t])
                M.load(v)
            ia, ja, xa = A.getValuesCSR() if t != "dense" else (None, None, A.getDenseArray().ravel())
            ib, jb, xb = B.getValuesCSR() if t != "dense" else (None, None, B.getDenseArray().ravel())
            if t != "dense" and not (np.array_equal(ia, ib) and np.array_equal(ja, jb)):
                print(f"{name}{' (free term)' if part else ''}: different stored entries ({len(ja)} vs {len(jb)})")
                return 1
            d = np.abs(xa - xb).max() / max(np.abs(xa).max(), 1e-300) if len(xa) else 0.0
            worst = max(worst, d)
            nz += len(xa)
            A.destroy(); B.destroy()
        n += 1
    ok = worst <= args.rtol
    print(f"{args.a} vs {args.b}: {n} matrices, {nz} stored values, same blocks, largest relative "
          f"difference {worst:.3g} ({'bit for bit' if worst == 0 else ('within ' if ok else 'over ') + str(args.rtol)})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
