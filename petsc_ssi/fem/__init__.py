"""Structural FEM of petsc_ssi (paper Section 3, eqs. 13-24).

  mesh.py         hex8 meshes: gmsh reader, structured generator, named groups
  assembly.py     vectorised hex8 kernels; distributed K (AIJ, bs 3) and lumped M
  loads.py        pressure/point loads, fixed dofs (load histories: petsc_ssi/histories.py)
  integrators.py  implicit Green's-function integrator (eqs. 13-16) and Newmark
  model.py        the structure described by the options (checked before assembly)
  static.py       K u = f (reference)
  run.py          -ssi_problem fem
  modes.py        petsc-ssi modes (SLEPc)
  options.py      the -ssi_fem_* / -ssi_modes_n options

Modules that import petsc4py.PETSc do so through ``petsc_ssi.petsc.init()``.
"""
