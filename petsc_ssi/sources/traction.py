"""Surface tractions as data: t(x, t) = f(x) a(t - t0(x)) over a region of the soil's surface.

    f(x)   the traction amplitude [Pa]: a constant vector, or a function of the node coordinates
           (n, 3) [m] returning (n, 3); the soil's convention t = sigma n with n = +z on the free
           surface, so a pressure p0 > 0 pushing the surface down is f = (0, 0, -p0)
    a(t)   a scalar history (``petsc_ssi.histories.History``: heaviside, box, smoothstep or a
           table; 0 for t <= 0) with its exact running integral I(t) = int_0^t a
    t0(x)  a delay [s] per node: None (0 everywhere), a number, or a function of the coordinates
           (n, 3) returning (n,). A load moving at speed v along e from x_s is the delay
           t0(x) = (x - x_s).e / v with a box history of duration l / v (a load of length l);
           a travelling wave of the surface is t0(x) = x.e / c.

The soil's traction is piecewise constant in time: step m carries the mean over ((m-1) dt, m dt],
    p_i^m = f(x_i) (I(m dt - t0_i) - I((m-1) dt - t0_i)) / dt,
exact for every history (``petsc_ssi.histories``), node by node. Without a delay the mean is the
history's own ``mean`` (the code before sources existed computed exactly this: same bits).

In space the tractions are nodal values of the nine-node elements, continuous over the loaded
region (``bem.lagset.Regions``): the soil sums its sources node by node, so two sources on
adjacent patches would add at their shared nodes; ``check_sources`` refuses that (give one source
whose amplitude is a field over both).
"""
import numpy as np

from ..petsc import SSIError, warn
from ..histories import History


def _vector(v, n):
    a = np.asarray(v, float)
    if a.shape == (3,):
        return np.tile(a, (n, 1))
    raise SSIError(f"a surface traction's amplitude must be 3 numbers or a function of the nodes' coordinates "
                   f"(got shape {a.shape})")


class SurfaceTraction:
    """f(x) a(t - t0(x)) on the nodes of ``elements`` (module docstring); ``name`` labels the log."""

    def __init__(self, elements, amplitude, history, delay=None, name="surface traction"):
        self.elements = np.unique(np.asarray(elements, np.int64))
        self.amplitude, self.history, self.delay, self.name = amplitude, history, delay, name
        self.idx = self._f = self._t0 = None

    def nodes(self, mesh):
        """The soil nodes this source loads (sorted ids)."""
        return np.unique(mesh.cells[self.elements]) if self.elements.size else np.zeros(0, np.int64)

    def bind(self, mesh, region_nodes):
        """Evaluate f and t0 at this source's nodes; ``region_nodes``: the soil's loaded nodes
        (sorted, the traction columns' order). Returns the indices of this source's nodes in it."""
        own = self.nodes(mesh)
        self.idx = np.searchsorted(region_nodes, own)
        x = mesh.nodes[own]
        f = self.amplitude(x) if callable(self.amplitude) else _vector(self.amplitude, len(own))
        self._f = np.ascontiguousarray(np.asarray(f, float).reshape(len(own), 3))
        t0 = self.delay(x) if callable(self.delay) else self.delay
        self._t0 = None if t0 is None else np.broadcast_to(np.asarray(t0, float), (len(own),)).copy()
        for what, v in (("amplitude", self._f), ("delay", self._t0)):
            if v is not None and not np.all(np.isfinite(v)):
                raise SSIError(f"{self.name}: its {what} is not finite at {int((~np.isfinite(v)).sum())} nodes")
        return self.idx

    def step_mean(self, m, dt):
        """The traction (k, 3) [Pa] at this source's nodes, mean over ((m-1) dt, m dt]."""
        a, b = (m - 1) * dt, m * dt
        if self._t0 is None:
            return self._f * self.history.mean(a, b)
        I = self.history.integral
        return self._f * ((I(b - self._t0) - I(a - self._t0)) / (b - a))[:, None]

    def amplitudes(self, at=None):
        """The distinct amplitude vectors (k, 3) [Pa] at this source's nodes (after ``bind``), or at those
        ``at`` (a boolean mask in ``bind``'s order) selects: the soil checks those on a symmetry plane."""
        f = self._f if self._f is None or at is None else self._f[np.asarray(at, bool)]
        return np.unique(f, axis=0) if f is not None and len(f) else np.zeros((0, 3))

    def describe(self):
        f = self._f
        amp = (f"({f[0, 0]:.6g}, {f[0, 1]:.6g}, {f[0, 2]:.6g}) Pa" if f is not None and len(f) and np.all(f == f[0])
               else "a field" if f is not None else "?")
        delay = "" if self._t0 is None else f", delayed {self._t0.min():.6g} .. {self._t0.max():.6g} s"
        return (f"{self.name}: {self.elements.size} elements, traction {amp}, history {self.history.kind}"
                f"{delay}")


def uniform_patch(cfg, mesh):
    """The options' soil load (-ssi_load_group, -ssi_load_p0, -ssi_load_history, -ssi_load_t0,
    -ssi_load_table) as a source: f = (0, 0, -p0) on the group's elements; None when the options
    load nothing. SSIError on a bad history or table, naming the option."""
    if not cfg.load_group:
        return None
    elems = mesh.select(cfg.load_group)
    from ..bem import symmetry
    symmetry.check_box("-ssi_load_group", cfg.load_group, mesh.centres(), symmetry.parse(cfg.get("symmetry", "")))
    if not len(elems):
        return None
    try:
        hist = History(cfg.load_history, cfg.load_t0, cfg.load_table if cfg.load_history == "table" else None)
    except SSIError as exc:
        raise SSIError(f"-ssi_load_history {cfg.load_history}: {exc}") from None
    z = mesh.cell_coords()[elems][:, :, 2]
    tilted = int(np.count_nonzero(np.ptp(z, axis=1) > 1e-9 * (1.0 + np.abs(z).max())))
    if tilted:      # (a pit's walls: the vertical traction shears them)
        warn(f"-ssi_load_group {cfg.load_group}: {tilted} of its {len(elems)} elements are not horizontal (an "
             f"excavation's walls?): -ssi_load_p0 is the vertical traction (0, 0, -p0) on every loaded element, a "
             "shear on a wall, not a pressure normal to it")
    return SurfaceTraction(elems, np.array([0.0, 0.0, -cfg.load_p0]), hist, name=f"-ssi_load_group {cfg.load_group}")


def soil_sources(cfg, mesh):
    """The surface tractions the options describe (a list; empty when nothing loads the soil)."""
    s = uniform_patch(cfg, mesh)
    return [s] if s is not None else []


def check_sources(mesh, sources):
    """SSIError when two sources load different but adjacent elements (their shared nodes would
    carry the sum of both: the traction is continuous over the loaded region)."""
    for i, a in enumerate(sources):
        for b in sources[i + 1:]:
            if np.array_equal(a.elements, b.elements):
                continue
            shared = np.intersect1d(a.nodes(mesh), b.nodes(mesh))
            if shared.size:
                raise SSIError(f"{a.name} and {b.name} load different elements that share {shared.size} nodes: the "
                               "soil's traction is continuous over its loaded region, so those nodes would carry the "
                               "sum of both; give one source over both regions (an amplitude field) or the same "
                               "elements to both")
