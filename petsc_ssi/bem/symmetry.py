"""Symmetry planes x = 0 and/or y = 0 (``-ssi_symmetry x=sym,y=anti``).

Only the part x >= 0 (y >= 0) is meshed; each element is integrated together
with its mirror images. A field symmetric about x = 0 satisfies
u(-x, y) = S u(x, y) with S = diag(-1, 1, 1); antisymmetric: S = diag(1, -1, -1).
Images across both planes use the product. Reflection reverses the orientation
of an element, so the node order of an image with an odd number of
reflections is permuted to keep the outward normal.
"""
import numpy as np

from ..petsc import SSIError

FLIP = np.array([0, 3, 2, 1, 7, 6, 5, 4, 8])   # swaps xi and eta


def parse(spec):
    """'x=sym,y=anti' -> [(axis, +1 sym / -1 anti), ...]"""
    planes = []
    spec = (spec or "").strip()
    if not spec or spec.lower() == "none":
        return planes
    for part in spec.split(","):
        try:
            ax, kind = (s.strip().lower() for s in part.split("="))
        except ValueError:
            raise SSIError(f"-ssi_symmetry '{spec}': expected e.g. 'x=sym,y=anti'") from None
        if ax not in ("x", "y") or kind not in ("sym", "anti", "symmetric", "antisymmetric"):
            raise SSIError(f"-ssi_symmetry '{spec}': planes are x or y, types sym or anti")
        a = 0 if ax == "x" else 1
        if any(p[0] == a for p in planes):
            raise SSIError(f"-ssi_symmetry '{spec}': plane {ax}=0 given twice")
        planes.append((a, 1 if kind.startswith("sym") else -1))
    return planes


def check_box(option, spec, centres, planes):
    """SSIError where the group ``spec`` of ``option`` is a box ('box:x0,x1,y0,y1', element centres inside) that
    crosses a symmetry plane of ``planes`` (x0 < 0 for x = 0, y0 < 0 for y = 0) without selecting, among the meshed
    elements (``centres``: x >= 0, y >= 0), each element's mirror image whenever it selects the element: the model
    mirrors every element it selects, so the whole model would load (or move) other elements than the box holds.
    A box in the meshed part (x0 >= 0) is mirrored, as every load is; one symmetric about the plane selects the
    same elements either way."""
    if not spec.startswith("box:") or not planes:
        return
    b = [float(v) for v in spec[4:].split(",")]
    c = np.asarray(centres, float)

    def inside(p):
        return (p[:, 0] >= b[0]) & (p[:, 0] <= b[1]) & (p[:, 1] >= b[2]) & (p[:, 1] <= b[3])

    for ax, _ in planes:
        lo, hi = b[2 * ax], b[2 * ax + 1]
        if lo >= 0.0:
            continue
        m = c.copy()
        m[:, ax] = -m[:, ax]
        if np.any(inside(c) != inside(m)):
            name = "xy"[ax]
            raise SSIError(f"{option} {spec}: the box crosses the symmetry plane {name} = 0 ({lo:g}..{hi:g}) but "
                           f"does not hold the mirror image of every element it selects: the model mirrors each "
                           f"selected element, so it would load other elements than the box; give the box in "
                           f"{name} >= 0 (mirrored) or symmetric about the plane")


def sign_matrix(axis, kind):
    s = np.ones(3)
    s[axis] = -1.0
    return s if kind > 0 else -s


def images(planes):
    """All images: list of (reflect_axes tuple, sign vector (3,))."""
    out = [((), np.ones(3))]
    for ax, kind in planes:
        s = sign_matrix(ax, kind)
        out += [(axes + (ax,), sgn * s) for axes, sgn in out]
    return out


# A node nearer a plane than NEAR_PLANE times its elements' node spacing but not on it (``on_plane``): the mesh
# was meant to reach the plane and missed it by rounding or a shift. Such a node and its mirror image are two
# free nodes a hair apart, the plane's odd components not zeroed: a vertical load on the 6 m grid's quarter
# model with every node 1e-7 m off x = 0 is 6 % off the model on the plane at its receivers, and ran without a
# warning (below 1e-6 h) until 2026-11-30 (tests/bem/test_errors.py -k near_the_plane).
NEAR_PLANE = 1e-3


def check_mesh(nodes, planes, h, node_h=None):
    """Refuse a mesh that crosses a symmetry plane or has a node near the plane but not on it (within
    ``NEAR_PLANE`` times its own elements' node spacing ``node_h`` (N,), h the largest, if not given: a mesh
    meant to reach the plane); warn (one line) where it stays farther from the plane:
    the strip between the mesh and its mirror image is then left out of the surface (not traction-free), most
    likely a mesh placed off the plane by mistake."""
    from ..petsc import warn
    for ax, _ in planes:
        name = "xy"[ax]
        if len(nodes) == 0:
            continue
        x = nodes[:, ax]
        if x.min() < -plane_tol(h):
            raise SSIError(f"-ssi_symmetry: the mesh crosses the plane {name} = 0; mesh only {name} >= 0")
        near = np.where(~on_plane(nodes, ax, h) & (x <= NEAR_PLANE * (h if node_h is None else node_h)))[0]
        if len(near):
            k = int(near[np.argmin(x[near])])
            at = ", ".join(f"{c:.6g}" for c in nodes[k])
            raise SSIError(f"-ssi_symmetry: node {k} at ({at}) m lies {x[k]:.3g} m off the plane {name} = 0, nearer "
                           f"than {NEAR_PLANE:g} of its elements' node spacing but not on it (within {plane_tol(h):.3g} "
                           f"m; {len(near)} such node(s)): put them on the plane or mesh away from it")
        gap = float(x.min())
        if gap > plane_tol(h):                            # (not on the plane, and no node near it: above)
            warn(f"-ssi_symmetry: the mesh does not reach the plane {name} = 0 (its nearest node at {name} = {gap:.6g} m): "
                 f"the {2 * gap:.6g} m strip between the mesh and its mirror image is left out of the surface; mesh "
                 f"up to the plane")


def virtual_elements(X, cells, tcols, planes):
    """Arrays of virtual elements: coords (V,9,3), node ids, sign (V,3), traction cols."""
    VX, VN, VS, VT = [], [], [], []
    for axes, sgn in images(planes):
        Xi = X.copy()
        for ax in axes:
            Xi[:, :, ax] *= -1.0
        perm = FLIP if len(axes) % 2 else np.arange(9)
        VX.append(Xi[:, perm])
        VN.append(cells[:, perm])
        VS.append(np.tile(sgn, (cells.shape[0], 1)))
        VT.append(tcols[:, perm])
    return (np.ascontiguousarray(np.concatenate(VX)), np.ascontiguousarray(np.concatenate(VN)),
            np.ascontiguousarray(np.concatenate(VS)), np.ascontiguousarray(np.concatenate(VT)))


def map_point(p, planes):
    """Map a point into the meshed part: returns (mapped point, sign vector)."""
    p = np.array(p, float)
    s = np.ones(3)
    for ax, kind in planes:
        if p[ax] < 0:
            p[ax] = -p[ax]
            s *= sign_matrix(ax, kind)
    return p, s


def plane_tol(h, tol=1e-9):
    """How near a plane a node is on it [m]: tol max(h, 1), h the largest element size."""
    return tol * max(h, 1.0)


def on_plane(nodes, ax, h, tol=1e-9):
    """Boolean mask of the nodes on the plane x_ax = 0 (within ``plane_tol`` of it): the nodes whose odd
    components a plane forces to zero (``zero_dofs``) and where a load must not carry them
    (``halfspace.HalfSpace.bind_sources``)."""
    return np.abs(nodes[:, ax]) <= plane_tol(h, tol)


def has_odd(v, ax, kind, rel=1e-12):
    """Whether the 3-vector v has a component the plane's reflection makes odd (S = -1) beyond ``rel`` of its
    largest component (a direction computed as cos(pi/2) is 6e-17, not 0); a value that is not finite counts
    as one (it cannot be checked)."""
    v = np.asarray(v, float)
    if not np.all(np.isfinite(v)):
        return True
    return bool(np.any((sign_matrix(ax, kind) < 0) & (np.abs(v) > rel * np.abs(v).max())))


def zero_dofs(nodes, planes, h, tol=1e-9):
    """DOFs that a symmetry plane forces to zero: the components of a node on
    the plane that are odd under the plane's reflection (u_x on x = 0 for
    'sym', u_y and u_z for 'anti'); the same holds for the traction there."""
    out = []
    for ax, kind in planes:
        on = np.where(on_plane(nodes, ax, h, tol))[0]
        odd = np.where(sign_matrix(ax, kind) < 0)[0]
        out.append((3 * on[:, None] + odd[None, :]).ravel())
    return np.unique(np.concatenate(out)) if out else np.zeros(0, np.int64)


def check_compatible(planes, traction, disp, where="", what="the load traction"):
    """Refuse loads the declared symmetry contradicts: components with S = -1 must vanish (``has_odd``: to
    1e-12 of the vector's largest; a uniform field on a patch that meets the plane is even; ``where`` says which
    nodes were checked; ``what``: the traction's name in the message)."""
    for ax, kind in planes:
        name = f"{'xy'[ax]}={'sym' if kind > 0 else 'anti'}"
        for label, v in ((what, traction), ("the prescribed displacement", disp)):
            if v is not None and has_odd(v, ax, kind):
                raise SSIError(f"-ssi_symmetry {name}: {label} {tuple(float(x) for x in v)}{where} is not "
                               f"{'symmetric' if kind > 0 else 'antisymmetric'} about this plane")
