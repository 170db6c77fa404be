"""The structure's dof map: which dofs each node carries, where they are, who owns them.

Every node carries the translations ux, uy, uz (field 0, "displacement");
nodes touched by a frame or shell also carry the rotations rx, ry, rz
(field 1, "rotation": small rotations about the global axes). The map is a
PETSc Section over the replicated mesh (chart = nodes, two fields), so a
node's dofs are contiguous (translations first) and its offset is
``section.getOffset(node)`` (PyLith's solution subfields on a section).

Ownership is by node: rank r owns the nodes [n0, n1) and exactly their dofs
[r0, r1), so a 6-dof node is never split between ranks. Nodes with 3 dofs
only (hex8 models) are split like PETSc's default split of 3N dofs with block
size 3 (N // p nodes, the first N % p ranks one more): a hex8 model numbers
and distributes its dofs exactly as before the dof map existed. With
rotations, the node ranges are chosen so the dof counts are balanced. Every
node's dof count is a multiple of 3 and its offset too, so matrices and
vectors keep block size 3.

Released joints: a part with ``-ssi_fem_part_NAME_release rotations`` is
hinged to the other rotational parts at the nodes they share (a slab simply
supported on its beams): such a node carries a second rotation triple (field
2, "released_rotation", local dofs 6-8) used by the released parts' cells,
while its translations stay one set shared by all (the tie is exact: the same
dofs). Released parts are joined to each other by that second triple. Node
rotations (output, receivers, point moments) are the first triple, the
rotations of the parts that are not released; fixing a rotation by name fixes
both triples.

Fixed dofs are recorded as constraint dofs of the section
(``setConstraintDof``/``setConstraintIndices``, local indices within the
node's dofs) and returned by ``fixed``.

Everything here is replicated numpy except ``vec``/``nodal_vec`` (PETSc Vecs
in the owned layout) and ``near_null_space`` (collective).
"""
import numpy as np

from ..petsc import init, SSIError

TRANSLATIONS = ("ux", "uy", "uz")
ROTATIONS = ("rx", "ry", "rz")
DOF_NAMES = TRANSLATIONS + ROTATIONS


def _uniform_split(n, size):
    """PETSc's split of n items over ``size`` ranks: boundaries (size + 1,)."""
    counts = np.full(size, n // size, np.int64)
    counts[: n % size] += 1
    return np.r_[0, np.cumsum(counts)]


def _balanced_split(ndof, size):
    """Node boundaries (size + 1,) with about equal dof counts per rank."""
    c = np.r_[0, np.cumsum(ndof)]
    total = c[-1]
    b = np.searchsorted(c, np.arange(size + 1) * total / size, side="left")
    b[0], b[-1] = 0, len(ndof)
    return np.maximum.accumulate(b)


class DofMap:
    """Collective constructor: dofs per node (3 or 6) -> offsets and ownership on ``comm``."""

    def __init__(self, has_rotation, comm=None, released=None):
        PETSc = init()
        comm = PETSc.COMM_SELF if comm is None else comm
        self.comm = comm
        self.has_rotation = np.asarray(has_rotation, bool)
        n = self.has_rotation.size
        self.n_nodes = n
        self.released = np.zeros(n, bool) if released is None else np.asarray(released, bool)
        if self.released.shape != (n,) or np.any(self.released & ~self.has_rotation):
            raise SSIError("internal error: released rotations at nodes without rotations")
        self.ndof = (3 + 3 * self.has_rotation + 3 * self.released).astype(np.int64)
        self.section = sec = self._section({})
        self.offset = np.array([sec.getOffset(p) for p in range(n)], np.int64) if n else np.zeros(0, np.int64)
        self.size = int(sec.getStorageSize())
        size, rank = comm.getSize(), comm.getRank()
        bounds = _uniform_split(n, size) if not self.has_rotation.any() else _balanced_split(self.ndof, size)
        self.node_bounds = bounds
        self.n0, self.n1 = int(bounds[rank]), int(bounds[rank + 1])
        ends = np.r_[self.offset, self.size]
        self.dof_bounds = ends[bounds]
        self.r0, self.r1 = int(self.dof_bounds[rank]), int(self.dof_bounds[rank + 1])
        self._fixed = np.zeros(0, np.int64)

    def _section(self, constraints):
        """The PETSc Section of the map; ``constraints``: {node: local dof indices fixed}
        (constraint dofs are set before setUp, their indices after)."""
        PETSc = init()
        sec = PETSc.Section().create(comm=PETSc.COMM_SELF)
        nf = 3 if self.released.any() else 2
        sec.setNumFields(nf)
        for f, name in enumerate(("displacement", "rotation", "released_rotation")[:nf]):
            sec.setFieldName(f, name)
            sec.setFieldComponents(f, 3)
        sec.setChart(0, self.n_nodes)
        for p in range(self.n_nodes):
            sec.setDof(p, int(self.ndof[p]))
            sec.setFieldDof(p, 0, 3)
            sec.setFieldDof(p, 1, 3 if self.has_rotation[p] else 0)
            if nf == 3:
                sec.setFieldDof(p, 2, 3 if self.released[p] else 0)
        for p, loc in constraints.items():
            sec.setConstraintDof(int(p), len(loc))
            for f in range(nf):
                sec.setFieldConstraintDof(int(p), f, int(np.sum((loc >= 3 * f) & (loc < 3 * f + 3))))
        sec.setUp()
        for p, loc in constraints.items():
            sec.setConstraintIndices(int(p), loc.astype(PETSc.IntType))
        return sec

    # ------------------------------------------------------------ sizes
    @property
    def n_local(self):
        return self.r1 - self.r0

    @property
    def uniform3(self):
        """True when no node carries rotations (a hex8-only model)."""
        return not self.has_rotation.any()

    def vec(self):
        """Collective: a zero Vec in the owned layout (block size 3)."""
        PETSc = init()
        v = PETSc.Vec().createMPI((self.n_local, self.size), bsize=3, comm=self.comm)
        v.zeroEntries()
        return v

    # ------------------------------------------------------------ dofs
    def dof_index(self, name):
        if name not in DOF_NAMES:
            import difflib
            near = difflib.get_close_matches(name, DOF_NAMES, n=1)
            raise SSIError(f"unknown dof name '{name}' (dof names: {', '.join(DOF_NAMES)})"
                           + (f"; did you mean {near[0]}?" if near else ""))
        return DOF_NAMES.index(name)

    def dofs(self, nodes, names=DOF_NAMES, where_present=True, all_rotations=False):
        """Global dofs of ``nodes`` for the dof ``names`` (flat, node-major).

        Rotation names at nodes without rotations are skipped when
        ``where_present`` (SSIError otherwise). A rotation name gives the node's
        first rotation triple, and with ``all_rotations`` also the released one
        (supports and symmetry planes fix both)."""
        nodes = np.asarray(nodes, np.int64).ravel()
        out = []
        for name in names:
            k = self.dof_index(name)
            sel = nodes
            if k >= 3:
                ok = self.has_rotation[nodes]
                if not where_present and not ok.all():
                    raise SSIError(f"dof {name} requested at {int((~ok).sum())} node(s) without rotations "
                                   "(nodes of bricks only)")
                sel = nodes[ok]
            out.append(self.offset[sel] + k)
            if k >= 3 and all_rotations:
                rel = sel[self.released[sel]]
                out.append(self.offset[rel] + k + 3)
        return np.concatenate(out) if out else np.zeros(0, np.int64)

    def rotation_dofs(self, nodes, released=False):
        """(n, 3) global rotation dofs of ``nodes`` (every node must carry rotations): the first
        triple, or with ``released`` the released triple where a node has one."""
        nodes = np.asarray(nodes, np.int64).ravel()
        if not self.has_rotation[nodes].all():
            raise SSIError("rotations requested at nodes of bricks only")
        base = self.offset[nodes] + 3 + (3 * self.released[nodes] if released else 0)
        return base[:, None] + np.arange(3)

    def node_dofs(self, nodes, k=3):
        """(n, k) global dofs of the first k dofs of each node (k = 3: translations;
        k = 6 needs every node to carry rotations)."""
        nodes = np.asarray(nodes, np.int64).ravel()
        if k > 3 and not self.has_rotation[nodes].all():
            raise SSIError("rotations requested at nodes of bricks only")
        return self.offset[nodes][:, None] + np.arange(k)

    def translation_dofs(self, nodes):
        return self.node_dofs(nodes, 3)

    def cell_dofs(self, cells, dof_names, released=False):
        """(E, n * len(dof_names)) global dofs of element cells (node-major, the
        element's dof order). ``released``: the cells of a released part, whose rotations at
        released nodes are the second triple."""
        cells = np.asarray(cells, np.int64)
        ks = np.array([self.dof_index(d) for d in dof_names], np.int64)
        if ks.max(initial=0) >= 3 and not self.has_rotation[cells].all():
            raise SSIError("internal error: an element with rotation dofs on nodes without rotations")
        d = self.offset[cells][:, :, None] + ks
        if released and ks.max(initial=0) >= 3:
            d = d + 3 * (self.released[cells][:, :, None] & (ks >= 3))
        return d.reshape(cells.shape[0], cells.shape[1] * len(ks))

    # ------------------------------------------------------------ constraints
    def set_fixed(self, dofs):
        """Record the fixed dofs (replicated, global) as constraint dofs of the section
        (which is rebuilt: PETSc sets constraint counts before setUp)."""
        dofs = np.unique(np.asarray(dofs, np.int64))
        if dofs.size and (dofs.min() < 0 or dofs.max() >= self.size):
            raise SSIError("internal error: fixed dof out of range")
        node = np.searchsorted(self.offset, dofs, side="right") - 1
        cons = {int(p): dofs[node == p] - self.offset[p] for p in np.unique(node)}
        self.section.destroy()
        self.section = self._section(cons)
        self._fixed = dofs
        return dofs

    @property
    def fixed(self):
        """The fixed dofs, as recorded in the section's constraints (global, sorted)."""
        return self.constrained_dofs()

    def constrained_dofs(self):
        """Global dofs of the section's constraint indices (node by node)."""
        sec = self.section
        out = [self.offset[p] + np.asarray(sec.getConstraintIndices(p), np.int64)
               for p in np.unique(np.searchsorted(self.offset, self._fixed, side="right") - 1)
               if sec.getConstraintDof(int(p))]
        return np.sort(np.concatenate(out)) if out else np.zeros(0, np.int64)

    # ------------------------------------------------------------ fields
    def nodal_array(self, values_u=None, values_r=None):
        """Replicated global dof array from (N, 3) translations and rotations
        (rotations ignored at nodes without them)."""
        out = np.zeros(self.size)
        if values_u is not None:
            out[self.node_dofs(np.arange(self.n_nodes))] = np.asarray(values_u, float)
        if values_r is not None:
            rn = np.nonzero(self.has_rotation)[0]
            out[self.offset[rn][:, None] + np.arange(3, 6)] = np.asarray(values_r, float)[rn]
        return out

    def vec_from_global(self, arr):
        """Collective: Vec holding the owned part of a replicated global dof array."""
        v = self.vec()
        v.getArray()[:] = np.asarray(arr, float)[self.r0:self.r1]
        return v

    def nodal_vec(self, values):
        """Collective: Vec from replicated (N, 3) translations (rotations zero), or from a
        replicated global dof array (size,)."""
        values = np.asarray(values, float)
        if values.ndim == 1 and values.size == self.size:
            return self.vec_from_global(values)
        return self.vec_from_global(self.nodal_array(values))

    def local_field_index(self, field):
        """Local indices (into the owned dof array) of the owned nodes' translations
        (field 0) or rotations (field 1), (n1 - n0, 3); -1 where a node has no rotations."""
        nodes = np.arange(self.n0, self.n1)
        idx = self.offset[nodes][:, None] + (np.arange(3) if field == 0 else np.arange(3, 6)) - self.r0
        if field == 1:
            idx[~self.has_rotation[nodes]] = -1
        return idx

    def node_vec(self):
        """Collective: a zero Vec of (N, 3) nodal values in the same node ownership (block
        size 3): the layout of output fields (displacement, rotation) and coordinates."""
        PETSc = init()
        v = PETSc.Vec().createMPI((3 * (self.n1 - self.n0), 3 * self.n_nodes), bsize=3, comm=self.comm)
        v.zeroEntries()
        return v

    def nodal_coords(self, coords):
        """Collective: the node coordinates as a nodal Vec (``node_vec`` layout)."""
        v = self.node_vec()
        v.getArray()[:] = np.asarray(coords, float)[self.n0:self.n1].ravel()
        return v

    def extract(self, x, out, field=0):
        """Local (no communication): copy the translations (field 0) or rotations (field 1)
        of the owned nodes of the dof-layout Vec ``x`` into the nodal Vec ``out`` (zero where
        a node has no rotations). Returns ``out``."""
        if not hasattr(self, "_fidx"):
            self._fidx = {}
        if field not in self._fidx:
            self._fidx[field] = self.local_field_index(field)
        idx = self._fidx[field]
        a = x.getArray(readonly=True)
        o = out.getArray().reshape(-1, 3)
        ok = idx >= 0
        o[:] = 0.0
        o[ok] = a[idx[ok]]
        return out

    # ------------------------------------------------------------ rigid-body modes
    def rigid_body_modes(self, coords, centre=None):
        """(size, 6) replicated: 3 translations and 3 rotations about ``centre``
        (default: the centroid), rotation dofs included (theta at every rotation dof)."""
        x = np.asarray(coords, float) - (np.mean(coords, axis=0) if centre is None else centre)
        R = np.zeros((self.size, 6))
        t = self.node_dofs(np.arange(self.n_nodes))
        for c in range(3):
            R[t[:, c], c] = 1.0
        X, Y, Z = x.T
        R[t[:, 1], 3], R[t[:, 2], 3] = -Z, Y          # about x
        R[t[:, 0], 4], R[t[:, 2], 4] = Z, -X          # about y
        R[t[:, 0], 5], R[t[:, 1], 5] = -Y, X          # about z
        rn = np.nonzero(self.has_rotation)[0]
        rel = np.nonzero(self.released)[0]
        for c in range(3):
            R[self.offset[rn] + 3 + c, 3 + c] = 1.0
            R[self.offset[rel] + 6 + c, 3 + c] = 1.0
        return R

    def restrains_rigid_motion(self, coords, fixed):
        """Whether the fixed dofs remove all six rigid-body modes (K nonsingular)."""
        fixed = np.asarray(fixed, np.int64)
        if len(fixed) == 0:
            return False
        c = np.asarray(coords, float)
        scale = max(float(np.abs(c - c.mean(axis=0)).max()), 1e-300)
        R = self.rigid_body_modes(c / scale)[fixed]
        s = np.linalg.svd(R, compute_uv=False)
        return s.size == 6 and s[-1] > 1e-8 * s[0]

    def near_null_space(self, coords):
        """Collective: PETSc NullSpace of the 6 rigid-body modes (orthonormalised) for AMG."""
        PETSc = init()
        R = self.rigid_body_modes(coords)
        Q, _ = np.linalg.qr(R)
        vecs = []
        for k in range(6):
            v = self.vec()
            v.getArray()[:] = Q[self.r0:self.r1, k]
            vecs.append(v)
        return PETSc.NullSpace().create(vectors=vecs, comm=self.comm)


class BrickDofMap(DofMap):
    """The dof map of N nodes with translations only (a model of bricks)."""

    def __init__(self, n_nodes, comm):
        super().__init__(np.zeros(int(n_nodes), bool), comm)
