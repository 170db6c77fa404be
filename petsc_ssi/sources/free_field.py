"""The free field's traction on the faces of an excavation, as a source of the scattered field (issue 42,
item 3).

The soil carries the scattered field u_sc = u - u_ff (``seismic.input``). On the flat free surface the
free field is traction-free, t_ff = sigma_ff n = 0, so a plane surface needs no source. On an
excavation's walls and bottom it is not: the total traction there is zero (a free face), so the
scattered field's traction is

    t_sc = -t_ff = -sigma_ff(x, t) n(x),

a known traction on those faces. Its step mean over ((m-1) dt, m dt] is exact: the free field's stress
has a running time integral in closed form (``SeismicInput.traction_integral``), and the mean is the
difference of two values over dt.

The soil's tractions are nodal values, continuous over the loaded region (``bem.lagset.Regions``); at an
edge of the excavation (a wall meeting the bottom, two walls meeting) the faces' normals differ and so
does t_ff. A node takes the traction of its tributary faces' summed vector area,

    n_a = sum_e int_e N_a n dGamma / sum_e int_e N_a dGamma,

which keeps the node's consistent force (int N_a t dGamma over its elements) for a stress uniform
near it; its length is below 1 at an edge (1/sqrt(2) where two faces meet at a right angle). The
traction jumps there in truth, which this continuous interpolation smears over one element: the
error falls with the element size.
"""
import numpy as np

from ..mesh import quad9


def vector_areas(mesh, elements, nodes, order=4):
    """(n_a (k, 3), w_a (k,)): sum over ``elements`` of int N_a n dGamma and int N_a dGamma [m^2] at each
    of ``nodes`` (sorted ids); Gauss rule of ``order`` points a direction."""
    g, w = np.polynomial.legendre.leggauss(order)
    XI, ETA = np.meshgrid(g, g, indexing="ij")
    W = np.outer(w, w).ravel()
    X = mesh.cell_coords()[elements]                                  # (e, 9, 3)
    _, jn = quad9.geometry(X, XI.ravel(), ETA.ravel())                # (e, q, 3)
    N = np.array([quad9.shape(a, b) for a, b in zip(XI.ravel(), ETA.ravel())])    # (q, 9)
    vec = np.einsum("q,qa,eqd->ead", W, N, jn)
    area = np.einsum("q,qa,eq->ea", W, N, np.linalg.norm(jn, axis=-1))
    idx = np.searchsorted(nodes, mesh.cells[elements])
    nv, na = np.zeros((len(nodes), 3)), np.zeros(len(nodes))
    np.add.at(nv, idx.ravel(), vec.reshape(-1, 3))
    np.add.at(na, idx.ravel(), area.ravel())
    return nv, na


class FreeFieldTraction:
    """-t_ff = -sigma_ff n on ``elements`` (an excavation's free faces): the surface-traction protocol
    (``petsc_ssi.sources``), its wave given by ``attach`` once the seismic input is made (before the
    first step)."""

    def __init__(self, elements, name="free-field traction on the excavation"):
        self.elements = np.unique(np.asarray(elements, np.int64))
        self.name = name
        self.seismic = None
        self.idx = self._x = self._n = None

    def nodes(self, mesh):
        return np.unique(mesh.cells[self.elements]) if self.elements.size else np.zeros(0, np.int64)

    def bind(self, mesh, region_nodes):
        own = self.nodes(mesh)
        self.idx = np.searchsorted(region_nodes, own)
        nv, na = vector_areas(mesh, self.elements, own)
        self._x = mesh.nodes[own].copy()
        self._n = nv / na[:, None]
        return self.idx

    def attach(self, seismic):
        """The seismic input (``seismic.input.SeismicInput``) whose free field this source cancels."""
        self.seismic = seismic

    def normals(self):
        """The nodes' effective normals (k, 3) (module docstring; unit on a face, shorter at an edge)."""
        return self._n

    def step_mean(self, m, dt):
        """-t_ff (k, 3) [Pa] at this source's nodes, the exact mean over ((m-1) dt, m dt]."""
        if self.seismic is None:
            raise RuntimeError("FreeFieldTraction: no seismic input attached")
        I = self.seismic.traction_integral
        return -(I(self._x, self._n, m * dt) - I(self._x, self._n, (m - 1) * dt)) / dt

    def amplitudes(self, at=None):
        """None given ahead (the wave sets them): no distinct vectors to check against symmetry planes
        (a surface with an excavation takes none)."""
        return np.zeros((0, 3))

    def describe(self):
        return (f"{self.name}: {self.elements.size} elements (walls and bottoms), traction -sigma_ff n of the "
                "seismic input")


class InterfaceFreeField:
    """The free field's traction t_ff = sigma_ff n on a coupled structure's faces below the ground (walls and
    bottom of an excavation), for the structure's side of the interface.

    The structure takes the consistent force of the total traction, f_a = -int N_a (t_sc + t_ff) dGamma. The
    free field's share is integrated element by element with each face's own normal,

        b_a = sum_e int_e N_a sigma_ff(x) n_e dGamma     (Gauss rule of ``order`` points a direction),

    so that the jump of t_ff at an edge (a wall meeting the bottom) stays where it is; its nodal
    traction is the L2 projection p_ff = M^-1 b on the interface's continuous nine-node field (M the
    interface's consistent mass matrix, ``coupling.interface``), for which M p_ff = b exactly (with symmetry
    planes: on the dofs they leave free, those they fix held at zero). (The
    nodal values at the nodes' mean normals, as ``FreeFieldTraction`` takes on free faces, would give
    M p_ff != b near an edge: the soil's scattered traction then makes up the difference, a
    self-equilibrated traction near the edges as large as t_ff that does not fall with the mesh.)
    Step means over ((m-1) dt, m dt] are exact, from the free field's running stress integral."""

    def __init__(self, mesh, elements, nodes, M, zero=None, order=4):
        import scipy.sparse.linalg as sla
        g, w = np.polynomial.legendre.leggauss(order)
        XI, ETA = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
        X = mesh.cell_coords()[np.asarray(elements, np.int64)]           # (e, 9, 3)
        x, jn = quad9.geometry(X, XI, ETA)                                # (e, q, 3) each
        N = quad9.shape(XI, ETA)                                          # (q, 9)
        self._x = x.reshape(-1, 3)
        self._jw = (jn * np.outer(w, w).ravel()[None, :, None]).reshape(-1, 3)   # n J w at each point
        # b_a = sum over points of N_a(q) (traction integral with the weighted normal at q)
        rows = np.searchsorted(nodes, mesh.cells[np.asarray(elements, np.int64)])          # (e, 9)
        e, q = X.shape[0], len(XI)
        import scipy.sparse as sp
        self._P = sp.csr_matrix((np.tile(N, (e, 1)).ravel(),
                                 (np.repeat(rows, q, axis=0).ravel(),
                                  np.repeat(np.arange(e * q), 9))), shape=(len(nodes), e * q))
        # per component, the projection on the dofs a symmetry plane leaves free (``zero``: (k, 3), the
        # interface's; the full model's p_ff vanishes on those by symmetry, and the modelled part's M p_ff = b
        # holds on the others only with them held at zero)
        self._zero = np.zeros((len(nodes), 3), bool) if zero is None else np.asarray(zero, bool)
        M = sp.csr_matrix(M)
        self._lu = []
        for c in range(3):
            free = np.flatnonzero(~self._zero[:, c])
            self._lu.append((free, sla.splu(sp.csc_matrix(M[free][:, free])) if free.size else None))
        self.seismic = None

    def attach(self, seismic):
        """The seismic input (``seismic.input.SeismicInput``) whose free field this is."""
        self.seismic = seismic

    def force(self, m, dt):
        """b (k, 3) [N]: int N_a t_ff dGamma at the interface nodes, the exact mean over ((m-1) dt, m dt]."""
        I = self.seismic.traction_integral
        T = (I(self._x, self._jw, m * dt) - I(self._x, self._jw, (m - 1) * dt)) / dt
        return np.asarray(self._P @ T)

    def step_mean(self, m, dt):
        """p_ff = M^-1 b (k, 3) [Pa]: the nodal traction whose consistent force is b."""
        b = self.force(m, dt)
        out = np.zeros_like(b)
        for c, (free, lu) in enumerate(self._lu):
            if lu is not None:
                out[free, c] = lu.solve(np.ascontiguousarray(b[free, c]))
        return out
