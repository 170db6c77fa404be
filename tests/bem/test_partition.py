"""-ssi_partition: which soil nodes (rows of the lag matrices) each rank owns (bem/partition.py)."""
import json
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

from helpers import PY, ROOT, cli, petsc, read_h5, relmax
from petsc_ssi.bem import partition

pytestmark = pytest.mark.mpi

ARGS = ["-ssi_mesh_size", "16,16", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1", "-ssi_load_group", "load",
        "-ssi_load_p0", "1000", "-ssi_symmetry", "x=sym,y=sym", "-ssi_t_end", "0.03", "-ssi_dt", "7.5e-4",
        "-ssi_receivers", "3,0,0;2,2,0", "-ssi_output_stride", "5"]


def _check_cover(ranges, n, p):
    assert len(ranges) == p and ranges[0][0] == 0 and ranges[-1][1] == n
    assert all(ranges[r][1] == ranges[r + 1][0] for r in range(p - 1))
    assert all(b >= a for a, b in ranges)
    if n >= p:
        assert all(b > a for a, b in ranges)


def test_balanced_ranges_cover_and_balance():
    """Contiguous ranges covering every node, at least one node per rank, each rank's work within
    one node's weight of the mean; equal weights give PETSc's equal split; fewer nodes than ranks
    still cover."""
    rng = np.random.default_rng(3)
    for n in (1, 7, 50, 333):
        w = rng.uniform(0.2, 3.0, n) * np.linspace(1, 4, n)
        for p in (1, 2, 3, 5, 8, 16):
            r = partition.balanced_ranges(w, p)
            _check_cover(r, n, p)
            if n >= 4 * p:
                c = np.r_[0, np.cumsum(w)]
                sums = np.array([c[b] - c[a] for a, b in r])
                assert np.abs(sums - c[-1] / p).max() <= w.max() + 1e-12, (n, p, sums)
            assert partition.balanced_ranges(w.copy(), p) == r           # deterministic
            sizes = [b - a for a, b in partition.balanced_ranges(np.ones(n), p)]
            assert sizes == [b - a for a, b in partition.equal_ranges(n, p)] or max(sizes) - min(sizes) <= 1


def _small_lagset(PETSc, **extra):
    from petsc_ssi.bem.lagset import Material, Regions, LagSet
    from petsc_ssi.bem.symmetry import parse as parse_planes
    from petsc_ssi.mesh.surface import grid
    mesh = grid(8.0, 8.0, 1.0, (1.0, 1.0), xmin=0.0, ymin=0.0)
    opts = {"gauss": 2, "singular_order": 8, "subdivisions": 2, "near_factor": 2.0, "max_subdivisions": 8,
            "cache": True, **extra}
    return mesh, LagSet(PETSc.COMM_SELF, mesh, Material(548.0, 316.0, 2000.0), 7.5e-4, 12,
                        Regions(mesh, load_elems=mesh.groups["load"]), parse_planes("x=sym,y=sym"), opts)


def test_node_work_is_the_memory_estimate_count():
    """The partition's block count per node sums to the memory estimate's count (one window rule);
    its products are the blocks of each lag times the uses of that lag, which are the products
    the march makes (estimate.Counts' count, checked there against a run's VecMAXPY count): lag 1
    never (it is in the step matrix), lag j >= 2 from step max(2, j - 1) on (stabilised) or from
    step j (plain)."""
    from petsc_ssi.bem.windows import estimate_blocks
    PETSc = petsc()
    mesh, ls = _small_lagset(PETSc)
    nimg = len(ls.Vc) // mesh.n_cells
    rows = np.arange(mesh.n_nodes)
    S, L = 10, 12
    assert list(partition.lag_uses(5, S, True)) == [0, 9, 9, 8, 7]           # (no history at step 1)
    assert list(partition.lag_uses(5, S, False)) == [0, 9, 8, 7, 6]
    assert list(partition.lag_uses(3, S, True, 2)) == [0, 9, 9, 8, 8]        # + 2 interpolating matrices
    lw = partition.lag_weights(L, S, True)
    b, q = partition.node_work(mesh.nodes, rows, ls.Vc, ls.VR, ls.mat, ls.dt, nimg, lw, L)
    est = estimate_blocks(mesh.nodes, rows, ls.Vc, ls.VR, L, ls.mat, ls.dt, nimg)
    assert abs(b.sum() / est.sum() - 1) < 1e-12
    # products by lag: the same window count, one lag at a time
    per_lag = sum(lw[l - 1] * estimate_blocks(mesh.nodes, rows[:1], ls.Vc, ls.VR, L, ls.mat, ls.dt, nimg)[l - 1]
                  for l in range(1, L + 1))
    assert abs(q[0] / per_lag - 1) < 1e-12
    # an interpolating matrix at lag 20 adds its window's blocks times its uses, G n_t blocks per
    # use; the windows then reach lag 20, as in the memory estimate of such a run
    lw2 = partition.lag_weights(L, S, True, [20])
    b2, q2 = partition.node_work(mesh.nodes, rows, ls.Vc, ls.VR, ls.mat, ls.dt, nimg, lw2, L, n_t=3)
    e = estimate_blocks(mesh.nodes, rows, ls.Vc, ls.VR, 20, ls.mat, ls.dt, nimg)
    assert abs(b2.sum() / e[:L].sum() - 1) < 1e-12
    e0 = estimate_blocks(mesh.nodes, rows[:1], ls.Vc, ls.VR, 20, ls.mat, ls.dt, nimg)
    assert abs(q2[0] - (np.dot(lw2, e0) + 3 * lw2.sum())) < 1e-9 * q2[0]


# slow tier: the balanced partition evens the assembled work: a speed property (jobscripts measure it);
#  balanced == equal partitions at -n 2 stays
@pytest.mark.slow
def test_balanced_evens_the_assembled_work():
    """The medium Lamb case (625 nodes, 107 lags, 106 steps) assembled on one process
    (jobscripts/partition_balance.py --one medium): cut for 2, 4, 8 and 16 ranks from the estimate,
    the busiest rank's assembled blocks are at least two points closer to the mean than with PETSc's
    equal node counts, and its history products no more than one point further from it. (On meshes
    of a few grid lines per rank the cut's granularity dominates and this need not hold.)"""
    p = subprocess.run([PY, os.path.join(ROOT, "jobscripts", "partition_balance.py"), "--one", "medium"],
                       cwd=ROOT, capture_output=True, text=True, timeout=600,
                       env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    rows = [json.loads(x) for x in p.stdout.splitlines() if x.startswith("{")]
    assert p.returncode == 0 and [r["ranks"] for r in rows] == [2, 4, 8, 16], p.stdout + p.stderr
    for r in rows:
        assert r["blocks_balanced"] < r["blocks_equal"] - 0.02, r
        assert r["products_balanced"] < r["products_equal"] + 0.01, r


# slow tier: the make-test budget (10-20 s); the default tier's sibling: test_balanced_ranges_cover_and_balance, test_node_work_is_the_memory_estimate_count
@pytest.mark.slow
@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
def test_two_ranks_balanced_and_equal_agree(tmp_path):
    """At -n 2 the balanced cut differs from the equal one (here: nodes near the symmetry corner carry
    more work), reproduces it and -n 1 to round-off, and is the cut `petsc-ssi estimate` counts."""
    out = {k: tmp_path / f"{k}.h5" for k in ("n1", "bal", "eq")}
    cli(ARGS + ["-ssi_output", str(out["n1"])], nranks=1)
    pb = cli(ARGS + ["-ssi_output", str(out["bal"])], nranks=2)
    pe = cli(ARGS + ["-ssi_output", str(out["eq"]), "-ssi_partition", "equal"], nranks=2)
    pat = r"soil nodes over 2 ranks: (\d+)\.\.(\d+) per rank, -ssi_partition (\w+) \(estimated work max/mean ([\d.]+)"
    mb, me = re.search(pat, pb.stdout), re.search(pat, pe.stdout)
    assert mb and me, pb.stdout + pe.stdout
    assert mb.group(3) == "balanced" and me.group(3) == "equal"
    assert int(me.group(2)) - int(me.group(1)) <= 1 < int(mb.group(2)) - int(mb.group(1))
    assert float(mb.group(4)) < float(me.group(4))
    r1, rb, re_ = (read_h5(out[k]) for k in ("n1", "bal", "eq"))
    assert np.abs(r1["u"]).max() > 0
    for r in (rb, re_):
        assert relmax(r["u"], r1["u"]) <= 1e-12 and relmax(r["last"], r1["last"]) <= 1e-12
    # the cost model's ranges for 2 ranks, counted on one process: the sizes the run printed
    code = ("import json, sys\nfrom petsc_ssi.petsc import init\nPETSc = init(sys.argv)\n"
            "from petsc_ssi import options\nfrom petsc_ssi.app import estimate\ncfg = options.resolve(('common', 'bem', 'estimate'))\n"
            "_, _, cnt = estimate.count_run(cfg, PETSc.COMM_WORLD, [2], 0.0)\nprint('RANGES' + json.dumps(cnt.ranges[2]))")
    p = subprocess.run([PY, "-c", code] + ARGS, cwd=ROOT, capture_output=True, text=True, timeout=300,
                       env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    line = [x for x in p.stdout.splitlines() if x.startswith("RANGES")]
    assert p.returncode == 0 and line, p.stdout + p.stderr
    sizes = sorted(b - a for a, b in json.loads(line[0][6:]))
    assert sizes == [int(mb.group(1)), int(mb.group(2))]


def test_sampled_weights_for_large_meshes(monkeypatch):
    """Past PAIRS_PER_RANK node-element pairs per rank every k-th node is counted and stands for
    the k from it on: the weights keep their total to within a few per cent and the cut stays
    within a node's weight of the exact one's balance."""
    PETSc = petsc()
    mesh, ls = _small_lagset(PETSc)
    nimg = len(ls.Vc) // mesh.n_cells
    lw = partition.lag_weights(12, 10, True)
    args = (PETSc.COMM_SELF, mesh.nodes, ls.Vc, ls.VR, ls.mat, ls.dt, nimg, lw, 12)
    exact = partition.all_weights(*args)
    monkeypatch.setattr(partition, "PAIRS_PER_RANK", mesh.n_nodes * len(ls.Vc) / 3.5)     # k = 4
    sampled = partition.all_weights(*args)
    assert len(sampled) == len(exact) and not np.array_equal(sampled, exact)
    assert np.array_equal(sampled[::4], exact[::4])
    assert abs(sampled.sum() / exact.sum() - 1) < 0.05
    for p in (2, 4):
        ib = partition.imbalance(exact, partition.balanced_ranges(sampled, p))
        assert ib - 1 <= p * exact.max() / exact.sum() + 0.05, (p, ib)


@pytest.mark.parametrize("lag_hi", [2, 5])
def test_candidate_elements_assemble_the_arrays_of_every_element(lag_hi, monkeypatch):
    """The assembly's candidate elements (``windows.candidates``, a k-d tree within the lags' P-wave reach: the
    step matrix's lags 1-2 on a large grid visit O(points) pairs, not O(points x elements); the 100 m site's
    lags 1-2 took 17 s, 6.9 s at 80 m, against 0.43 s) give the arrays of the loop over every element bit for
    bit, on a quarter model (symmetry images among the elements), with the element cache on and off; each
    point's list is ascending and holds every element whose bounding sphere comes within the reach."""
    from petsc_ssi.bem import windows
    from petsc_ssi.bem.packs import CP, DT, TOFF
    PETSc = petsc()
    got = {}
    for share in (0.0, 1e9):                  # never the candidates (every element); always them
        monkeypatch.setattr(windows, "NEAR_SHARE", share)
        for cache in (True, False):
            mesh, ls = _small_lagset(PETSc, cache=cache)
            pk = ls.kernel_packs(1, lag_hi, 0.0)
            cand = ls.candidates(ls.rows, pk)
            assert (len(cand[0]) > 0) == (share > 0)
            ls.assemble(lag_hi=lag_hi, chunk=7)          # (chunks: each call's rows from its offset in the lists)
            got[share, cache] = [B.csr(l) for B in (ls.H, ls.G) for l in range(1, lag_hi + 1)]
        # the shared cache's listing of geometries (enumerate_pairs, more than one rank): the same with the lists
        from petsc_ssi.bem.assemble import enumerate_pairs
        qinv = 1.0 / (1e-9 * float(ls.Vh.min()))
        got[share, "pairs"] = enumerate_pairs(ls.rows, *pk[:4], qinv, ls.CACHE_MAX, 81, cand)
    for cache in (True, False):
        assert len(got[0.0, cache]) == len(got[1e9, cache])
        for a, b in zip(got[0.0, cache], got[1e9, cache]):
            assert len(a) == len(b) == 3 and all(np.array_equal(x, y) for x, y in zip(a, b))
    assert all(np.array_equal(x, y) for x, y in zip(got[0.0, "pairs"], got[1e9, "pairs"]))
    assert len(got[0.0, "pairs"][0]) > 0
    assert sum(len(a[1]) for a in got[0.0, True]) > 0
    # the lists: ascending, and every element within reach + its radius of the point is in them
    phys = pk[2]
    reach = float(phys[CP] * (phys[DT] * lag_hi + phys[TOFF]))
    ptr, el = windows.candidates(mesh.nodes, ls.Vc, ls.VR, reach)
    d = np.linalg.norm(mesh.nodes[:, None, :] - ls.Vc[None, :, :], axis=2)
    for i in range(mesh.n_nodes):
        mine = el[ptr[i]:ptr[i + 1]]
        assert np.all(np.diff(mine) > 0)
        assert set(np.flatnonzero(d[i] - ls.VR < reach)) <= set(mine.tolist())
    assert ptr[-1] < d.size                   # (fewer than every pair)
    monkeypatch.setattr(windows, "CANDIDATES_MAX", 0.0)     # (lists over the cap: every element, no lists)
    assert windows.candidates(mesh.nodes, ls.Vc, ls.VR, reach) is None


@pytest.mark.parametrize("L", [1, 2, 5, 12])
def test_near_pairs_count_as_the_all_pairs_windows(L, monkeypatch):
    """``estimate_blocks`` through the k-d tree's near pairs (``windows.near_pairs``: the step matrix's short
    reach on a large surface) counts what the all-pairs windows count, on a quarter model (symmetry
    images folded) and with the in-plane filter; the near pairs are exactly the valid all-pairs windows."""
    from petsc_ssi.bem import windows
    from petsc_ssi.bem.windows import estimate_blocks, near_pairs, pair_windows, plane_heights
    PETSc = petsc()
    mesh, ls = _small_lagset(PETSc)
    nimg = len(ls.Vc) // mesh.n_cells
    rows = np.arange(mesh.n_nodes)
    pz = plane_heights(ls.VX, nimg)
    got = {}
    for share in (0.0, 1e9):                  # all pairs; always the tree
        monkeypatch.setattr(windows, "NEAR_SHARE", share)
        got[share] = (estimate_blocks(mesh.nodes, rows, ls.Vc, ls.VR, L, ls.mat, ls.dt, nimg),
                      estimate_blocks(mesh.nodes, rows, ls.Vc, ls.VR, L, ls.mat, ls.dt, nimg, plane_z=pz))
    assert got[0.0][0].sum() > 0
    for a, b in zip(got[0.0], got[1e9]):
        assert np.array_equal(a, b)
    lo, hi, ok = pair_windows(mesh.nodes, ls.Vc, ls.VR, L, ls.mat, ls.dt, nimg)
    pt, e, nlo, nhi = near_pairs(mesh.nodes, ls.Vc, ls.VR, L, ls.mat, ls.dt, nimg)
    i, j = np.nonzero(ok)
    assert np.array_equal(pt, i) and np.array_equal(e, j)
    assert np.array_equal(nlo, lo[i, j]) and np.array_equal(nhi, hi[i, j])
    # points out of every element's reach (the traction elements' window seen from far nodes): no pairs
    far = mesh.nodes[:3] + np.array([1e3, 0.0, 0.0])
    assert all(len(a) == 0 for a in near_pairs(far, ls.Vc, ls.VR, L, ls.mat, ls.dt, nimg))
    monkeypatch.setattr(windows, "NEAR_SHARE", 1e9)
    assert not estimate_blocks(far, np.arange(3), ls.Vc, ls.VR, L, ls.mat, ls.dt, nimg).any()
