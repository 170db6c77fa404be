"""The block patterns of the lag matrices (bem/bsr.py): which entries (p, q) of a 3x3 node block a
matrix stores, in storage order. A leaf: the block kernels' template (bsr.py) and its vector
operations (simd.py) read it, the assembly (assemble.py) names its patterns. The njit kernels compiled
from it depend on it: the word njit here puts this module in their cache key
(petsc_ssi._numba_cache_dir).

For a collocation point and an element in one plane (every soil surface petsc_ssi accepts is the
plane z = 0; symmetry images stay in it) the traction kernel (H) only couples in-plane with
out-of-plane components, entries (x,z), (y,z), (z,x), (z,y) (``H4``), the displacement kernel (G)
keeps (x,x), (x,y), (y,x), (y,y), (z,z) (``G5``); ``FULL`` keeps all nine (any other surface).
"""
FULL, H4, G5 = 9, 4, 5
PATTERNS = {FULL: tuple((p, q) for p in range(3) for q in range(3)),
            H4: ((0, 2), (1, 2), (2, 0), (2, 1)),
            G5: ((0, 0), (0, 1), (1, 0), (1, 1), (2, 2))}
NAMES = {FULL: "full", H4: "flat-H", G5: "flat-G"}


def rows(m):
    """Per block row p = 0, 1, 2, the (value slot j, column component q) of the entries pattern ``m``
    keeps in that row, in storage order: row p of a block times x is sum_j d[j] x[q_j] in that order.
    Every pattern keeps at least one entry a row (a block product writes each row once)."""
    out = tuple(tuple((j, q) for j, (p, q) in enumerate(PATTERNS[m]) if p == r) for r in range(3))
    if not all(out):
        raise ValueError(f"block pattern {m}: a row without entries")
    return out
