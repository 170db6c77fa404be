"""A surface traction on a rectangle that need not follow the mesh: t(x, t) = f a(t) on
[x0, x1] x [y0, y1] of the surface z = 0, zero elsewhere (-ssi_load_area).

``traction.SurfaceTraction`` loads the nodes of mesh cells: its rectangle must be a union of cells. On
a uniform grid whose nodes are a slab's (the building's 0.6 m nodes) no set of cells is the paper's
1 m x 1 m patch at x = 14.5 m (runs/building/README.md). An area source is not nodal values: the soil
integrates its lag kernels over the rectangle itself (``bem.area``), for every collocation point it
owns, and adds

    sum_m g_{n-m+1} a_m,      g_l(x_i) = int_rect U^l(x - x_i) f dGamma,

to the right-hand side of each step equation (through the scheme's own combination of equations:
plain or stabilised, ``bem.area.AreaHistory``). The rectangle is a traction of the surface the mesh
stands for; its own displacement is the mesh's (the points inside it are collocation points like any
other). With symmetry planes (-ssi_symmetry) its part in the meshed region and that part's mirror images
are integrated (``AreaTraction.images``): a rectangle across a plane must be mirror-symmetric about it. It is
not in the output's nodal traction field (the cells' loads and the contact tractions are): its nodal values
are not defined where its edges cross cells. Its lags are exact to the last one the run reaches (no
interpolation beyond T_L, no truncation): a rank keeps (its rows) x (lags) numbers, in the run's log. It may
not overlap the soil cells whose traction is an unknown (a structure's interface, a footing): refused.

    f      the traction [Pa], the soil's convention t = sigma n with n = +z: a pressure p0 pushing the
           surface down is f = (0, 0, -p0)
    a(t)   a scalar history (``petsc_ssi.histories.History``), step m carrying its mean over
           ((m-1) dt, m dt] as every traction of the soil
"""
import numpy as np

from ..petsc import SSIError
from ..histories import History


def parse_rect(text, option="-ssi_load_area"):
    """(x0, x1, y0, y1) [m] from 'x0,x1,y0,y1'; SSIError naming ``option`` otherwise."""
    try:
        r = tuple(float(v) for v in str(text).split(","))
    except ValueError:
        r = ()
    if len(r) != 4 or not all(np.isfinite(r)):
        raise SSIError(f"{option} {text}: give the rectangle as x0,x1,y0,y1 [m]")
    if not (r[0] < r[1] and r[2] < r[3]):
        raise SSIError(f"{option} {text}: needs x0 < x1 and y0 < y1")
    return r


class AreaTraction:
    """f a(t) on the rectangle ``rect`` = (x0, x1, y0, y1) [m] of z = 0 (module docstring)."""

    elements = np.zeros(0, np.int64)        # (no mesh cells: the soil's loaded region does not include it)

    def __init__(self, rect, amplitude, history, name="area load"):
        self.rect = tuple(float(v) for v in rect)
        self.f = np.asarray(amplitude, float).reshape(3)
        self.history, self.name = history, name

    def step_mean(self, m, dt):
        """a's mean over step m, ((m-1) dt, m dt] (a scalar; f is in the lag vectors)."""
        return self.history.mean((m - 1) * dt, m * dt) if m >= 1 else 0.0

    def images(self, planes):
        """[(rect, f), ...]: the rectangles the soil integrates and their tractions. Without symmetry planes
        the rectangle itself. With planes (``bem.symmetry``: the part x >= 0, y >= 0 is meshed, a field is
        S-mirrored across each plane) the rectangle's part in the meshed region and its mirror images, each
        with its traction S f: a rectangle that crosses a plane must be mirror-symmetric about it and its
        traction allowed there (f = S f on the plane: a vertical load on a 'sym' plane, not on an 'anti'
        one). SSIError otherwise."""
        from ..bem.symmetry import images, has_odd
        r = list(self.rect)
        for ax, kind in planes:
            lo, hi = r[2 * ax], r[2 * ax + 1]
            name = "xy"[ax]
            if hi <= 0.0:
                raise SSIError(f"{self.name}: the rectangle lies in {name} < 0, the mirror image of the meshed part "
                               f"(-ssi_symmetry meshes {name} >= 0): give it there")
            if lo < 0.0:
                if abs(lo + hi) > 1e-9 * max(abs(lo), abs(hi)):
                    raise SSIError(f"{self.name}: the rectangle crosses the symmetry plane {name} = 0 but is not "
                                   f"mirror-symmetric about it ({lo:g}..{hi:g}): the model mirrors every load there")
                if has_odd(self.f, ax, kind):
                    raise SSIError(f"{self.name}: the traction ({', '.join(f'{v:g}' for v in self.f)}) Pa on the "
                                   f"plane {name} = 0 is not allowed by -ssi_symmetry {name}="
                                   f"{'sym' if kind > 0 else 'anti'} (it would be mirrored into its opposite)")
                r[2 * ax] = 0.0
        out = []
        for axes, sgn in images(planes):
            q = list(r)
            for ax in axes:
                q[2 * ax], q[2 * ax + 1] = -r[2 * ax + 1], -r[2 * ax]
            out.append((tuple(q), sgn * self.f))
        return out

    def meshed_rect(self, planes):
        """(x0, x1, y0, y1): the rectangle's part in the meshed region (x >= 0, y >= 0 with the planes)."""
        x0, x1, y0, y1 = self.rect
        for ax, _ in planes:
            x0, y0 = (max(x0, 0.0), y0) if ax == 0 else (x0, max(y0, 0.0))
        return x0, x1, y0, y1

    def points(self, planes):
        """(5, 3) [m]: the corners and the centre of the rectangle's meshed part (where waves start from: the
        soil's diffraction warning and its automatic T_L)."""
        x0, x1, y0, y1 = self.meshed_rect(planes)
        return np.array([[x0, y0, 0.0], [x1, y0, 0.0], [x1, y1, 0.0], [x0, y1, 0.0],
                         [0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.0]])

    def check_free(self, cell_xy, what):
        """SSIError when the rectangle overlaps the inside of a cell whose traction is an unknown (``cell_xy``:
        (cells, 9, 2) [m], the structure's interface or a prescribed footing's): the load would go into the
        soil's right-hand side while the structure or footing there never felt it."""
        if not len(cell_xy):
            return
        x0, x1, y0, y1 = self.rect
        lo, hi = cell_xy.min(axis=1), cell_xy.max(axis=1)
        eps = 1e-9 * (1.0 + np.abs(cell_xy).max())
        over = (lo[:, 0] < x1 - eps) & (hi[:, 0] > x0 + eps) & (lo[:, 1] < y1 - eps) & (hi[:, 1] > y0 + eps)
        if np.any(over):
            raise SSIError(f"{self.name}: the rectangle overlaps {int(over.sum())} of the soil cells of {what}, whose "
                           "traction is an unknown; load the structure (-ssi_fem_load_*) or keep the area beside it")

    def check(self, nodes, planes):
        """SSIError unless the rectangle lies on the meshed surface (inside the nodes' extent, every node in
        it at z = 0; with symmetry planes its part in the meshed region) and agrees with the planes
        (``images``)."""
        self.images(planes)
        x0, x1, y0, y1 = self.meshed_rect(planes)
        lo, hi = nodes[:, :2].min(axis=0), nodes[:, :2].max(axis=0)
        if x0 < lo[0] or x1 > hi[0] or y0 < lo[1] or y1 > hi[1]:
            raise SSIError(f"{self.name}: the rectangle {x0:g}..{x1:g} x {y0:g}..{y1:g} m is not inside the soil "
                           f"mesh ({lo[0]:g}..{hi[0]:g} x {lo[1]:g}..{hi[1]:g} m)")
        inside = (nodes[:, 0] >= x0) & (nodes[:, 0] <= x1) & (nodes[:, 1] >= y0) & (nodes[:, 1] <= y1)
        if np.any(np.abs(nodes[inside, 2]) > 1e-9 * (1.0 + np.abs(nodes[:, :2]).max())):
            raise SSIError(f"{self.name}: the surface under the rectangle is not the plane z = 0 (an excavation?): "
                           "an area load is a traction of z = 0; load the cells (-ssi_load_group) instead")

    def amplitudes(self, at=None):
        return self.f[None, :]

    def describe(self):
        x0, x1, y0, y1 = self.rect
        return (f"{self.name}: the rectangle {x0:g}..{x1:g} x {y0:g}..{y1:g} m, traction "
                f"({self.f[0]:.6g}, {self.f[1]:.6g}, {self.f[2]:.6g}) Pa, history {self.history.kind}, "
                "integrated over the rectangle itself (not the mesh's cells)")


def from_options(cfg):
    """The options' area load (-ssi_load_area with -ssi_load_p0, -ssi_load_history, -ssi_load_t0,
    -ssi_load_table), or None."""
    if not cfg.get("load_area", ""):
        return None
    rect = parse_rect(cfg.load_area)
    try:
        hist = History(cfg.load_history, cfg.load_t0, cfg.load_table if cfg.load_history == "table" else None)
    except SSIError as exc:
        raise SSIError(f"-ssi_load_history {cfg.load_history}: {exc}") from None
    return AreaTraction(rect, (0.0, 0.0, -cfg.load_p0), hist, name=f"-ssi_load_area {cfg.load_area}")


def is_area(source):
    """Whether ``source`` is an area load (its kernels integrated over its rectangle: ``bem.area``)."""
    return isinstance(source, AreaTraction)
