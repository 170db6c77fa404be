"""The wave windows of a BEM run: which lags each (collocation node, element) pair reaches.

An element's kernels are non-zero at a node only while a wave front from it sweeps the element:
for bounding spheres of the elements, lags from the P arrival at the nearest point to the S
departure from the farthest (``pair_windows``). The memory estimate, the partition's weights and
the cost model count stored blocks with them (``estimate_blocks``); ``causal_lags`` is the number
of lags after which no pair has a non-zero block.
"""
import math

import numpy as np


def causal_lags(r_max, mat, dt):
    """Lags that can be non-zero: the P kernel vanishes once (l-2) dt > r/c_s."""
    return int(math.floor(r_max / (mat.cs * dt))) + 2


def bounding_spheres(VX):
    c = VX[:, 8, :].copy()
    R = 1.1 * np.linalg.norm(VX - c[:, None, :], axis=2).max(axis=1) + 1e-12
    # element size: the longest of the four sides (corner to mid-side node, twice), independent of
    # which corner is node 0 (an element and its mirror image get the same size, so the same
    # near-field subdivisions: half and full models then integrate the same pairs alike)
    sides = [np.linalg.norm(VX[:, m] - VX[:, a], axis=1) for a, m in ((0, 4), (1, 5), (2, 6), (3, 7),
                                                                      (1, 4), (2, 5), (3, 6), (0, 7))]
    h = np.max(sides, axis=0) * 2
    return c, R, h


def pair_windows(xc, Vc, VR, L, mat, dt, n_images=1):
    """The lags 1..L each (point, element) pair reaches: (lo, hi, ok) of shape (points, elements
    without images), from the bounding spheres (the P wave's arrival to the S wave's passing, plus
    2), as the union over the element's symmetry images (they fold onto the same columns)."""
    E = len(Vc) // n_images
    d = np.linalg.norm(xc[:, None, :] - Vc[None, :, :], axis=2)
    lo = np.maximum(1, np.floor(np.maximum(d - VR, 0) / (mat.cp * dt)) + 1)
    hi = np.minimum(L, np.floor((d + VR) / (mat.cs * dt)) + 2)
    n = np.clip(hi - lo + 1, 0, None).reshape(len(xc), n_images, E)
    lo = np.where(n > 0, lo.reshape(n.shape), np.inf).min(1)
    hi = np.where(n > 0, hi.reshape(n.shape), -np.inf).max(1)
    return lo, hi, np.isfinite(lo) & (hi >= lo)


def plane_heights(VX, n_images=1):
    """Per element (without symmetry images, which stay in their plane) the height z of the horizontal
    plane holding all its nodes, NaN where there is none (a wall)."""
    E = len(VX) // n_images
    z = VX[:E, :, 2]
    return np.where(np.all(z == z[:, :1], axis=1), z[:, 0], np.nan)


def near_pairs(xc, Vc, VR, L, mat, dt, n_images=1):
    """``pair_windows`` over the pairs that can reach a lag 1..L only: (point, element, lo, hi) of the pairs
    whose union over the element's symmetry images has hi >= lo, found by k-d trees within the P wave's
    L dt reach of the bounding spheres (a pair farther apart starts after lag L: lo > L). Equal to
    ``pair_windows``' valid pairs; O(points x elements near) instead of O(points x elements)."""
    from scipy.spatial import cKDTree
    E = len(Vc) // n_images
    r = float(np.max(VR)) + mat.cp * dt * L
    sd = cKDTree(xc).sparse_distance_matrix(cKDTree(Vc), r, output_type="ndarray")
    pt, vc, d = sd["i"].astype(np.int64), sd["j"].astype(np.int64), sd["v"]
    lo = np.maximum(1, np.floor(np.maximum(d - VR[vc], 0) / (mat.cp * dt)) + 1)
    hi = np.minimum(L, np.floor((d + VR[vc]) / (mat.cs * dt)) + 2)
    v = hi >= lo
    key = pt[v] * E + vc[v] % E                       # (the union over an element's images)
    o = np.argsort(key, kind="stable")
    key, lo, hi = key[o], lo[v][o], hi[v][o]
    if not len(key):                                  # (no element within reach of these points)
        return key, key, lo, hi
    first = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    return key[first] // E, key[first] % E, np.minimum.reduceat(lo, first), np.maximum.reduceat(hi, first)


# near_pairs instead of the all-pairs windows when the reach's share of the surface's pairs is below this;
# about NEAR_PAIRS point-element pairs a call
NEAR_SHARE = 0.2
NEAR_PAIRS = 2e6
# the assembly's candidate lists (``candidates``) at most about this many elements over a rank's rows (64 MB)
CANDIDATES_MAX = 16e6


def candidates(pts, Vc, VR, reach):
    """The virtual elements each point of ``pts`` can meet within the P wave's ``reach`` [m] (the assembly's
    ``_pair_window``: an element whose bounding sphere lies farther is skipped there), as CSR (ptr (points +
    1,) int64, elements int32 ascending in each point's list), found by a k-d tree over the spheres' centres
    within reach + the largest radius (a superset of the pairs the assembly keeps, by a relative 1e-9 of
    margin: the same pairs as the loop over every element, in the same order). None where the reach covers
    NEAR_SHARE of the surface or more (the loop over every element is then as cheap), or where the lists would
    hold more than about CANDIDATES_MAX elements (4 bytes each, not in the memory estimate): the step matrix's lags
    1-2 on a large grid visit O(points) pairs instead of O(points x elements) (the 100 m site's lags 1-2:
    its assembly grew as N^1.9 before)."""
    if not len(Vc) or not len(pts) or reach <= 0.0:      # (no pair: every sphere at distance >= reach)
        return np.zeros(len(pts) + 1, np.int64), np.zeros(0, np.int32)
    area = np.prod(np.ptp(Vc[:, :2], axis=0) + 2 * float(np.max(VR)))
    r = (float(reach) + float(np.max(VR))) * (1.0 + 1e-9) + 1e-12
    if np.pi * r ** 2 >= NEAR_SHARE * area or len(pts) * len(Vc) * np.pi * r ** 2 / area > CANDIDATES_MAX:
        return None
    from scipy.spatial import cKDTree
    tree = cKDTree(Vc)
    step = int(np.clip(NEAR_PAIRS / max(1.0, len(Vc) * np.pi * r ** 2 / area), 64, 1 << 16))
    counts, idx = [], []
    for s in range(0, len(pts), step):
        sd = cKDTree(pts[s:s + step]).sparse_distance_matrix(tree, r, output_type="ndarray")
        key = sd["i"].astype(np.int64) * len(Vc) + sd["j"].astype(np.int64)
        key.sort()
        counts.append(np.bincount(key // len(Vc), minlength=len(pts[s:s + step])))
        idx.append((key % len(Vc)).astype(np.int32))
    ptr = np.zeros(len(pts) + 1, np.int64)
    np.cumsum(np.concatenate(counts), out=ptr[1:])
    return ptr, np.concatenate(idx)


def estimate_blocks(xnodes, rows, Vc, VR, L, mat, dt, n_images=1, chunk=256, plane_z=None):
    """Estimated number of non-zero 3x3 blocks of each H lag (array, index
    l-1) in ``rows``: for each (row, element) the lags its wave window touches
    (union over the element's symmetry images, which fold onto the same
    columns), times four nodes per element (a node is shared by about four).
    ``plane_z`` (``plane_heights``): only the pairs whose point lies in the element's horizontal plane
    (the blocks H keeps in the flat pattern on a surface that is not one plane, ``lagset.SplitBuckets``;
    a column also met by elements of another plane, at an edge, is counted as theirs). Where the lags'
    reach covers a small share of the surface (the step matrix's lags 1-2), only the pairs within it are
    visited (``near_pairs``: the same counts)."""
    diff = np.zeros(L + 2)
    pts = xnodes[rows]
    area = np.prod(np.ptp(Vc[:, :2], axis=0) + 2 * float(np.max(VR))) if len(Vc) else 0.0
    reach = float(np.max(VR)) + mat.cp * dt * L if len(Vc) else 0.0
    if len(Vc) and np.pi * reach ** 2 < NEAR_SHARE * area:
        # (points a call: about NEAR_PAIRS pairs, from the elements' mean density within the reach)
        step = int(np.clip(NEAR_PAIRS / max(1.0, len(Vc) * np.pi * reach ** 2 / area), 64, 16 * chunk))
        for s in range(0, len(rows), step):
            pt, e, lo, hi = near_pairs(pts[s:s + step], Vc, VR, L, mat, dt, n_images)
            if plane_z is not None:
                keep = pts[s + pt, 2] == plane_z[e]
                lo, hi = lo[keep], hi[keep]
            diff += 4.0 * np.bincount(lo.astype(np.int64), minlength=L + 2)[:L + 2]
            diff -= 4.0 * np.bincount(hi.astype(np.int64) + 1, minlength=L + 2)[:L + 2]
        return np.cumsum(diff)[1:L + 1]
    for s in range(0, len(rows), chunk):
        lo, hi, ok = pair_windows(pts[s:s + chunk], Vc, VR, L, mat, dt, n_images)
        if plane_z is not None:
            ok = ok & (pts[s:s + chunk, 2][:, None] == plane_z[None, :])
        # counts of window starts and ends (np.add.at of 4.0 per pair summed the same integers, slowly)
        diff += 4.0 * np.bincount(lo[ok].astype(np.int64), minlength=L + 2)[:L + 2]
        diff -= 4.0 * np.bincount(hi[ok].astype(np.int64) + 1, minlength=L + 2)[:L + 2]
    return np.cumsum(diff)[1:L + 1]
