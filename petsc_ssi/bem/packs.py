"""The argument packs of the BEM kernels (issue 40, item 5; bempp-cl's style): the material and the
step as one float array, the quadrature as one record, in place of long positional lists.

``wave(dt, cp, cs, rho, nu, toff)``: a float64 array indexed by DT, CP, CS, RHO, NU, MU, TOFF (the
step, the wave speeds, the density, Poisson's ratio, the shear modulus rho c_s^2 and the kernel time
offset of a lag matrix at a non-integer lag). ``Quad``: the quadrature record (subdivisions, Gauss
points, the singular rule, the singular-pair tolerance, the mesh's smallest element size). Both are
read in njit code (numba types the record as a named tuple; the index constants are compile-time
globals), and read by value: the kernels compute with the same numbers as before. A leaf (numpy only).
"""
from collections import namedtuple

import numpy as np

DT, CP, CS, RHO, NU, MU, TOFF = range(7)

Quad = namedtuple("Quad", "ns_base near_factor ns_max gq gw gr gwr tol h_ref")
Quad.__doc__ = """The quadrature record of the assembly kernels: ``ns_base`` subdivisions of an element side
(``near_factor``: refined near the collocation point up to ``ns_max``), Gauss points and weights gq, gw
(regular) and gr, gwr (the singular pairs' polar rule), ``tol`` (a point within tol h of a node is that
node) and ``h_ref`` (the smallest element size: the length unit of the CPV at an open edge)."""


def wave(dt, cp, cs, rho, nu, toff=0.0):
    """The material and the step as one array (module docstring); mu = rho c_s c_s as the kernels
    compute it."""
    dt, cp, cs, rho, nu, toff = (float(v) for v in (dt, cp, cs, rho, nu, toff))
    return np.array([dt, cp, cs, rho, nu, rho * cs * cs, toff])


def quad(ns_base, near_factor, ns_max, gq, gw, gr, gwr, tol, h_ref):
    """A ``Quad`` with the types the compiled kernels are specialised for (one signature)."""
    f = lambda a: np.ascontiguousarray(a, dtype=np.float64)      # noqa: E731
    return Quad(int(ns_base), float(near_factor), int(ns_max), f(gq), f(gw), f(gr), f(gwr), float(tol),
                float(h_ref))


def quad_from(opts, h_ref, tol):
    """The ``Quad`` of the options of a BEM assembly (gauss, singular_order, subdivisions, near_factor,
    max_subdivisions)."""
    gq, gw = np.polynomial.legendre.leggauss(opts["gauss"])
    gr, gwr = np.polynomial.legendre.leggauss(opts["singular_order"])
    return quad(opts["subdivisions"], opts["near_factor"], opts["max_subdivisions"], gq, gw, gr, gwr, tol, h_ref)
