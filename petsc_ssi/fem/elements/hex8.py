"""hex8: the eight-node trilinear brick (isoparametric, 2x2x2 Gauss, full integration).

Formulation: standard displacement-based trilinear hexahedron (Hughes, "The Finite
Element Method", 1987, Sec. 3.5; Zienkiewicz & Taylor, vol. 1), isotropic linear
elasticity. Chosen because the paper's foundation block is meshed with it and the
elements are compact bricks (no bending-dominated thin members, where the full-
integration brick would lock: model those with frame or shell parts).

Element kernels (vectorised over elements with numpy einsum, 2x2x2 Gauss):
  K_e[a i, b j] = int  lambda N_a,i N_b,j + mu (N_a,j N_b,i + delta_ij N_a,k N_b,k) dV
  m_a           = rho int N_a dV            (row sum of the consistent mass;
                                             positive for trilinear bricks)
``hex8_stiffness_reference`` is the slow textbook B^T D B version the fast
kernel is tested against. Node order: gmsh's (= VTK's): 0-3 the face zeta = -1
counter-clockwise seen from +z, 4-7 the face zeta = +1 above them.
"""
import numpy as np

from ...petsc import SSIError
from . import register
from .base import ElementType

XI_NODES = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                     [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)


def gauss_hex(order=2):
    """Tensor Gauss-Legendre points (G, 3) and weights (G,) on [-1, 1]^3."""
    x, w = np.polynomial.legendre.leggauss(order)
    P = np.array(np.meshgrid(x, x, x, indexing="ij")).reshape(3, -1).T
    W = np.prod(np.array(np.meshgrid(w, w, w, indexing="ij")).reshape(3, -1).T, axis=1)
    return P, W


def hex8_shape(xi):
    """Trilinear shape functions N (G, 8) and derivatives dN/dxi (G, 8, 3)."""
    t = 1.0 + xi[:, None, :] * XI_NODES[None, :, :]          # (G, 8, 3)
    N = 0.125 * np.prod(t, axis=2)
    dN = np.empty(t.shape)
    for k in range(3):
        others = [j for j in range(3) if j != k]
        dN[:, :, k] = 0.125 * XI_NODES[None, :, k] * t[:, :, others[0]] * t[:, :, others[1]]
    return N, dN


def hex8_geometry(X, order=2):
    """Physical derivatives dN/dx (E, G, 8, 3), weights |J| w (E, G) and N (G, 8).

    ``X``: (E, 8, 3) node coordinates. Raises SSIError on a non-positive
    Jacobian (inverted or degenerate brick, or a wrong node order).
    """
    P, W = gauss_hex(order)
    N, dN = hex8_shape(P)
    J = np.matmul(X.transpose(0, 2, 1)[:, None], dN[None])   # (E, G, 3, 3): dx_i / dxi_k
    det = np.linalg.det(J)
    if np.any(det <= 0):
        bad = np.unique(np.nonzero(det <= 0)[0])
        raise SSIError(f"{bad.size} hex8 cell(s) have a non-positive Jacobian (first: cell {bad[0]}): "
                       "inverted or degenerate bricks, or a node order other than gmsh's")
    Jinv = np.linalg.inv(J)                                  # dxi_k / dx_i
    dNdx = np.matmul(dN[None], Jinv)                         # (E, G, 8, 3)
    return dNdx, det * W[None, :], N


def lame(E, nu):
    """Lame constants (lambda, mu) from Young's modulus and Poisson's ratio."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def hex8_stiffness(X, E, nu):
    """Element stiffness matrices (E, 24, 24), dof order 3*a + i. Vectorised.

    Both terms are batched products over (Gauss point, direction):
    T1[a i, b j] = sum_g w N_a,i N_b,j and T2[a, b] = sum_g,k w N_a,k N_b,k.
    """
    lam, mu = lame(E, nu)
    G, wd, _ = hex8_geometry(X)
    ne, ng = G.shape[:2]
    Gf = G.reshape(ne, ng, 24)                               # (a, i) -> 3a + i
    T1 = np.matmul((Gf * wd[:, :, None]).transpose(0, 2, 1), Gf).reshape(ne, 8, 3, 8, 3)
    Gk = G.transpose(0, 2, 1, 3).reshape(ne, 8, 3 * ng)      # a x (g, k)
    T2 = np.matmul(Gk * np.repeat(wd, 3, axis=1)[:, None, :], Gk.transpose(0, 2, 1))
    Ke = lam * T1 + mu * T1.transpose(0, 1, 4, 3, 2)
    Ke += mu * T2[:, :, None, :, None] * np.eye(3)[None, None, :, None, :]
    return Ke.reshape(-1, 24, 24)


def hex8_lumped_mass(X, rho):
    """Lumped nodal masses (E, 8): rho int N_a dV (row sums of the consistent mass)."""
    _, wd, N = hex8_geometry(X)
    return rho * np.einsum("ga,eg->ea", N, wd)


def hex8_stiffness_reference(X, E, nu):
    """Slow textbook K_e = sum_g B^T D B |J| w, one element and point at a time."""
    lam, mu = lame(E, nu)
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[np.arange(3), np.arange(3)] += 2 * mu
    D[np.arange(3, 6), np.arange(3, 6)] = mu
    P, W = gauss_hex(2)
    N, dN = hex8_shape(P)
    out = np.zeros((X.shape[0], 24, 24))
    for e in range(X.shape[0]):
        for g in range(P.shape[0]):
            J = X[e].T @ dN[g]
            dx = dN[g] @ np.linalg.inv(J)                    # (8, 3)
            B = np.zeros((6, 24))
            for a in range(8):
                gx, gy, gz = dx[a]
                B[:, 3 * a:3 * a + 3] = [[gx, 0, 0], [0, gy, 0], [0, 0, gz],
                                         [0, gz, gy], [gz, 0, gx], [gy, gx, 0]]
            out[e] += B.T @ D @ B * np.linalg.det(J) * W[g]
    return out


class Hex8(ElementType):
    name = "hex8"
    dim = 3
    nodes_per_cell = 8
    dof_names = ("ux", "uy", "uz")
    gmsh_type = 5
    xdmf_type = "Hexahedron"
    required = ("E", "nu", "rho")
    optional = {}

    def check(self, X, props):
        P, _ = gauss_hex(2)
        _, dN = hex8_shape(P)
        det = np.linalg.det(np.matmul(X.transpose(0, 2, 1)[:, None], dN[None]))
        bad = np.nonzero((det <= 0).any(axis=1))[0]
        if bad.size:
            c = X[bad[0]].mean(axis=0)
            return (f"{bad.size} hex8 cell(s) have a non-positive Jacobian (first: cell {bad[0]} near "
                    f"({c[0]:.4g}, {c[1]:.4g}, {c[2]:.4g})): inverted or degenerate bricks, or a node order "
                    "other than gmsh's")
        return None

    def stiffness(self, X, props):
        return hex8_stiffness(X, props.E, props.nu)

    def lumped_mass(self, X, props):
        return np.repeat(hex8_lumped_mass(X, props.rho), 3, axis=1)

    def stiffness_reference(self, X, props):
        return hex8_stiffness_reference(X, props.E, props.nu)


HEX8 = register(Hex8())
