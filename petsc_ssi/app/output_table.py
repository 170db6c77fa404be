"""The README's "Output files" table, generated from real files: ``python -m petsc_ssi.app.output_table
FILE.h5 ...`` walks each file (h5py) and prints one row per dataset (snapshots once, as
``<field>_NNNNNN``): file, group, dataset, shape in symbols, unit (the dataset's ``unit``
attribute) and meaning (``MEANING``). ``update(README, files)`` rewrites the table between its
markers; tests/test_output_files.py runs a small coupled case and checks the README's table is
what its files hold."""
import re
import sys

BEGIN, END = "<!-- BEGIN output-files -->", "<!-- END output-files -->"

MEANING = {
    "coordinates": "node coordinates (the XDMF geometry)",
    "topology": "cells (node indices; XDMF topology; a Mixed list when element types mix)",
    "time": "time of each snapshot (the first at t = 0, the state at rest; the last step only if a multiple "
            "of -ssi_output_stride)",
    "displacement_NNNNNN": "snapshot k of the nodal displacement (total field with an earthquake)",
    "traction_NNNNNN": "snapshot k of the soil's nodal traction on the surface",
    "velocity_NNNNNN": "snapshot k of the structure's nodal velocity",
    "rotation_NNNNNN": "snapshot k of the rotations (frame and shell nodes; 0 elsewhere)",
    "receivers/points": "receiver points as given",
    "receivers/t": "receiver times: soil t = dt, 2 dt, ... (K: the steps); structure t = 0, dt, ... (K: the "
                   "steps + 1)",
    "receivers/u": "displacement at each receiver",
    "receivers/velocity": "velocity at each structure receiver",
    "receivers/acceleration": "acceleration at each structure receiver (no acceleration field is written)",
    "receivers/rotation": "rotation at each structure receiver (0 at nodes without rotations)",
    "receivers/nodes": "structure node each receiver snapped to",
    "receivers/node_points": "coordinates of that node",
    "receivers/snap_distance": "distance from the point to that node",
    "receivers/has_rotation": "whether that node carries rotations",
    "demands/t": "times of the storey demands: t = 0, dt, ... (every step)",
    "demands/base_shear": "base shear (x, y): the force the structure exerts on the ground through its base, "
                          "foundation inertia included (convention attribute)",
    "demands/overturning_moment": "overturning moment (about x, y) of the same forces about reference_point",
    "demands/peak_base_shear": "peak |base shear| per component over the run",
    "demands/peak_base_shear_time": "time of that peak",
    "demands/peak_overturning_moment": "peak |overturning moment| per component over the run",
    "demands/peak_overturning_moment_time": "time of that peak",
    "demands/reference_point": "the point the moments are taken about (-ssi_structure_moment_ref)",
    "demands/levels": "the drift levels z_i (-ssi_structure_drift_levels)",
    "demands/drift_ratio": "inter-storey drift ratio per storey (x, y): relative displacement / storey height",
    "demands/peak_drift_ratio": "peak |drift ratio| per storey and component",
    "demands/peak_drift_ratio_time": "time of that peak",
    "interface/t": "interface series times t = dt, 2 dt, ... (every step)",
    "interface/x": "interface nodes (soil side)",
    "interface/normal": "outward soil normal at each interface node",
    "interface/uf": "structure displacement at the interface nodes",
    "interface/ub": "soil displacement at the interface nodes",
    "interface/uf_check": "implicit coupling: the structure's interface displacement recomputed from the "
                          "converged tractions",
    "interface/p": "interface traction on the soil",
    "interface/gap": "normal gap (> 0 open)",
    "interface/pN": "normal contact pressure",
    "interface/closed": "contact closed (1) or open (0)",
    "interface/n_open": "open interface nodes",
    "interface/iterations": "contact iterations of the step",
    "interface/changes": "contact status changes of the step",
    "interface/force_fe": "resultant force of the interface on the structure",
    "interface/force_be": "resultant force of the interface on the soil",
    "interface/moment_fe": "resultant moment on the structure (about the origin)",
    "interface/moment_be": "resultant moment on the soil (about the origin)",
    "interface/bem_residual": "relative residual of the soil's step solve",
    "interface/force_map_error": "largest difference of the two force maps",
    "timing/step_wall": "wall time of each step",
}


def _symbols(f):
    """{size: symbol} of the sizes of this file: N nodes, E cells, S snapshots, R receivers, K
    receiver times, I interface nodes, KI interface times."""
    sym = {}

    def put(n, s):
        if n is not None and n not in sym and n != 3:
            sym[n] = s
    put(f["coordinates"].shape[0] if "coordinates" in f else None, "N")
    put(f["topology"].shape[0] if "topology" in f else None, "E")
    put(f["time"].shape[0] if "time" in f else None, "S")
    put(f["receivers/points"].shape[0] if "receivers/points" in f else None, "R")
    put(f["receivers/t"].shape[0] if "receivers/t" in f else None, "K")
    put(f["interface/x"].shape[0] if "interface/x" in f else None, "I")
    put(f["interface/t"].shape[0] if "interface/t" in f else None, "K")
    return sym


def rows(path, label=None):
    """[(file, group, dataset, shape, unit, meaning)] of one output file."""
    import h5py
    out, seen = [], set()
    with h5py.File(path, "r") as f:
        sym = _symbols(f)

        def visit(name, obj):
            if not isinstance(obj, h5py.Dataset):
                return
            key = re.sub(r"_\d{6}$", "_NNNNNN", name)
            if key in seen:
                return
            seen.add(key)
            grp, _, ds = key.rpartition("/")
            shape = "(" + ", ".join(sym.get(n, str(n)) for n in obj.shape) + ")"
            unit = obj.attrs.get("unit", "")
            out.append((label or path, grp or "/", ds, shape, str(unit), MEANING.get(key, "")))
        f.visititems(visit)
    return out


def table(files):
    """Markdown of ``files`` [(path, label)]."""
    lines = ["| file | group | dataset | shape | unit | meaning |", "|---|---|---|---|---|---|"]
    for path, label in files:
        for r in rows(path, label):
            lines.append("| " + " | ".join(f"`{c}`" if i in (0, 2) else c for i, c in enumerate(r)) + " |")
    return "\n".join(lines)


def update(readme, files):
    text = open(readme).read()
    i, j = text.index(BEGIN) + len(BEGIN), text.index(END)
    new = text[:i] + "\n" + table(files) + "\n" + text[j:]
    if new != text:
        with open(readme, "w") as fh:
            fh.write(new)
    return new != text


if __name__ == "__main__":
    print(table([(p, None) for p in sys.argv[1:]]))
