"""Member forces of the structure's frame and shell parts (``-ssi_structure_forces PARTS``): per
output snapshot in the structure's HDF5 file, their peak envelope over every step, and the
envelope as cell fields of the structure's XDMF (ParaView colours the members by peak moment).

Conventions (the element kernels')
----------------------------------
Frames (``fem.elements.frame.Frame.end_force_operator``): f = k_local (T u_e), the 12 end forces
and moments the NODES EXERT ON THE ELEMENT in its local axes (x' from node 0 to node 1, z' the
part's orientation vector made normal to x', y' = z' x x'), order (N, V2, V3, T, M2, M3) at node 0
(suffix _i) then node 1 (_j), from the element's stiffness only (no inertia of the member:
OpenSees' ``localForce``). The section's stress resultants (tension, and moments as vectors on
the face with outward normal +x') are -f_i at node 0 and +f_j at node 1: axial tension N_j =
-N_i; M2 > 0 stretches the +z' fibre; M3 > 0 compresses the +y' fibre. [N, N m]

Shells (``fem.elements.shell.resultant_operator``): the stress resultants at the element's centre
in its local frame (``shell.local_frame``: e1, e2 in the mean plane, e3 = the normal), N11 N22
N12 [N/m] = int sigma dz, M11 M22 M12 [N m/m] = int sigma z dz (z along e3; M11 > 0 stretches the
+e3 fibre), Q1 Q2 [N/m] = int sigma_a3 dz, from the same B matrices as the stiffness (the Allman
membrane field, the MITC4 assumed shear, the warping links).

Output (the structure's file: ``-ssi_output`` of a fem run, ``<stem>_structure.h5`` of an ssi run)
----------------------------------------------------------------------------------------------
  forces_<part>_<k:06d>     (E, c)       the forces at snapshot k (time[k]), written collectively
  forces_envelope_<part>    (E, c)       max over ALL steps (not only the written ones) of |value|
  forces/<part>             (K, E, c)    the snapshots as one (virtual) dataset; attrs unit (one
                                         per component, comma-separated), components,
                                         convention, element, part
  forces/<part>_envelope    (E, c)       the envelope, with the same attributes
  forces/<part>_gravity, _max, _min, _gravity_plus_max, _gravity_plus_min   (E, c)
                                         with -ssi_fem_gravity (``fem/gravity.py``): the self-weight
                                         case G, the signed max and min over every step of the run's
                                         E(t), and G + max E, G + min E (attribute ``combination``)
  forces/<part>_cells       (E,)         each element's index in the XDMF topology
  forces/<part>_nodes       (E, n)       its nodes (0-based, the ``coordinates`` rows)
  forces/snapshots, forces/time          the snapshot indices k of the K rows and their times
  cell_peak_<component>     (n_cells,)   the envelope as a cell field over every cell of the
                                         topology (frames: max over both ends, e.g. peak_M3;
                                         NaN on cells without that component); in the XDMF as
                                         Center="Cell" attributes of every time step

with c = 12 (frames) or 8 (shells), E the part's elements in the order of its cell blocks. The
elements are split over the ranks in contiguous ranges (PETSc's default split); each rank
computes its own from one scatter of the displacement Vec per step (the dofs of its elements), as
one batched product with operators built once (``einsum``).
"""
import numpy as np

from ..petsc import init, SSIError
from .elements.frame import END_FORCES, END_FORCE_UNITS
from .elements.shell import RESULTANTS, RESULTANT_UNITS, resultant_operator

KINDS = ("frame", "shell")
COMBINATION = ("G + max_t E(t) and G + min_t E(t), component by component: G the static self-weight case "
               "(-ssi_fem_gravity, K u_G = -g M e_z with the fixed dofs held), E(t) the run's dynamic response "
               "(increments from the unloaded state; every step, t = 0 at rest included); linear superposition, "
               "factors 1")

FRAME_CONVENTION = ("end forces the nodes exert on the element, local axes (x' node 0 -> node 1, z' the "
                    "orientation vector normal to x', y' = z' x x'), f = k_local T u_e, no member inertia "
                    "(OpenSees localForce); stress resultants: -f_i at node 0, +f_j at node 1 (N > 0 tension, "
                    "M2 > 0 stretches +z', M3 > 0 compresses +y')")
SHELL_CONVENTION = ("stress resultants at the element centre in its local frame (e1, e2 in the mean plane, e3 "
                    "normal): N = int sigma dz, M = int sigma z dz (M11 > 0 stretches the +e3 fibre), "
                    "Q = int sigma_a3 dz")


def parse_force_parts(text, specs):
    """The part names of ``-ssi_structure_forces`` (comma list or 'all': every frame and shell part)
    given the parsed parts (``fem.parts.PartSpec``); '' or 'none': []. SSIError (one line) for an
    unknown part or a part that is not a frame or shell part. Replicated."""
    words = [w.strip() for w in str(text or "").split(",") if w.strip()]
    if not words or words == ["none"]:
        return []
    kinds = {s.name: s.element for s in specs}
    if words == ["all"]:
        names = [s.name for s in specs if s.element in KINDS]
        if not names:
            raise SSIError("-ssi_structure_forces all: the structure has no frame or shell part "
                           f"(parts: {', '.join(f'{n} ({k})' for n, k in kinds.items())})")
        return names
    for w in words:
        if w not in kinds:
            import difflib
            near = difflib.get_close_matches(w, list(kinds), n=1)
            raise SSIError(f"-ssi_structure_forces: no part '{w}' (parts: {', '.join(kinds)})"
                           + (f"; did you mean {near[0]}?" if near else ""))
        if kinds[w] not in KINDS:
            raise SSIError(f"-ssi_structure_forces: part '{w}' is a {kinds[w]} part; member forces are "
                           "computed for frame and shell parts only")
    if len(set(words)) != len(words):
        raise SSIError(f"-ssi_structure_forces '{text}': a part is named twice")
    return words


def _split(n, size):
    counts = np.full(size, n // size, np.int64)
    counts[: n % size] += 1
    return np.r_[0, np.cumsum(counts)]


class _Part:
    """One part's elements on this rank: operators (E_loc, c, nd), dof positions, Vecs."""

    def __init__(self, name, blocks, offsets, mesh, dofmap, comm):
        PETSc = init()
        self.name = name
        self.kind = blocks[0].element.name
        self.components = END_FORCES if self.kind == "frame" else RESULTANTS
        self.units = END_FORCE_UNITS if self.kind == "frame" else RESULTANT_UNITS
        self.c = len(self.components)
        self.cells = np.concatenate([b.cells for b in blocks])             # replicated
        self.cell_index = np.concatenate([o + np.arange(b.cells.shape[0]) for b, o in zip(blocks, offsets)])
        n = self.cells.shape[0]
        b = _split(n, comm.getSize())
        self.e0, self.e1 = int(b[comm.getRank()]), int(b[comm.getRank() + 1])
        ops, dofs, start = [], [], 0
        for blk in blocks:
            lo, hi = max(self.e0 - start, 0), min(self.e1 - start, blk.cells.shape[0])
            start += blk.cells.shape[0]
            if hi <= lo:
                continue
            c = blk.cells[lo:hi]
            X = mesh.coords[c]
            if self.kind == "frame":
                ops.append(blk.element.end_force_operator(X, blk.props))
            else:
                ops.append(resultant_operator(X, blk.props)[:, 0])
            dofs.append(dofmap.cell_dofs(c, blk.element.dof_names, blk.props.released))
        nd = 6 * blocks[0].element.nodes_per_cell
        self.G = np.concatenate(ops) if ops else np.zeros((0, self.c, nd))
        self.dofs = np.concatenate(dofs) if dofs else np.zeros((0, nd), np.int64)
        self.vec = PETSc.Vec().createMPI(((self.e1 - self.e0) * self.c, n * self.c), bsize=self.c, comm=comm)
        self.env_vec = self.vec.duplicate()          # the envelope's Vec, filled when written or saved
        self.env = np.zeros((self.e1 - self.e0, self.c))
        self.value = np.zeros((self.e1 - self.e0, self.c))
        self.gravity = self.smax = self.smin = None          # with a gravity case (``ForceRecorder.set_gravity``)

    def attrs(self):
        return {"unit": ",".join(self.units),
                "components": ",".join(self.components), "element": self.kind, "part": self.name,
                "convention": FRAME_CONVENTION if self.kind == "frame" else SHELL_CONVENTION}

    def peaks(self, env):
        """[(component, unit, (E,) peak)] of the cell fields: frames max over both ends."""
        if self.kind == "frame":
            return [(self.components[k][:-2], self.units[k], np.maximum(env[:, k], env[:, 6 + k]),
                     " and both ends of the frame element") for k in range(6)]
        return [(self.components[k], self.units[k], env[:, k], " at the shell element's centre") for k in range(self.c)]


class ForceRecorder:
    """Collective: an observer of the recorder (``io.recorder``): the member forces of ``parts``
    (names of frame and shell parts) of ``model`` every step (the envelope), written with the
    structure's snapshots into ``out`` (the structure's Output, which calls back at flush and
    close: ``write_collective``, ``write_serial``)."""

    def __init__(self, out, model, comm, parts):
        PETSc = init()
        self.out, self.comm = out, comm
        mesh, dm = model.mesh, model.dofmap
        offsets = np.r_[0, np.cumsum([b.cells.shape[0] for b in mesh.blocks])]
        self.parts = []
        for name in parts:
            sel = [i for i, b in enumerate(mesh.blocks) if b.part == name]
            self.parts.append(_Part(name, [mesh.blocks[i] for i in sel], offsets[sel], mesh, dm, comm))
        self.n_cells = int(offsets[-1])
        alld = np.concatenate([p.dofs.ravel() for p in self.parts]) if self.parts else np.zeros(0, np.int64)
        need = np.unique(alld)
        for p in self.parts:
            p.pos = np.searchsorted(need, p.dofs)
        self.seq = PETSc.Vec().createSeq(len(need), comm=PETSc.COMM_SELF)
        iset = PETSc.IS().createGeneral(need.astype(PETSc.IntType), comm=PETSc.COMM_SELF)
        template = dm.vec()
        self.scatter = PETSc.Scatter().create(template, iset, self.seq, None)
        template.destroy()
        iset.destroy()
        self.snapshots, self.times = [], []           # the output snapshots k with forces, their times
        if out is not None:
            out.writers.append(self)

    # ------------------------------------------------------------ the recorder's protocol
    def initial(self, t, step, write=False):
        if step.get("structure") is not None:
            self.record(t, step["structure"][0], write=write)

    def observe(self, n, t, step):
        if step.get("structure") is not None:
            self.compute(step["structure"][0])

    def snapshot(self, n, t, step):
        if step.get("structure") is not None:
            self.write(t)

    def record(self, t, u, write=False):
        """Collective: the forces of the displacement Vec u (dof layout) into the envelope; with
        ``write`` also into the output (the structure's snapshot of time t must be written)."""
        self.compute(u)
        if write:
            self.write(t)

    def state(self, n_times=None):
        return {"forces_snapshots": np.asarray(self.snapshots, np.int64),
                "forces_times": np.asarray(self.times, float)}

    def restore(self, s, n=None):
        self.snapshots = [int(k) for k in s["forces_snapshots"]]
        self.times = [float(t) for t in s["forces_times"]]

    def set_gravity(self, u):
        """Collective: the gravity case's displacement Vec ``u`` (``fem.gravity``): its forces G are
        kept, and from now on the signed max and min of every step's forces (combined with G at the
        output: G + max, G + min)."""
        self.scatter.scatter(u, self.seq)
        a = self.seq.getArray(readonly=True)
        for p in self.parts:
            p.gravity = np.einsum("ecd,ed->ec", p.G, a[p.pos])
            p.smax = np.full_like(p.env, -np.inf)
            p.smin = np.full_like(p.env, np.inf)
            p.ext_vecs = {w: p.env_vec.duplicate() for w in ("max", "min", "gravity")}

    def _extreme_vecs(self, with_gravity=True):
        """{name: Vec} of the signed extremes (and the gravity forces), the Vecs filled."""
        out = {}
        for p in self.parts:
            if p.gravity is None:
                continue
            for what, arr in (("max", p.smax), ("min", p.smin)) + ((("gravity", p.gravity),) if with_gravity else ()):
                v = p.ext_vecs[what]
                v.getArray()[:] = arr.ravel()
                out[f"forces_{what}_{p.name}"] = v
        return out

    def _envelope_vecs(self):
        """{name: Vec} of the envelopes, the Vecs filled (no view into a Vec's array is kept: a
        load may replace it)."""
        for p in self.parts:
            p.env_vec.getArray()[:] = p.env.ravel()
        return {f"forces_envelope_{p.name}": p.env_vec for p in self.parts}

    def checkpoint_vecs(self):
        """{name: Vec}: the envelopes (saved by the checkpoint globally: any rank count restarts),
        and with a gravity case the signed extremes (G itself is solved again on a restart)."""
        out = self._envelope_vecs()
        out.update(self._extreme_vecs(with_gravity=False))
        return out

    def restore_vecs(self, reader):
        for p in self.parts:
            reader.load(f"forces_envelope_{p.name}", p.env_vec)
            p.env[:] = p.env_vec.getArray(readonly=True).reshape(-1, p.c)
            if p.gravity is not None:
                for what, arr in (("max", p.smax), ("min", p.smin)):
                    v = p.ext_vecs[what]
                    reader.load(f"forces_{what}_{p.name}", v)
                    arr[:] = v.getArray(readonly=True).reshape(-1, p.c)

    # ------------------------------------------------------------ work
    def compute(self, u):
        """Collective (one scatter): every part's forces of u, and the envelope updated."""
        self.scatter.scatter(u, self.seq)
        a = self.seq.getArray(readonly=True)
        for p in self.parts:
            np.einsum("ecd,ed->ec", p.G, a[p.pos], out=p.value)
            np.maximum(p.env, np.abs(p.value), out=p.env)
            if p.gravity is not None:
                np.maximum(p.smax, p.value, out=p.smax)
                np.minimum(p.smin, p.value, out=p.smin)

    def write(self, t):
        """Collective: the last computed forces as the snapshot the structure's output just wrote
        (its index and time)."""
        out = self.out
        if out is None or not out.times or out.times[-1] != float(t):
            return
        k = len(out.times) - 1
        vecs = {}
        for p in self.parts:
            p.vec.getArray()[:] = p.value.ravel()
            vecs[f"forces_{p.name}_{k:06d}"] = p.vec
        out.write_vecs(vecs, f"snapshot {k} (t = {t:.6g} s): member forces")
        if self.snapshots and self.snapshots[-1] == k:
            return
        self.snapshots.append(k)
        self.times.append(float(t))

    # ------------------------------------------------------------ Output's call-backs
    def write_collective(self, out):
        """Collective, before the output closes its viewer: the envelopes (and the gravity case's
        forces and the signed extremes)."""
        out.write_vecs(self._envelope_vecs(), "member force envelopes")
        ext = self._extreme_vecs()
        if ext:
            out.write_vecs(ext, "member forces of gravity and the signed extremes")

    def write_serial(self, f):
        """Rank 0, the file open (h5py): the 'forces' group and the cell fields; returns the XDMF
        cell attributes [(name, dataset, unit)]."""
        import h5py
        from ..io.output import new_group
        g = new_group(f, "forces")
        g.create_dataset("snapshots", data=np.asarray(self.snapshots, np.int64), track_times=False)
        d = g.create_dataset("time", data=np.asarray(self.times, float), track_times=False)
        d.attrs["unit"] = "s"
        peaks = {}
        for p in self.parts:
            E = p.cells.shape[0]
            env = f[f"forces_envelope_{p.name}"][()].reshape(E, p.c)
            K = len(self.snapshots)
            if K:
                layout = h5py.VirtualLayout(shape=(K, E, p.c), dtype="f8")
                for i, k in enumerate(self.snapshots):
                    name = f"forces_{p.name}_{k:06d}"
                    layout[i] = h5py.VirtualSource(self.out.source_of(name), name, shape=(E, p.c))
                ds = _virtual(g, p.name, layout, np.nan)
            else:
                ds = g.create_dataset(p.name, shape=(0, E, p.c), dtype="f8", track_times=False)
            de = g.create_dataset(f"{p.name}_envelope", data=env, track_times=False)
            for a in (ds, de):
                for key, val in p.attrs().items():
                    a.attrs[key] = val
            de.attrs["what"] = "max over every time step of |value|"
            if p.gravity is not None:
                _gravity_datasets(f, g, p, E)
            g.create_dataset(f"{p.name}_cells", data=p.cell_index, track_times=False)
            g.create_dataset(f"{p.name}_nodes", data=p.cells, track_times=False)
            for comp, unit, val, where in p.peaks(env):
                arr, _, _ = peaks.setdefault(comp, (np.full(self.n_cells, np.nan), unit, where))
                arr[p.cell_index] = val
        cells = []
        for comp, (arr, unit, where) in peaks.items():
            d = f.create_dataset(f"cell_peak_{comp}", data=arr, track_times=False)
            d.attrs["unit"] = unit
            d.attrs["what"] = f"peak |{comp}| over every time step{where}; NaN on cells without it"
            cells.append((f"peak_{comp}", f"cell_peak_{comp}", unit))
        return cells


def _gravity_datasets(f, g, p, E):
    """Rank 0: forces/<part>_gravity, _max, _min, _gravity_plus_max, _gravity_plus_min (fem/gravity.py)."""
    val = {w: f[f"forces_{w}_{p.name}"][()].reshape(E, p.c) for w in ("gravity", "max", "min")}
    what = {"gravity": "the static self-weight case G (-ssi_fem_gravity)",
            "max": "signed max over every time step of the run's value E(t) (t = 0 at rest included)",
            "min": "signed min over every time step of the run's value E(t) (t = 0 at rest included)",
            "gravity_plus_max": "G + max_t E(t)", "gravity_plus_min": "G + min_t E(t)"}
    val["gravity_plus_max"] = val["gravity"] + val["max"]
    val["gravity_plus_min"] = val["gravity"] + val["min"]
    for w, arr in val.items():
        d = g.create_dataset(f"{p.name}_{w}", data=arr, track_times=False)
        for key, v in p.attrs().items():
            d.attrs[key] = v
        d.attrs["what"] = what[w]
        d.attrs["combination"] = COMBINATION


def _virtual(g, name, layout, fill):
    """``g[name]``: the virtual dataset of ``layout`` created without a modification time (h5py's
    create_virtual_dataset records one: two runs' identical data gave files of other bytes, which
    -ssi_reproducible promises not to). Through h5py's low-level calls; h5py's own call where those
    are not (another h5py)."""
    import h5py
    try:
        dcpl = layout._get_dcpl(g.file.filename)
        dcpl.set_fill_value(np.array([fill]))
        dcpl.set_obj_track_times(False)
        space = h5py.h5s.create_simple(tuple(layout.shape))
        tid = h5py.h5t.py_create(np.dtype(layout.dtype), logical=1)
        return h5py.Dataset(h5py.h5d.create(g.id, name=name.encode(), tid=tid, space=space, dcpl=dcpl))
    except AttributeError:
        return g.create_virtual_dataset(name, layout, fillvalue=fill)


def add_force_recorder(cfg, out, model, comm, recorder=None):
    """Collective: the ForceRecorder of ``-ssi_structure_forces`` added to ``recorder`` (when
    given) among its recorders (``Recorder.add_recorder``), or None (no part named, or no output
    to write to)."""
    parts = parse_force_parts(cfg.get("structure_forces", ""), model.specs or [])
    if not parts:
        return None
    if out is None:
        from ..petsc import warn
        warn("-ssi_structure_forces: the run writes no output (-ssi_output is empty): no member forces", comm)
        return None
    fr = ForceRecorder(out, model, comm, parts)
    return recorder.add_recorder(fr) if recorder is not None else fr
