"""A soil region's traction resultants (issue 12, item 1).

``-ssi_disp_group G`` prescribes on the region G the rigid motion

    u(x, t) = h(t) [u0 + theta0 x (x - x_ref)]

(``-ssi_disp_value`` u0, ``-ssi_disp_rotation`` theta0: small rotations about the axes through
``-ssi_disp_ref`` x_ref; ``-ssi_disp_history`` h; the source ``sources.rigid.PrescribedRigidMotion``,
or the massless footing's ``sources.rigid.MasslessRigidFooting``), and the run records every step the resultants
of the region's traction (the force the soil exerts... on the region, i.e. the integral of the
traction vector p that acts on the soil):

    F = int_G p dGamma,        M = int_G (x - x_ref) x p dGamma

through a small PETSc operator R (6 x 3 n_t) from the traction Vec: F = sum_k a_k p_k,
M = sum_k (b_k - a_k x_ref) x p_k with a_k = int N_k dGamma and b_k = int x N_k dGamma over the
region's elements (6 x 6 Gauss points), and with symmetry planes the images' shares folded in, so
F and M are those of the whole region. The traction of step n is its mean over (t_{n-1}, t_n]
(piecewise constant in time), the displacement h(t_n) the value at t_n.
"""
import numpy as np

from ..petsc import init, SSIError
from ..mesh import quad9
from . import symmetry


def parse_vector(text, name):
    try:
        v = np.array([float(s) for s in str(text).split(",")])
        assert v.size == 3 and np.all(np.isfinite(v))
    except (ValueError, AssertionError):
        raise SSIError(f"-ssi_{name} '{text}': expected three numbers 'x,y,z'") from None
    return v


def area_moments(mesh, elems, nodes, order=6):
    """a_k = int N_k dGamma and b_k = int x N_k dGamma over ``elems`` for the ``nodes`` (the
    region's nodes, in that order): sum_k a_k p_k = int p dGamma, sum_k b_k x p_k = int x x p."""
    g, w = np.polynomial.legendre.leggauss(order)
    xi, eta = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    ww = np.outer(w, w).ravel()
    X = mesh.cell_coords()[elems]
    xg, jn = quad9.geometry(X, xi, eta)
    J = np.linalg.norm(jn, axis=-1) * ww
    Nq = quad9.shape(xi, eta)                         # (P, 9)
    Ne = J @ Nq                                       # (E, 9)
    Be = np.einsum("ep,pa,epi->eai", J, Nq, xg)       # (E, 9, 3)
    lut = -np.ones(mesh.n_nodes, np.int64)
    lut[nodes] = np.arange(len(nodes))
    a = np.zeros(len(nodes))
    b = np.zeros((len(nodes), 3))
    loc = lut[mesh.cells[elems]].ravel()
    np.add.at(a, loc, Ne.ravel())
    np.add.at(b, loc, Be.reshape(-1, 3))
    return a, b


def _skew(v):
    """(..., 3, 3): skew(v) w = v x w."""
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1), np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


class Resultants:
    """Collective: the operator R (6 x 3 n_t, rows on rank 0) from the traction Vec to the region's
    F and M about x_ref (whole region, images folded in)."""

    def __init__(self, comm, prob, p_tmpl):
        PETSc = init()
        reg, mesh = prob.regions, prob.mesh
        self.comm = comm
        self.xref = prob.motion.xref
        a, b = area_moments(mesh, reg.disp_elems, reg.disp_nodes)
        blocks = np.zeros((reg.n_disp, 6, 3))
        for axes, s in symmetry.images(prob.planes):
            bi = b.copy()
            for ax in axes:
                bi[:, ax] *= -1.0                     # first moments of the image (x mirrored)
            blocks[:, :3, :] += a[:, None, None] * np.diag(s)[None]
            blocks[:, 3:, :] += _skew(bi - a[:, None] * self.xref) * s[None, None, :]
        self.R = PETSc.Mat().createAIJ(size=((PETSc.DECIDE, 6), (p_tmpl.getLocalSize(), p_tmpl.getSize())),
                                       nnz=(3 * reg.n_disp, 3 * reg.n_disp), comm=comm)
        self.R.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        r0, r1 = self.R.getOwnershipRange()
        cols = (3 * (reg.n_load + np.arange(reg.n_disp))[:, None] + np.arange(3)).ravel().astype(PETSc.IntType)
        for i in range(r0, r1):
            self.R.setValues([i], cols, blocks[:, i, :].ravel())
        self.R.assemble()
        self.y = self.R.createVecLeft()
        self.series = []

    def record(self, p):
        self.R.mult(p, self.y)
        self.series.append(self.y.getArray().copy())

    def arrays(self):
        """Collective: (K, 6) [F; M] on rank 0 (None elsewhere)."""
        loc = np.array(self.series).reshape(len(self.series), -1)
        allp = self.comm.tompi4py().gather(loc, root=0)
        return np.concatenate(allp, axis=1) if self.comm.getRank() == 0 else None
