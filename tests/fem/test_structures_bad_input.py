"""Bad input to a structure of parts ends the run under `mpirun -n 2` with ONE line
'petsc-ssi: error: ...' and exit status 2 on every rank, before assembly (no "[fem] alpha_m"
line, which follows the assembly), never a hang (timeout) or a traceback."""
import os

import numpy as np
import pytest

from fem_helpers import run_cli

pytestmark = pytest.mark.mpi

BASE = ["-ssi_problem", "fem", "-ssi_fem_mesh", "meshes/slab_on_columns.geo", "-ssi_t_end", "0.004",
        "-ssi_dt", "0.002", "-ssi_output", ""]
SLAB = {"slab_element": "shell", "slab_E": "30e9", "slab_nu": "0.2", "slab_rho": "2500", "slab_thickness": "0.2",
        "columns_element": "frame", "columns_E": "30e9", "columns_nu": "0.2", "columns_rho": "2500",
        "columns_section": "0.3,0.3"}


def args(parts="slab,columns", drop=(), fixed="base", **extra):
    props = {k: v for k, v in SLAB.items() if k not in drop}
    props.update({k: v for k, v in extra.items() if not k.startswith("ssi_")})
    out = BASE + ["-ssi_fem_parts", parts, "-ssi_fem_fixed", fixed]
    for k, v in props.items():
        out += [f"-ssi_fem_part_{k}", v]
    for k, v in extra.items():
        if k.startswith("ssi_"):
            out += [f"-{k}", v]
    return out


def one_line_error(r):
    if "-ssi_fem_part_pole_element" in r.args:               # the mechanism case warns first
        assert "joints are pinned" in r.stdout, r.stdout
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    errs = [ln for ln in lines if ln.startswith("petsc-ssi: error: ")]
    assert r.returncode == 2, r.stdout + r.stderr
    assert len(errs) == 1, r.stdout + r.stderr
    assert "Traceback" not in r.stderr, r.stderr
    assert "[fem] alpha_m" not in r.stdout, r.stdout
    return errs[0]


@pytest.fixture(scope="module")
def bad_meshes(tmp_path_factory):
    """.msh files with one defect each (written by the same writer users can call)."""
    from fem_helpers import _init  # noqa: F401  (PETSc initialised before gmsh)
    from petsc_ssi.mesh.gmsh import write_msh
    d = tmp_path_factory.mktemp("bad")
    X = np.array([[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1], [0, 0, 0], [5, 5, 5.0]])
    out = {}
    out["lonely"] = str(d / "lonely.msh")            # node 5 is in a point group but in no element
    write_msh(out["lonely"], X, {"slab": ("quad4", [[0, 1, 2, 3]]), "columns": ("line2", [[4, 0]]),
                                 "base": ("point", [[4]]), "far": ("point", [[5]])})
    Xd = np.vstack([X[:5], [[0, 0, 1.0]]])           # the column's top is a second node at the slab corner
    out["duplicate"] = str(d / "duplicate.msh")
    write_msh(out["duplicate"], Xd, {"slab": ("quad4", [[0, 1, 2, 3]]), "columns": ("line2", [[4, 5]]),
                                     "base": ("point", [[4]])})
    out["zero_length"] = str(d / "zero_length.msh")
    write_msh(out["zero_length"], X[:5], {"slab": ("quad4", [[0, 1, 2, 3]]),
                                          "columns": ("line2", [[4, 0], [0, 0]]), "base": ("point", [[4]])})
    Xm = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1],
                   [1, 1, 1.5], [1, 1, 2.0]], float)
    out["mechanism"] = str(d / "mechanism.msh")     # a pole pinned to a brick at one node
    write_msh(out["mechanism"], Xm, {"block": ("hex8", [list(range(8))]), "pole": ("line2", [[6, 8], [8, 9]]),
                                     "bottom": ("quad4", [[0, 3, 2, 1]]), "tip": ("point", [[9]])})
    out["zero_area"] = str(d / "zero_area.msh")
    write_msh(out["zero_area"], X[:5], {"slab": ("quad4", [[0, 1, 2, 3], [0, 1, 1, 0]]),
                                        "columns": ("line2", [[4, 0]]), "base": ("point", [[4]])})
    return out


COLUMNS = tuple(k for k in SLAB if k.startswith("columns_"))
MECH = ["-ssi_problem", "fem", "-ssi_fem_parts", "block,pole", "-ssi_fem_part_block_element", "hex8",
        "-ssi_fem_part_block_E", "1e9", "-ssi_fem_part_block_nu", "0.2", "-ssi_fem_part_block_rho", "2000",
        "-ssi_fem_part_pole_element", "frame", "-ssi_fem_part_pole_E", "1e9", "-ssi_fem_part_pole_nu", "0.2",
        "-ssi_fem_part_pole_rho", "2000", "-ssi_fem_part_pole_section", "0.1,0.1", "-ssi_fem_fixed", "bottom",
        "-ssi_fem_point_load", "tip,1000,0,0", "-ssi_output", ""]
CASES = {
    "shell without thickness": (lambda m: args(drop=("slab_thickness",)),
                                "part 'slab' (shell) needs -ssi_fem_part_slab_thickness"),
    "frame without section": (lambda m: args(drop=("columns_section",)),
                              "part 'columns' (frame) needs -ssi_fem_part_columns_section b,h or"),
    "part without element": (lambda m: args(drop=("slab_element",)), "part 'slab' has no element type"),
    "unknown element": (lambda m: args(slab_element="plate"), "must be one of hex8|frame|shell"),
    "misspelt property": (lambda m: args(slab_thicknes="0.2"), "did you mean thickness?"),
    "property of another element": (lambda m: args(columns_thickness="0.2"),
                                    "a frame part has no property 'thickness'"),
    "unknown part in a property": (lambda m: args(slap_E="1e9"), "no part 'slap' in -ssi_fem_parts"),
    "part named twice": (lambda m: args(parts="slab,slab"), "a part is named twice"),
    "part properties without parts": (lambda m: BASE + ["-ssi_fem_part_slab_E", "1"],
                                      "is set but -ssi_fem_parts names no part"),
    "parts on the box generator": (lambda m: [a if a != "meshes/slab_on_columns.geo" else "box" for a in args()],
                                   "-ssi_fem_parts needs a gmsh mesh"),
    "shell with nu 0.5": (lambda m: args(slab_nu="0.5"), "Poisson's ratio must lie in (-1, 0.5)"),
    "frame with a negative area": (lambda m: args(columns_area="-1"), "-ssi_fem_part_columns_area -1: must be > 0"),
    "massless shell": (lambda m: args(slab_rho="0"), "has no mass"),
    "orientation parallel to a column": (lambda m: args(columns_orientation="0,0,2"), "parallel"),
    "part group missing": (lambda m: args(parts="slab,columns,roof", roof_element="shell", roof_E="1", roof_nu="0",
                                          roof_rho="1", roof_thickness="1"), "no physical group 'roof'"),
    "part on a group of the wrong dimension": (lambda m: args(parts="slab,base", drop=COLUMNS,
                                                              base_element="frame", base_E="1",
                                                              base_nu="0", base_rho="1", base_section="1,1",
                                                              fixed="slab"), "has dimension 0"),
    "unknown dof name": (lambda m: args(fixed="base:ux+rq"), "unknown dof name 'rq'"),
    "rotation of a brick-only group": (lambda m: ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2",
                                                  "-ssi_fem_fixed", "base:rx", "-ssi_output", ""],
                                       "have no rotation dofs (bricks only)"),
    "moment on a brick node": (lambda m: ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_fem_fixed",
                                          "base", "-ssi_fem_point_load", "0,0,0.5,0,0,0,1,0,0", "-ssi_output", ""],
                               "acts on a node without rotation dofs"),
    "point load on a missing group": (lambda m: args(ssi_fem_point_load="roof,1,0,0"), "no group 'roof'"),
    "unconnected node": (lambda m: [a if a != "meshes/slab_on_columns.geo" else m["lonely"] for a in
                                    args(fixed="base,far")], "belong to no element of any part"),
    "duplicate nodes": (lambda m: [a if a != "meshes/slab_on_columns.geo" else m["duplicate"] for a in args()],
                        "coincident nodes"),
    "zero-length frame": (lambda m: [a if a != "meshes/slab_on_columns.geo" else m["zero_length"] for a in args()],
                          "part 'columns' (frame)"),
    "mechanism (static)": (lambda m: ["static", "-ssi_fem_mesh", m["mechanism"]] + MECH, "K is singular (relative residual"),
    "zero-area shell": (lambda m: [a if a != "meshes/slab_on_columns.geo" else m["zero_area"] for a in args()],
                        "part 'slab' (shell)"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_structure_input_one_line_on_every_rank(case, bad_meshes):
    make, message = CASES[case]
    r = run_cli(make(bad_meshes), n=2, timeout=120)
    line = one_line_error(r)
    assert message in line, line
