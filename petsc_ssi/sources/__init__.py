"""Sources: what drives a run, as objects the domains sum over (issue 40, item 1).

A source is data about the excitation, not code in a domain. The soil (``bem.halfspace.HalfSpace``)
is given a list of sources and sums them; nothing patches a built domain from outside.

The surface-traction protocol (``traction.SurfaceTraction`` is the one implementation; a new kind
of surface load is a class with these members, or plain data given to ``SurfaceTraction``):

    elements                 the soil elements it loads (int array): the soil's loaded region is
                             the union of its sources' elements
    bind(mesh, region_nodes) called once by the soil with its surface mesh and the loaded region's
                             node ids (sorted: the soil's traction-column order); returns the
                             indices in ``region_nodes`` of the nodes it loads
    step_mean(m, dt)         the traction at those nodes (k, 3) [Pa, the soil's outward normal
                             convention: t = sigma n with n = +z on the free surface z = 0, so a
                             load pushing the surface down is t_z < 0] averaged over step m, the
                             interval ((m-1) dt, m dt]: the BEM's piecewise-constant traction is
                             this mean (the L2 projection, ``petsc_ssi.histories``)
    amplitudes(at=None)      the distinct traction vectors (k, 3) [Pa] it applies (at the nodes the
                             boolean mask ``at`` selects, in ``bind``'s order): the soil refuses those
                             its symmetry planes contradict at the nodes on a plane
                             (``bem.symmetry.check_compatible``; off a plane a load is mirrored;
                             a source with ``amplitudes()`` alone is checked at every node)
    describe()               one line for the run's log

The structure's load (``nodal.NodalLoad``): F a(t) with F the nodal forces of the options' pressures
and point loads, sampled per step by the integrator's rule ('cell' or 'step'); the fixed base and
the coupled run both take it (their load() methods had each written the sampling).

An area load (``area.AreaTraction``, -ssi_load_area) is a surface traction on a rectangle that need not
follow the cells: the soil integrates its kernels over the rectangle itself (``bem.area``) and adds its terms
to every step's right-hand side; it has ``rect``, ``f``, ``step_mean(m, dt)`` (a scalar) and ``check``.

The soil's prescribed motion (``rigid.PrescribedRigidMotion``, h(t) [u0 + theta0 x (x - x_ref)] on a
region) and the massless footing (``rigid.MasslessRigidFooting``, whose rigid motion is the unknown of
every step) are sources too: they load the soil through the displacement of a region of elements
(``rigid``'s docstring has their protocol: ``bind``, ``values``, ``factor``, ``control_point``,
``correction``). The soil tells the two kinds apart by what they give: a traction source has
``step_mean``, a motion source ``values``; it takes at most one motion source.

Where a new excitation goes: a new kind of source is a module here; the domains take it through
their ``sources`` argument (``bem.problem.BEMTransient(cfg, comm, sources=[...])``); without it the
soil takes the sources the options describe (``from_options``).
"""
from .traction import SurfaceTraction, uniform_patch, soil_sources
from .nodal import NodalLoad
from .rigid import PrescribedRigidMotion, MasslessRigidFooting, rigid_motion
from .area import AreaTraction, is_area
from . import area as _area

__all__ = ["SurfaceTraction", "uniform_patch", "soil_sources", "NodalLoad", "PrescribedRigidMotion",
           "MasslessRigidFooting", "rigid_motion", "from_options", "is_motion", "AreaTraction", "is_area"]


def from_options(cfg, mesh):
    """The soil's sources the options describe: the surface traction of -ssi_load_* (cells, or the
    rectangle of -ssi_load_area) and the rigid motion of -ssi_disp_* (prescribed or a massless footing);
    a list, empty when nothing loads the soil."""
    tractions = soil_sources(cfg, mesh)
    area = _area.from_options(cfg)
    motion = rigid_motion(cfg, mesh)
    return tractions + ([area] if area is not None else []) + ([motion] if motion is not None else [])


def is_motion(source):
    """Whether ``source`` prescribes the displacement of a region (``rigid``) rather than a traction."""
    return hasattr(source, "values") and not hasattr(source, "step_mean")
