"""Which soil nodes (rows of the lag matrices) each rank owns (-ssi_partition).

PETSc's default split gives every rank the same number of nodes, but nodes do not carry the same
work: a node near the middle of the mesh meets more elements inside each lag's wave window than a
node at an edge, so it holds more 3x3 blocks (memory, assembly) and its blocks take part in more
history products (time loop). On the medium Lamb case (a quarter model) the equal split leaves the
busiest of 2 ranks with 11 % more blocks than the mean, of 16 ranks with 19 % more (counted from
assembled lags: jobscripts/partition_balance.py).

``balanced`` (the default) cuts the node numbering into contiguous ranges of equal estimated work:
per node, its history products, counted from its blocks as ``model.estimate_blocks`` counts them
(the wave window of every node-element pair, folded over symmetry images, four nodes per element),
each block of lag l once per step that uses lag l in a run of L steps, L the lags the run reaches
(``weights`` says why products alone; not the run's own steps: the cut then depends on the
stored lags only, and a run stopped after n steps equals a run of n steps bit for bit). Every
rank computes the weights of an equal share of the nodes; all ranks gather them and cut
identically. Ranges stay contiguous, so the matrices' layout is PETSc's usual one with other
local sizes, and results agree with any other cut to round-off (the -n 1 / -n p tests).
"""
import numpy as np

CHOICES = ("balanced", "equal")


def equal_ranges(n, p):
    """PETSc's split of n nodes (block-3 rows) over p ranks: [(r0, r1)] per rank."""
    sizes = [n // p + (1 if r < n % p else 0) for r in range(p)]
    s = np.r_[0, np.cumsum(sizes)]
    return [(int(s[r]), int(s[r + 1])) for r in range(p)]


def lag_uses(Lx, steps, stabilized, n_interp=0):
    """Steps in which each stored matrix takes part in the history sum (the march's count, which
    ``estimate.Counts`` checks against a run's products): exact lags 1..Lx (lag 1 never: it is in
    the step matrix; lag j from step j - 1 on with the stabilised scheme, from step j plain), then
    the ``n_interp`` interpolating matrices (every step that reaches beyond lag Lx)."""
    n = np.arange(1, steps + 1)
    jmax = np.minimum(Lx, n + 1) if stabilized else np.minimum(Lx, n)
    jmax = np.where(n >= 2, jmax, 1)
    uses = np.zeros(Lx + n_interp)
    hist = np.bincount(jmax, minlength=Lx + 1)          # steps whose sum reaches exactly lag j
    reach_j = np.cumsum(hist[::-1])[::-1]                # steps reaching lag j or beyond
    uses[1:Lx] = reach_j[2:Lx + 1]
    if n_interp:
        reach = n + 1 if stabilized else n
        uses[Lx:] = np.count_nonzero((reach > Lx) & (n >= 2))
    return uses


def lag_weights(Lx, steps, stabilized, interp_lags=()):
    """Uses of the matrices by lag index 1..max(Lx, interp lags): the exact lags' uses, and each
    interpolating matrix's uses at the lag of its kernel time (``Plan.kernel_time``)."""
    uses = lag_uses(Lx, steps, stabilized, len(interp_lags))
    w = np.zeros(max([Lx] + list(interp_lags)))
    w[:Lx] = uses[:Lx]
    for i, l in enumerate(interp_lags):
        w[l - 1] += uses[Lx + i]
    return w


def node_work(xnodes, rows, Vc, VR, mat, dt, n_images, lag_w, Lx, n_t=0, chunk=256):
    """Estimated (blocks, products) of each node in ``rows``: blocks of the exact lags 1..Lx as
    ``model.estimate_blocks`` counts them (the wave window of each node-element pair, folded over
    symmetry images, four nodes per element); products: each block of lag index l (1..len(lag_w))
    times ``lag_w[l - 1]`` (``lag_weights``), and the node's row of G (``n_t`` traction nodes,
    stored dense: the same for every node) in every used matrix."""
    from .windows import pair_windows
    L = len(lag_w)
    cum = np.r_[0.0, np.cumsum(lag_w)]              # cum[l] = weight of lags 1..l
    blocks = np.zeros(len(rows))
    prods = np.full(len(rows), float(n_t) * cum[-1])
    for s in range(0, len(rows), chunk):
        xc = xnodes[rows[s:s + chunk]]
        lo, hi, ok = pair_windows(xc, Vc, VR, L, mat, dt, n_images)
        lo_i = np.where(ok, lo, 1).astype(np.int64)
        hi_i = np.where(ok, hi, 0).astype(np.int64)
        blocks[s:s + len(xc)] = 4.0 * np.clip(np.minimum(hi_i, Lx) - lo_i + 1, 0, None).sum(1)
        prods[s:s + len(xc)] += 4.0 * np.where(ok, cum[hi_i] - cum[lo_i - 1], 0.0).sum(1)
    return blocks, prods


def weights(blocks, prods):
    """The weight of each node: its estimated history products (``blocks``: the nodes' blocks, the
    weight where no step uses any lag). On the medium and paper Lamb cases at 2-16 ranks, cutting
    by products alone brings the busiest rank's products closer to even than the equal split
    (by 0.004 to 0.026) and takes a quarter to two thirds off the blocks' excess, as a node's
    products grow with its blocks; an equal mix of the blocks' and the products' shares evens the
    blocks further but leaves the products 2-4 points further from even than the equal split: the estimate counts the blocks of nodes near the symmetry corner low and those far from
    it high (jobscripts/partition_balance.py)."""
    prods = np.asarray(prods, float)
    return prods if float(prods.sum()) > 0 else np.asarray(blocks, float)


def balanced_ranges(w, p):
    """Contiguous ranges of the nodes 0..len(w)-1 over p ranks with about equal sums of ``w``: cut r
    at the node boundary nearest r/p of the total; every rank keeps at least one node when there
    are at least p nodes. Deterministic: every rank computes the same ranges from the same ``w``."""
    n = len(w)
    if p == 1 or n == 0:
        return equal_ranges(n, p)
    c = np.r_[0.0, np.cumsum(np.asarray(w, float))]
    if not c[-1] > 0:
        return equal_ranges(n, p)
    cuts = [0]
    for r in range(1, p):
        t = c[-1] * r / p
        k = int(np.searchsorted(c, t))                     # c[k - 1] < t <= c[k]
        if k > 0 and t - c[k - 1] < c[min(k, n)] - t:
            k -= 1
        lo_k = cuts[-1] + (1 if n >= p else 0)
        hi_k = n - (p - r if n >= p else 0)
        cuts.append(int(min(max(k, lo_k), hi_k)))
    cuts.append(n)
    return [(cuts[r], cuts[r + 1]) for r in range(p)]


PAIRS_PER_RANK = 2e7      # node-element pairs each rank counts at most (about half a second)


def all_weights(comm, xnodes, Vc, VR, mat, dt, n_images, lag_w, Lx, n_t=0):
    """Collective: the weights of all nodes, each rank counting an equal share and all gathering
    them in rank order (so every rank holds the same array). Where a rank's share would mean more
    than PAIRS_PER_RANK node-element pairs, every k-th node of it is counted and stands for the k
    nodes from it on (a run too large for memory is then still refused within seconds)."""
    N = len(xnodes)
    mpi = comm.tompi4py()
    r0, r1 = equal_ranges(N, mpi.Get_size())[mpi.Get_rank()]
    k = max(1, int(np.ceil(-(-N // mpi.Get_size()) * len(Vc) / PAIRS_PER_RANK)))
    rows = np.arange(r0, r1, k, dtype=np.int64)
    b, q = node_work(xnodes, rows, Vc, VR, mat, dt, n_images, lag_w, Lx, n_t)
    if k > 1:
        b, q = np.repeat(b, k)[:r1 - r0], np.repeat(q, k)[:r1 - r0]
    parts = mpi.allgather((b, q))
    return weights(np.concatenate([x[0] for x in parts]), np.concatenate([x[1] for x in parts]))


def imbalance(w, ranges):
    """Max over ranks of the ranks' summed weights, over their mean (1: balanced)."""
    c = np.r_[0.0, np.cumsum(w)]
    sums = np.array([c[b] - c[a] for a, b in ranges])
    return float(sums.max() / sums.mean()) if sums.mean() > 0 else 1.0


def node_ranges(comm, kind, xnodes, Vc, VR, mat, dt, n_images, lag_w, Lx, n_t=0):
    """Collective: (the node range of every rank by ``kind``, 'balanced' or 'equal'; the estimated
    work imbalance max/mean of those ranges and of the equal split: None on one rank)."""
    p = comm.getSize()
    N = len(xnodes)
    if kind not in CHOICES:
        raise ValueError(f"partition {kind!r}: expected one of {', '.join(CHOICES)}")
    eq = equal_ranges(N, p)
    if p == 1:
        return eq, None
    w = all_weights(comm, xnodes, Vc, VR, mat, dt, n_images, lag_w, Lx, n_t)
    ranges = balanced_ranges(w, p) if kind == "balanced" else eq
    return ranges, (imbalance(w, ranges), imbalance(w, eq))
