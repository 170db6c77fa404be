"""Nine-node (biquadratic Lagrange) quadrilateral: shape functions and
geometry, in gmsh/VTK node order:

    3---6---2      corners 0..3 counter-clockwise seen from the outward
    |       |      normal (+z on the free surface), mid-edge nodes 4..7
    7   8   5      (edges 0-1, 1-2, 2-3, 3-0), centre 8.
    |       |      natural coordinates (xi, eta) in [-1, 1]^2
    0---4---1
"""
import numpy as np

NODE_XI = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [0, -1], [1, 0], [0, 1], [-1, 0], [0, 0]],
                   dtype=float)
# 1D quadratic Lagrange index (0: -1, 1: 0, 2: +1) of each node in xi and eta
_IX = np.array([0, 2, 2, 0, 1, 2, 1, 0, 1])
_IE = np.array([0, 0, 2, 2, 0, 1, 2, 1, 1])


def _l1(s):
    s = np.asarray(s, float)
    return np.stack([0.5 * s * (s - 1.0), 1.0 - s * s, 0.5 * s * (s + 1.0)], axis=-1)


def _dl1(s):
    s = np.asarray(s, float)
    return np.stack([s - 0.5, -2.0 * s, s + 0.5], axis=-1)


def shape(xi, eta):
    """N[..., 9] at natural coordinates (broadcast)."""
    lx, le = _l1(xi), _l1(eta)
    return lx[..., _IX] * le[..., _IE]


def shape_grad(xi, eta):
    """dN/dxi, dN/deta, each [..., 9]."""
    lx, le = _l1(xi), _l1(eta)
    dx, de = _dl1(xi), _dl1(eta)
    return dx[..., _IX] * le[..., _IE], lx[..., _IX] * de[..., _IE]


def geometry(X, xi, eta):
    """Position, unnormalised normal (J n = dx/dxi x dx/deta) at points.

    X: (..., 9, 3) node coordinates; xi, eta broadcastable to the points.
    Returns x (..., P, 3), jn (..., P, 3) with P the number of points.
    """
    N = shape(xi, eta)
    dN1, dN2 = shape_grad(xi, eta)
    x = N @ X
    t1 = dN1 @ X
    t2 = dN2 @ X
    return x, np.cross(t1, t2)


def gauss_legendre(n):
    return np.polynomial.legendre.leggauss(n)
