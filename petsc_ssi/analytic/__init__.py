"""Closed-form reference solutions used to verify the BEM/FEM solvers."""
from .pekeris import (  # noqa: F401
    arrivals,
    boussinesq_rectangle,
    dimensionless,
    lamb_point,
    lamb_point_general,
    patch_displacement,
    pekeris_point,
    point_displacement,
    poisson_ratio,
)
