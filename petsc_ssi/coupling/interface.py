"""The soil-structure interface: matching nodes, normals, consistent forces.

The interface is small (n_I nodes, a few hundred) and is described here by
replicated arrays, computed identically on every rank from the replicated
meshes; the per-step data (displacements, tractions, forces) live in PETSc
Vecs and move between the FE and BE layouts through scatters and one AIJ
matrix (``force_matrix``), never through rank 0.

Conventions (paper eqs. 26-29). n_b: outward normal of the soil (+z on a
flat surface), n_f = -n_b: outward normal of the structure's base.
Interface column k (0..n_I-1) is BE node ``be_nodes[k]`` (the sorted nodes of
the interface elements: the BEM's prescribed-displacement region, whose
traction columns are n_load + k) and FE node ``fe_nodes[k]``.
Consistent nodal forces from the BE traction field p(x) = sum_j N_j(x) p_j:
    f_b,i = int_Gamma N_i p dGamma = sum_j M_ij p_j,  M_ij = int N_i N_j dGamma
(nine-node shape functions, 4 x 4 Gauss points: exact on flat elements), and
f_f = -f_b (eq. 27).
"""
import numpy as np
import scipy.sparse as sp

from ..petsc import SSIError, init
from ..mesh import quad9
from ..fem.loads import group_faces


def _fmt(points, k=3):
    return "; ".join(f"({p[0]:.4g}, {p[1]:.4g}, {p[2]:.4g})" for p in points[:k]) + \
        (f"; ... ({len(points)} in all)" if len(points) > k else "")


def fe_interface_faces(fe_mesh, groups, excavated=False):
    """Quads of the comma-separated FE groups that rest on the soil, ordered so that their
    normal points out of the structure (into the soil): brick faces as they are (outward),
    shell cells reversed (shells are oriented up: the soil is under a foundation slab).
    ``excavated``: the soil's surface has an excavation, and the groups' faces above the ground
    z = 0 (a basement's walls continuing up as the storey's) are left out: the soil touches only
    the faces below it."""
    out = []
    for name in [g.strip() for g in str(groups).split(",") if g.strip()]:
        if name in fe_mesh.shells and name not in fe_mesh.faces:
            out.append(fe_mesh.shells[name][:, [0, 3, 2, 1]])
        else:
            out.append(group_faces(fe_mesh, name, "-ssi_fem_interface"))
    quads = np.concatenate(out) if out else np.zeros((0, 4), np.int64)
    if excavated and len(quads):
        quads = quads[fe_mesh.coords[quads, 2].max(axis=1) <= ground_tol(fe_mesh)]
        if len(quads) == 0:
            raise SSIError(f"-ssi_fem_interface {groups}: none of these faces lies below the ground z = 0 (on a "
                           "surface with an excavation the soil touches the structure's faces in it)")
    if len(quads) == 0:
        raise SSIError("-ssi_fem_interface names no faces of the structure")
    return quads


def ground_tol(fe_mesh):
    """The tolerance [m] for a structure's node to lie on or below the ground z = 0: 1e-6 of the mesh's
    largest extent."""
    return 1e-6 * (float(np.ptp(fe_mesh.coords, axis=0).max()) or 1.0)


def interface_offsets(fe_mesh, iface, groups):
    """(n_I, 3) offsets r_k from each interface node of a shell slab to the slab's underside,
    r_k = -(t/2) n_k (t the shell part's thickness, n_k = n_b the soil's outward normal, i.e.
    the slab's upward normal); zero at brick nodes. SSIError if a node lies on shells of two
    thicknesses."""
    t = np.zeros(fe_mesh.n_nodes)
    for b in fe_mesh.blocks:
        if b.element.name != "shell":
            continue
        nodes = np.unique(b.cells)
        clash = (t[nodes] > 0) & (np.abs(t[nodes] - b.props.thickness) > 1e-12 * b.props.thickness)
        if clash.any():
            raise SSIError("-ssi_interface_offset: an interface node lies on shells of two thicknesses")
        t[nodes] = b.props.thickness
    return -0.5 * t[iface.fe_nodes][:, None] * iface.n_b


def _released_shell_nodes(fe_mesh, dofmap):
    """(N,) bool: nodes with a released rotation triple that belong to a released shell part."""
    on = np.zeros(dofmap.n_nodes, bool)
    for b in fe_mesh.blocks:
        if b.element.name == "shell" and b.props is not None and b.props.released:
            on[b.cells.ravel()] = True
    return on & dofmap.released


class InterfaceOperator:
    """Collective: T, the PETSc Mat (3 n_I x structure dofs) that gives the displacement of the
    soil side of the interface from the structure's dofs (built from the dof map):
        u_I,k = u_k + theta_k x r_k      (r_k = 0: translations only; the slab offset otherwise),
    so the force of the soil on the structure is T^T f_I and the structure's interface
    flexibility is T D^-1 T^T (paper eqs. 26-29 with a shell foundation slab: translations are
    coupled, rotations only through the offset). Rows are split across the ranks (PETSc's
    default); ``gather`` brings T u to every rank (3 n_I numbers), ``spread`` applies T^T to a
    replicated interface vector."""

    def __init__(self, comm, iface, dofmap, offsets=None, fe_mesh=None):
        PETSc = init()
        self.PETSc, self.comm = PETSc, comm
        n = 3 * iface.n
        self.tI = PETSc.Vec().createMPI((PETSc.DECIDE, n), comm=comm)
        r0, r1 = self.tI.getOwnershipRange()
        self.r0, self.r1 = r0, r1
        tdofs = dofmap.translation_dofs(iface.fe_nodes)              # (n_I, 3)
        rows, cols, vals = [], [], []
        for c in range(3):
            rows.append(3 * np.arange(iface.n) + c); cols.append(tdofs[:, c]); vals.append(np.ones(iface.n))
        if offsets is not None and np.any(offsets):
            has = dofmap.has_rotation[iface.fe_nodes] & (np.abs(offsets).sum(axis=1) > 0)
            k = np.nonzero(has)[0]
            # the slab's own rotations: the released triple where the slab is hinged to beams
            slab_rel = _released_shell_nodes(fe_mesh, dofmap) if fe_mesh is not None else np.zeros(dofmap.n_nodes, bool)
            nk = iface.fe_nodes[k]
            rdofs = np.where(slab_rel[nk][:, None], dofmap.rotation_dofs(nk, released=True),
                             dofmap.rotation_dofs(nk))
            # theta x r = -[r]x theta: d(u_c)/d(theta_j) = -eps_{c m j} r_m = eps_{c j m} r_m
            eps = np.zeros((3, 3, 3))
            eps[0, 1, 2] = eps[1, 2, 0] = eps[2, 0, 1] = 1.0
            eps[0, 2, 1] = eps[2, 1, 0] = eps[1, 0, 2] = -1.0
            B = np.einsum("cjm,km->kcj", eps, offsets[k])             # (k, c, j)
            for c in range(3):
                for j in range(3):
                    nz = B[:, c, j] != 0
                    rows.append(3 * k[nz] + c); cols.append(rdofs[nz, j]); vals.append(B[nz, c, j])
        R, C, V = (np.concatenate(a) for a in (rows, cols, vals))
        own = (R >= r0) & (R < r1)
        A = sp.csr_matrix((V[own], (R[own] - r0, C[own])), shape=(r1 - r0, dofmap.size))
        A.sort_indices()
        self.T = PETSc.Mat().createAIJ(size=((r1 - r0, n), (dofmap.n_local, dofmap.size)),
                                       csr=(A.indptr.astype(PETSc.IntType), A.indices.astype(PETSc.IntType),
                                            A.data), comm=comm)
        self.T.assemble()
        self.scatter, self.seq = PETSc.Scatter.toAll(self.tI)

    def gather(self, u):
        """Collective: T u on every rank (numpy, 3 n_I)."""
        self.T.mult(u, self.tI)
        self.scatter.scatter(self.tI, self.seq)
        return self.seq.getArray(readonly=True).copy()

    def spread(self, fI, out):
        """Collective: out = T^T f_I for a replicated interface vector f_I (3 n_I)."""
        self.tI.getArray()[:] = np.asarray(fI)[self.r0:self.r1]
        self.T.multTranspose(self.tI, out)
        return out

    def destroy(self):
        for o in (self.T, self.tI, self.seq, self.scatter):
            o.destroy()


def _face_normals(X):
    """Unit normals of bilinear quads X (F, 4, 3) at their centres (node order outward)."""
    n = np.cross(X[:, 2] - X[:, 0], X[:, 3] - X[:, 1])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


class Interface:
    """Replicated interface data (see the module docstring)."""

    def __init__(self, be_elems, be_nodes, fe_nodes, x, n_b, M, zero, spacing):
        self.be_elems, self.be_nodes, self.fe_nodes = be_elems, be_nodes, fe_nodes
        self.x, self.n_b, self.M, self.zero, self.spacing = x, n_b, M, zero, spacing

    @property
    def n(self):
        return len(self.be_nodes)

    @property
    def n_f(self):
        return -self.n_b

    def area(self):
        return float(self.M.sum())


def build_interface(be_mesh, fe_mesh, spec, fe_groups, tol_rel, planes=(), h=1.0):
    """Match the meshes (SSIError listing unmatched nodes); normals; M.

    ``spec``: 'auto', a BE group name or 'box:...'. ``planes``: symmetry planes
    (the DOFs they force to zero are flagged in ``zero``, shape (n_I, 3)). On a soil surface with
    an excavation the structure's faces below the ground are matched (walls and bottom)."""
    from scipy.spatial import cKDTree
    quads = fe_interface_faces(fe_mesh, fe_groups, excavated=not be_mesh.flat)
    fnodes = np.unique(quads)
    xf = fe_mesh.coords[fnodes]
    edges = np.concatenate([quads[:, [0, 1]], quads[:, [1, 2]]])
    spacing = float(np.linalg.norm(fe_mesh.coords[edges[:, 0]] - fe_mesh.coords[edges[:, 1]], axis=1).min())
    tol = tol_rel * spacing
    tree = cKDTree(xf)
    xb_all = be_mesh.nodes
    d_all, i_all = tree.query(xb_all)
    on_fe = d_all <= tol
    if spec == "auto":
        elems = np.nonzero(on_fe[be_mesh.cells].all(axis=1))[0]
        if elems.size == 0:
            n_on = int(on_fe.sum())
            at = np.unique(i_all[on_fe]).size
            es = float(np.min(be_mesh.element_sizes()))       # (a node-to-node segment: half an element's side)
            raise SSIError(f"-ssi_interface auto: no soil element has all nine nodes on the structure's "
                           f"'{fe_groups}' faces: {n_on} soil node(s) lie on them (within {tol:.3g} m), at {at} of "
                           f"their {len(fnodes)} nodes (the soil's smallest element {2 * es:.3g} m, its nodes {es:.3g} "
                           f"m apart; the faces' nodes {spacing:.3g} m); every node of a soil element under the "
                           "structure must be one of its base nodes")
    else:
        elems = np.asarray(be_mesh.select(spec), np.int64)
    bnodes = np.unique(be_mesh.cells[elems])
    miss_b = bnodes[~on_fe[bnodes]]
    if miss_b.size:
        raise SSIError(f"interface: {miss_b.size} soil node(s) of -ssi_interface {spec} match no node of the "
                       f"structure's '{fe_groups}' faces within {tol:.3g} m: {_fmt(xb_all[miss_b])}")
    match = i_all[bnodes]
    if len(np.unique(match)) != len(match):
        raise SSIError(f"interface: two soil nodes match the same structure node (tolerance {tol:.3g} m "
                       "too large? -ssi_interface_tol)")
    hit = np.zeros(len(fnodes), bool)
    hit[match] = True
    if not hit.all():
        raise SSIError(f"interface: {int((~hit).sum())} node(s) of the structure's '{fe_groups}' faces match no "
                       f"soil node of the interface elements within {tol:.3g} m: {_fmt(xf[~hit])} (the soil's "
                       "nodes are every half element side: the mesh log's element sides, e.g. an excavation's walls "
                       "take a whole number of elements of about -ssi_mesh_h)")
    fe_nodes = fnodes[match]
    x = xb_all[bnodes]
    # normals: soil (nine-node geometry at the nodes, averaged) and structure (faces, averaged)
    lut = -np.ones(be_mesh.n_nodes, np.int64)
    lut[bnodes] = np.arange(len(bnodes))
    X = be_mesh.cell_coords()[elems]
    xi = quad9.NODE_XI
    _, jn = quad9.geometry(X[:, None, :, :], xi[None, :, 0], xi[None, :, 1])
    jn = jn / np.linalg.norm(jn, axis=-1, keepdims=True)
    nb = np.zeros((len(bnodes), 3))
    np.add.at(nb, lut[be_mesh.cells[elems]].ravel(), jn.reshape(-1, 3))
    nb /= np.linalg.norm(nb, axis=1, keepdims=True)
    fl = -np.ones(fe_mesh.n_nodes, np.int64)
    fl[fe_nodes] = np.arange(len(fe_nodes))
    fn = np.zeros((len(bnodes), 3))
    np.add.at(fn, fl[quads].ravel(), np.repeat(_face_normals(fe_mesh.coords[quads]), 4, axis=0))
    fn /= np.linalg.norm(fn, axis=1, keepdims=True)
    cosang = np.einsum("ij,ij->i", nb, fn)
    if np.any(cosang > -0.999):
        bad = np.nonzero(cosang > -0.999)[0]
        raise SSIError(f"interface: the soil and structure normals are not opposite at {bad.size} node(s) "
                       f"(e.g. {_fmt(x[bad], 1)}): is -ssi_fem_interface the face that rests on the soil?")
    M = mass_matrix(X, lut[be_mesh.cells[elems]], len(bnodes))
    zero = np.zeros((len(bnodes), 3), bool)
    for ax, kind in planes:
        on = np.abs(x[:, ax]) <= 1e-9 * max(h, 1.0)
        if kind > 0:
            zero[on, ax] = True
        else:
            zero[np.ix_(on, [c for c in range(3) if c != ax])] = True
    return Interface(elems, bnodes, fe_nodes, x, nb, M, zero, spacing)


def mass_matrix(X, conn, n, order=4):
    """M_ij = int N_i N_j dGamma over nine-node elements X (E, 9, 3) with local
    node numbers conn (E, 9): scipy CSR (n, n)."""
    g, w = np.polynomial.legendre.leggauss(order)
    xi, eta = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    ww = np.outer(w, w).ravel()
    N = quad9.shape(xi, eta)                                     # (P, 9)
    _, jn = quad9.geometry(X, xi, eta)                           # (E, P, 3)
    J = np.linalg.norm(jn, axis=-1) * ww                         # (E, P)
    Me = np.einsum("ep,pa,pb->eab", J, N, N)
    r = np.repeat(conn, 9, axis=1).ravel()
    c = np.tile(conn, (1, 9)).ravel()
    return sp.csr_matrix((Me.ravel(), (r, c)), shape=(n, n))


def fem_symmetry_dofs(fe_mesh, planes, tol=1e-9, dofmap=None):
    """FE DOFs a symmetry plane fixes: on x_a = 0, u_a and the rotations about the two
    other axes (sym), or the two other translations and the rotation about a (anti);
    rotations only where the nodes have them. SSIError if the structure extends to x_a < 0, or has a node
    nearer the plane than 1e-6 of its extent but not on it (within tol of it): a structure meant to reach the
    plane whose node there would be left free (as ``bem.symmetry.check_mesh`` for the soil)."""
    from ..fem.dofmap import DofMap, TRANSLATIONS, ROTATIONS
    from ..bem.symmetry import plane_tol
    dm = dofmap if dofmap is not None else DofMap(fe_mesh.has_rotation())
    out = []
    h = float(np.abs(fe_mesh.coords).max())
    t = plane_tol(h, tol)                   # (on the plane within t; h here the structure's extent)
    for ax, kind in planes:
        x = fe_mesh.coords[:, ax]
        if x.min() < -t * 1e3:
            raise SSIError(f"-ssi_symmetry: the structure's mesh extends to {'xy'[ax]} = {x.min():.4g} < 0; "
                           f"with a symmetry plane {'xy'[ax]} = 0 mesh only the part {'xy'[ax]} >= 0")
        on = np.nonzero(np.abs(x) <= t)[0]
        near = np.nonzero((np.abs(x) > t) & (np.abs(x) <= t * 1e3))[0]
        if len(near):
            k = int(near[np.argmin(np.abs(x[near]))])
            at = ", ".join(f"{c:.6g}" for c in fe_mesh.coords[k])
            raise SSIError(f"-ssi_symmetry: the structure's node {k} at ({at}) m lies {x[k]:.3g} m off the plane "
                           f"{'xy'[ax]} = 0, nearer than 1e-6 of the structure's extent but not on it (within "
                           f"{t:.3g} m; {len(near)} such node(s)): put them on the plane or away from it")
        others = [c for c in range(3) if c != ax]
        names = ([TRANSLATIONS[ax]] + [ROTATIONS[c] for c in others] if kind > 0 else
                 [TRANSLATIONS[c] for c in others] + [ROTATIONS[ax]])
        out.append(dm.dofs(on, names, all_rotations=True))
    return np.unique(np.concatenate(out)) if out else np.zeros(0, np.int64)


def force_matrix(comm, iface, fe_layout_vec, n_load, p_vec, dofmap, skip=()):
    """Collective: AIJ F with f_f = F p: rows in the FE layout (the translations of the
    interface nodes, from the dof map), columns the BE traction vector (columns
    3 (n_load + k) + c), entries -M (eq. 27). Rows of the FE DOFs ``skip`` (fixed ones)
    are left empty."""
    PETSc = init()
    r0, r1 = fe_layout_vec.getOwnershipRange()
    M = iface.M.tocoo()
    tdofs = dofmap.translation_dofs(iface.fe_nodes)
    cols_all = 3 * (n_load + M.col)
    R, C, V = [], [], []
    for c in range(3):
        R.append(tdofs[M.row, c]); C.append(cols_all + c); V.append(-M.data)
    R = np.concatenate(R); C = np.concatenate(C); V = np.concatenate(V)
    own = (R >= r0) & (R < r1) & ~np.isin(R, np.asarray(skip, np.int64))
    A = sp.csr_matrix((V[own], (R[own] - r0, C[own])), shape=(r1 - r0, p_vec.getSize()))
    A.sort_indices()
    F = PETSc.Mat().createAIJ(size=((r1 - r0, fe_layout_vec.getSize()), (p_vec.getLocalSize(), p_vec.getSize())),
                              csr=(A.indptr.astype(PETSc.IntType), A.indices.astype(PETSc.IntType), A.data),
                              comm=comm)
    F.assemble()
    return F
