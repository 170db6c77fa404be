"""Structural FEM of petsc_ssi (paper Section 3, eqs. 13-24).

  elements/       the element registry and its contract (hex8 bricks, frames, shells)
  mesh.py         the structure's mesh: cell blocks bound to parts, node groups, faces; gmsh reader
                  and generator
  parts.py        parts of the structure and their properties (-ssi_fem_parts)
  dofmap.py       which dofs each node carries, where they are, who owns them (a PETSc Section)
  assembly.py     distributed K (AIJ) and lumped M of any mix of elements
  loads.py        pressure and point loads, fixed dofs (load histories: petsc_ssi/histories.py)
  model.py        the structure the options describe, checked before assembly
  integrators.py  implicit Green's-function integrator (eqs. 13-16), Newmark and midpoint
  problem.py      -ssi_problem fem (FEMTransient)
  static.py       K u = f (petsc-ssi static)
  modes.py        petsc-ssi modes (SLEPc)
  obstacle.py     the shell obstacle course (MacNeal & Harder) for the shell element's tests
  options.py      the -ssi_fem_* / -ssi_modes_* options

Modules that import petsc4py.PETSc do so through ``petsc_ssi.petsc.init()``.
"""
