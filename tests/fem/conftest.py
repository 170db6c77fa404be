"""Fixtures of the FEM tests."""
import sys

import pytest


@pytest.fixture(scope="session")
def PETSc():
    """petsc4py initialised without pytest's own arguments."""
    from petsc_ssi.petsc import init
    return init([sys.argv[0]])
