#!/usr/bin/env python3
"""Generator of a multi-storey frame-and-shell building for the structures benchmark.

A regular building of ``--storeys`` storeys of height ``--height`` on a grid of
``--bays-x`` x ``--bays-y`` square bays of side ``--bay`` [m]:

  columns  vertical 2-node frames at every bay corner, from z = 0 to the roof, each storey
           split into round(height / elem) elements (intermediate nodes on the columns only)
  beams    2-node frames along every column line (x and y) of every floor, split into
           round(bay / elem) elements: they share their nodes with the slab
  slabs    one floor slab of 4-node shells per storey (z = k height, k = 1..storeys),
           (bays_x m) x (bays_y m) quads with m = round(bay / elem)
  base     point group: the column feet at z = 0 (to be fixed: -ssi_fem_fixed base)
  top      point group: one roof node, the corner (bays_x bay, bays_y bay, storeys height)

Every node carries 6 dofs (all are touched by a frame or a shell), so
dofs = 6 x nodes (before the base is fixed). Written with ``petsc_ssi.mesh.gmsh.write_msh``,
so the application reads it through the same gmsh reader as any user mesh.

    python runs/structures/frame_shell_model.py --storeys 10 --bays-x 4 --bays-y 4 \
        --bay 6 --height 3.5 --elem 1.0 --out out/structures-bench/b10x4x4-e1.0.msh
    python runs/structures/frame_shell_model.py ... --count     # sizes only, no file
"""
import argparse
import json
import os
import sys

import numpy as np


def building(storeys, bays_x, bays_y, bay, height, elem):
    """(coords (N, 3), {group: (type, cells)}, info dict) of the building."""
    m = max(1, int(round(bay / elem)))          # elements per bay edge (beams, slab)
    mc = max(1, int(round(height / elem)))      # elements per storey (columns)
    nxg, nyg = bays_x * m + 1, bays_y * m + 1   # slab grid nodes per floor
    per_floor = nxg * nyg
    xs = np.linspace(0.0, bays_x * bay, nxg)
    ys = np.linspace(0.0, bays_y * bay, nyg)
    # floor k = 1..storeys: nodes (k - 1) per_floor + i nyg + j
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    floors = [np.c_[X.ravel(), Y.ravel(), np.full(per_floor, k * height)] for k in range(1, storeys + 1)]
    coords = [np.concatenate(floors)] if floors else [np.zeros((0, 3))]
    n = storeys * per_floor

    def floor_node(k, i, j):                    # k = 1..storeys, grid indices (i, j)
        return (k - 1) * per_floor + i * nyg + j

    # columns: bay corners (i m, j m); feet at z = 0, intermediate nodes per storey
    ci, cj = np.meshgrid(np.arange(bays_x + 1) * m, np.arange(bays_y + 1) * m, indexing="ij")
    ci, cj = ci.ravel(), cj.ravel()
    ncol = ci.size
    feet = n + np.arange(ncol)
    coords.append(np.c_[xs[ci], ys[cj], np.zeros(ncol)])
    n += ncol
    col_cells = []
    below = feet
    for k in range(1, storeys + 1):
        chain = [below]
        for s in range(1, mc):
            ids = n + np.arange(ncol)
            coords.append(np.c_[xs[ci], ys[cj], np.full(ncol, (k - 1 + s / mc) * height)])
            n += ncol
            chain.append(ids)
        top = floor_node(k, ci, cj)
        chain.append(top)
        for a, b in zip(chain[:-1], chain[1:]):
            col_cells.append(np.c_[a, b])
        below = top
    coords = np.concatenate(coords)

    # beams along the column lines of every floor
    beam = []
    idx = np.arange(per_floor).reshape(nxg, nyg)
    for k in range(1, storeys + 1):
        off = (k - 1) * per_floor
        for j in range(0, nyg, m):               # lines y = j: along x
            line = off + idx[:, j]
            beam.append(np.c_[line[:-1], line[1:]])
        for i in range(0, nxg, m):               # lines x = i: along y
            line = off + idx[i, :]
            beam.append(np.c_[line[:-1], line[1:]])

    # slabs: counter-clockwise quads (normal +z)
    q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1).reshape(-1, 4)
    slab = np.concatenate([(k - 1) * per_floor + q for k in range(1, storeys + 1)])

    roof = floor_node(storeys, nxg - 1, nyg - 1)
    groups = {
        "columns": ("line2", np.concatenate(col_cells)),
        "beams": ("line2", np.concatenate(beam)),
        "slabs": ("quad4", slab),
        "base": ("point", feet[:, None]),
        "top": ("point", np.array([[roof]])),
    }
    info = dict(storeys=storeys, bays_x=bays_x, bays_y=bays_y, bay=bay, height=height, elem=elem,
                elems_per_bay=m, elems_per_storey=mc, nodes=int(coords.shape[0]),
                dofs=int(6 * coords.shape[0]), free_dofs=int(6 * (coords.shape[0] - ncol)),
                columns=int(groups["columns"][1].shape[0]), beams=int(groups["beams"][1].shape[0]),
                slabs=int(slab.shape[0]), top=[float(v) for v in coords[roof]])
    return coords, groups, info


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--storeys", type=int, default=10)
    ap.add_argument("--bays-x", type=int, default=4)
    ap.add_argument("--bays-y", type=int, default=4)
    ap.add_argument("--bay", type=float, default=6.0, help="bay width [m]")
    ap.add_argument("--height", type=float, default=3.5, help="storey height [m]")
    ap.add_argument("--elem", type=float, default=1.0, help="target element size [m]")
    ap.add_argument("--out", help="the .msh to write (omit with --count)")
    ap.add_argument("--count", action="store_true", help="print the sizes as JSON, write nothing")
    a = ap.parse_args(argv)
    coords, groups, info = building(a.storeys, a.bays_x, a.bays_y, a.bay, a.height, a.elem)
    if not a.count:
        if not a.out:
            ap.error("--out FILE.msh is required (or --count)")
        sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
        from petsc_ssi.mesh.gmsh import write_msh
        os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
        write_msh(a.out, coords, groups)
        info["msh"] = a.out
    print(json.dumps(info))


if __name__ == "__main__":
    main()
