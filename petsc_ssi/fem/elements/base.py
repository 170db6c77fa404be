"""The contract every structural element of the registry fulfils.

An element type is a module-level object (an instance of ``ElementType``) in
``fem/elements/<name>.py``, listed in ``fem/elements/__init__.py:REGISTRY``.
It declares:

  name            'hex8', 'frame', 'shell'
  dim             topological dimension of its cells (3 solid, 2 shell, 1 frame)
  nodes_per_cell  8, 4, 2
  dof_names       per node, in the element's local dof order (node-major:
                  dof k of node a is column a * len(dof_names) + k), e.g.
                  ('ux', 'uy', 'uz') or ('ux', 'uy', 'uz', 'rx', 'ry', 'rz');
                  rotations rx, ry, rz are small rotations about the GLOBAL
                  axes, translations along the global axes
  gmsh_type       gmsh element type id (5 hex8, 3 quad4, 1 line2)
  xdmf_type       XDMF topology name ('Hexahedron', 'Quadrilateral', 'Polyline')
  required        property names a part of this element must give
  optional        {property name: default} for the others it reads

and implements, vectorised over cells (no Python loop per cell):

  check(X, props) -> None | str        one-line error for the first bad cell
                                       (zero length/area, orientation parallel
                                       to the axis, inverted brick, ...)
  stiffness(X, props) -> (E, nd, nd)   element stiffness in global dofs
  lumped_mass(X, props) -> (E, nd)     diagonal mass in global dofs, > 0 on
                                       every dof (rotary inertia included)
  stiffness_reference(X, props)        slow, obvious version (loop per cell and
                                       point) the fast kernel is tested against

with X the (E, nodes_per_cell, 3) node coordinates and nd =
nodes_per_cell * len(dof_names). ``props`` is a ``Props``: the part's
material and section (scalars; ``orientation`` a 3-vector).
"""
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Props:
    """Material and section of one part (SI units)."""
    E: float = 0.0                 # Young's modulus [N/m^2]
    nu: float = 0.0                # Poisson's ratio
    rho: float = 0.0               # density [kg/m^3]
    thickness: float = 0.0         # shell thickness [m]
    area: float = 0.0              # frame cross-section area [m^2]
    Iy: float = 0.0                # frame: second moment about the local y axis, int z^2 dA [m^4]
    Iz: float = 0.0                # frame: second moment about the local z axis, int y^2 dA [m^4]
    J: float = 0.0                 # frame: St-Venant torsion constant [m^4]
    shear_factor: float = 5.0 / 6.0   # Timoshenko shear correction (frame, shell); 0: no shear
                                      # deformation (frame: Euler-Bernoulli)
    orientation: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
                                   # frame: a vector not parallel to the axis; the local z axis
                                   # (the section's depth direction) is its part normal to the axis
    added_mass: float = 0.0        # non-structural mass: kg/m^2 (shell), kg/m (frame)
    mass_per_area: float = 0.0     # shell: rho t replaced by this when > 0 [kg/m^2]
    drilling: float = 1.0          # shell: scale of the drilling-rotation stiffness
    released: bool = False         # frame, shell: rotations released from the other parts at
                                   # shared nodes (translations tied; dofmap.py)

    def G(self):
        return self.E / (2.0 * (1.0 + self.nu))


class ElementType:
    """Base class; see the module docstring."""
    name = ""
    dim = 0
    nodes_per_cell = 0
    dof_names = ()
    gmsh_type = 0
    xdmf_type = ""
    required = ()
    optional = {}

    @property
    def ndof(self):
        return self.nodes_per_cell * len(self.dof_names)

    def check(self, X, props):
        return None

    def stiffness(self, X, props):
        raise NotImplementedError

    def lumped_mass(self, X, props):
        raise NotImplementedError

    def stiffness_reference(self, X, props):
        raise NotImplementedError
