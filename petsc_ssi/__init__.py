"""petsc_ssi: parallel time-domain FEM-BEM soil-structure interaction on PETSc.

Implements Romero, Galvin and Dominguez, "3D non-linear time domain FEM-BEM
approach to soil-structure interaction problems": a time-domain BEM for the
elastic half-space (nine-node quadrilaterals), a FEM structure integrated with
implicit Green's functions, and their staggered coupling with contact.

Import order matters: ``petsc_ssi.petsc.init()`` must run (it calls
``petsc4py.init(sys.argv)``) before anything imports ``petsc4py.PETSc``, so
every command-line option reaches the options database. The command line
``petsc-ssi`` does this; library users call it first.
"""
__version__ = "0.1.0"
