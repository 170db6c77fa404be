"""petsc_ssi: parallel time-domain FEM-BEM soil-structure interaction on PETSc.

petsc4py and mpi4py come from the system PETSc build (Debian's python3-petsc4py
or a cluster's own PETSc), never from wheels that would build a second PETSc,
so they are deliberately not listed in install_requires.
"""
from setuptools import setup, find_packages

setup(
    name="petsc_ssi",
    version="0.1.0",
    description="3D non-linear time-domain FEM-BEM soil-structure interaction on PETSc",
    packages=find_packages(include=["petsc_ssi", "petsc_ssi.*"]),
    python_requires=">=3.9",
    install_requires=["numpy", "numba", "matplotlib", "mpi4py-fft"],
    extras_require={"mesh": ["gmsh"], "test": ["pytest"], "seismic": ["obspy"]},
    entry_points={"console_scripts": ["petsc-ssi = petsc_ssi.app.cli:main"]},
)
