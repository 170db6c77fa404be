"""Mesh meshes/building.geo with the application's own reader and check it; write the half model.

  .venv/bin/python runs/building/building_counts.py [NAME=VALUE ...]     (from the repository root)

NAME=VALUE set the .geo's ONELAB parameters (nbx, nby, sx, sy, ns, hs, h, hc, half), e.g.
``half=1`` or ``nby=4 sy=2.7``. For the default building and its half model it

- reads the mesh through ``petsc_ssi.fem.mesh.structure_from_model`` with the parts of
  runs/building/fixed-base.opts (which checks: one part per cell, no coincident nodes, each
  element's geometry), and prints element, node and dof counts per part and group;
- checks that the frame nodes at the levels are slab nodes (monolithic joints), that every
  shell, beam and column has the expected length/area, the groups' node counts, the expected
  counts (1728 shells, 1158 frames for 4 x 3 bays; halves for the half model) and that the half
  model's nodes are exactly the full model's nodes with y >= 0;
- writes out/building/building_half.msh (gmsh 4.1): petsc-ssi's structure reader takes no
  .geo parameters, so the half model runs from this .msh (-ssi_fem_mesh out/building/building_half.msh).
"""
import os
import sys
from types import SimpleNamespace

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, ROOT)
GEO = os.path.join(ROOT, "meshes", "building.geo")
HALF_MSH = os.path.join(ROOT, "out", "building", "building_half.msh")

from petsc_ssi.mesh import gmsh as reader               # noqa: E402
from petsc_ssi.fem.mesh import structure_from_model     # noqa: E402
from petsc_ssi.fem.parts import parse_parts             # noqa: E402


def opts_parts(path=os.path.join(HERE, "fixed-base.opts")):
    """{key: value} of the -ssi_fem_part_* options and the part list of the options file."""
    raw, parts = {}, ""
    for line in open(path):
        line = line.split("#")[0].split()
        if len(line) >= 2 and line[0].startswith("-ssi_fem_part_"):
            raw[line[0][len("-ssi_fem_part_"):]] = line[1]
        elif len(line) >= 2 and line[0] == "-ssi_fem_parts":
            parts = line[1]
    return raw, parts


def specs_for(model, raw, parts):
    """The fixed-base parts, plus int_beams_sym / columns_sym (half section) if the mesh has them."""
    raw = dict(raw)
    names = parts.split(",")
    for sym, base in (("int_beams_sym", "int_beams"), ("columns_sym", "columns")):
        if sym in model.groups:
            names.append(sym)
            for k, v in list(raw.items()):
                if k.startswith(base + "_"):
                    prop = k[len(base) + 1:]
                    if prop == "section":
                        b, hh = (float(s) for s in v.split(","))
                        v = f"{b / 2},{hh}"
                    elif prop == "added_mass":
                        v = str(float(v) / 2)
                    raw[f"{sym}_{prop}"] = v
    cfg = SimpleNamespace(get=lambda *a: ",".join(names), fem_parts=",".join(names))
    return parse_parts(cfg, raw)


def read(params):
    model = reader.read(GEO, dim=3, params=params)
    raw, parts = opts_parts()
    specs = specs_for(model, raw, parts)
    return model, structure_from_model(model, specs, GEO)


def report(mesh, params, fixed=("foundation",), sym=False):
    print(f"== building.geo {params or '(defaults)'}")
    counts = {}
    for b in mesh.blocks:
        counts[b.part] = counts.get(b.part, 0) + b.cells.shape[0]
    for name, n in counts.items():
        print(f"  part {name:14s} {n:5d} cells")
    ec = mesh.element_counts()
    print(f"  elements: {ec}  total {mesh.n_cells}")
    rot = mesh.has_rotation()
    ndof = 3 * mesh.n_nodes + 3 * int(rot.sum())
    nfix = set()
    for g in fixed:
        nfix |= set(mesh.nodes[g].tolist())
    fixed_dofs = 6 * len(nfix)
    if sym:
        fixed_dofs += 3 * len(set(mesh.nodes["sym_y"].tolist()) - nfix)
    print(f"  nodes {mesh.n_nodes} ({int(rot.sum())} with rotations), dofs {ndof}, "
          f"fixed {fixed_dofs} ({'+'.join(fixed)}{' + sym_y:uy+rx+rz' if sym else ''}), free {ndof - fixed_dofs}")
    for g in sorted(mesh.nodes):
        print(f"  group {g:14s} dim {mesh.dims[g]}  {len(mesh.nodes[g]):5d} nodes")
    for g in ("A", "B"):
        x = mesh.coords[mesh.nodes[g][0]]
        print(f"  point {g} = ({x[0]:g}, {x[1]:g}, {x[2]:g})")
    return ec


def check(mesh, expect_shell, expect_frame, hs=3.0):
    """Structural checks (AssertionError on failure)."""
    X = mesh.coords
    shell_nodes = np.unique(np.concatenate([b.cells.ravel() for b in mesh.blocks if b.element.name == "shell"]))
    ok = True
    for b in mesh.blocks:
        if b.element.name != "frame":
            continue
        n = np.unique(b.cells.ravel())
        if b.part.startswith("columns"):
            at_level = np.isclose(X[n, 2] / hs, np.round(X[n, 2] / hs))
            off = np.setdiff1d(n[at_level], shell_nodes)
            ok &= off.size == 0
            print(f"  {b.part}: {n.size} nodes, {int(at_level.sum())} at the levels, all of them slab nodes: "
                  f"{off.size == 0}")
        else:
            off = np.setdiff1d(n, shell_nodes)
            ok &= off.size == 0
            print(f"  {b.part}: {n.size} nodes, all of them slab nodes: {off.size == 0}")
    ec = mesh.element_counts()
    ok &= ec.get("shell", 0) == expect_shell and ec.get("frame", 0) == expect_frame
    print(f"  shells {ec.get('shell', 0)} (expected {expect_shell}), frames {ec.get('frame', 0)} "
          f"(expected {expect_frame}): {'OK' if ok else 'MISMATCH'}")
    # lengths and areas
    for b in mesh.blocks:
        P = X[b.cells]
        if b.element.name == "frame":
            L = np.linalg.norm(P[:, 1] - P[:, 0], axis=1)
            print(f"  {b.part:14s} frame lengths {L.min():.4g}..{L.max():.4g} m, total {L.sum():.6g} m")
        else:
            a = 0.5 * np.linalg.norm(np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 1]), axis=1)
            print(f"  {b.part:14s} shell areas {a.min():.4g}..{a.max():.4g} m^2, total {a.sum():.6g} m^2")
    assert ok, "building mesh check failed"


def write_half():
    import gmsh
    gmsh.initialize(["gmsh", "-v", "0"], readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.onelab.setNumber("Parameters/half", [1.0])
        gmsh.open(GEO)
        gmsh.model.mesh.generate(3)
        os.makedirs(os.path.dirname(HALF_MSH), exist_ok=True)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.write(HALF_MSH)
    finally:
        gmsh.finalize()
    print(f"wrote {os.path.relpath(HALF_MSH, ROOT)}")


def main(argv):
    params = {}
    for a in argv:
        k, v = a.split("=")
        params[k] = float(v)
    if params:
        model, mesh = read(params)
        report(mesh, params, sym=bool(params.get("half")))
        return
    _, full = read({})
    report(full, {})
    check(full, 1728, 1158)
    _, half = read({"half": 1})
    report(half, {"half": 1}, sym=True)
    check(half, 864, 579)
    # the half model's nodes are the full model's nodes with y >= 0
    key = lambda X: {tuple(np.round(x, 6)) for x in X}          # noqa: E731
    same = key(half.coords) == key(full.coords[full.coords[:, 1] > -1e-9])
    print(f"half-model nodes == full-model nodes with y >= 0: {same}")
    assert same
    write_half()


if __name__ == "__main__":
    main(sys.argv[1:])
