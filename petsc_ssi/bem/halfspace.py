"""The half-space of a run as meshed, loaded and checked (``HalfSpace``), before any assembly.

Order of work: every input check (collective, one-line errors) and the memory estimate come
before any assembly: the surface mesh (``read_surface_mesh``), the regions (loaded, prescribed),
the receivers, the lags and the interpolation plan, the node partition (``lagset``) and the
memory check (``check_memory``). ``bem.build.build_marcher`` then assembles.
"""

import numpy as np

from ..petsc import SSIError, collective, printf, warn
from ..mesh import surface
from .. import timegrid
from . import symmetry, receivers as rec
from ..sources import from_options, is_motion, is_area
from ..sources.traction import check_sources
from .lagset import Material, Regions, LagSet
from .windows import causal_lags
from . import interp
from ..sysmem import machine_memory, process_rss


def _pair(text, name):
    try:
        v = [float(s) for s in text.split(",")]
    except ValueError:
        raise SSIError(f"-ssi_{name} '{text}': expected 'a,b'") from None
    if len(v) != 2 or min(v) <= 0:
        raise SSIError(f"-ssi_{name} '{text}': expected two positive numbers 'a,b'")
    return v


def read_surface_mesh(cfg, comm, planes):
    """Collective: the surface mesh (grid generator or gmsh; rank 0 reads, broadcast)."""
    Lx, Ly = _pair(cfg.mesh_size, "mesh_size")
    patch = _pair(cfg.mesh_patch, "mesh_patch") if cfg.mesh_patch else None
    xmin = 0.0 if any(a == 0 for a, _ in planes) else None
    ymin = 0.0 if any(a == 1 for a, _ in planes) else None
    mpi = comm.tompi4py()
    mesh = None
    with collective(comm, f"-ssi_mesh {cfg.mesh}", "{what}: cannot read the mesh ({error})"):
        if comm.getRank() == 0:
            if cfg.mesh == "grid" and str(cfg.get("mesh_params", "") or "").strip():
                raise SSIError("-ssi_mesh_params: the grid generator (-ssi_mesh grid) has no parameters; they set "
                               "the DefineConstant parameters of a .geo given as -ssi_mesh")
            if cfg.mesh == "grid":
                mesh = surface.grid(Lx, Ly, cfg.mesh_h, patch, xmin, ymin, cfg.get("mesh_grade", 0.0))
            elif cfg.mesh == "pit":
                mesh = _pit(cfg, Lx, Ly, patch, planes)
            else:
                params = {"Lx": Lx, "Ly": Ly, "h": cfg.mesh_h,
                          "xmin": -Lx / 2 if xmin is None else 0.0,
                          "ymin": -Ly / 2 if ymin is None else 0.0}
                if patch:
                    params.update({"a": patch[0], "b": patch[1]})
                from ..fem.mesh import parse_mesh_params
                user = parse_mesh_params(cfg.get("mesh_params", ""), "-ssi_mesh_params")
                params.update(user)
                mesh = surface.read_gmsh(cfg.mesh, params, tuple(user))
                ext = np.ptp(np.asarray(mesh.nodes)[:, :2], axis=0)
                if cfg.user_set("mesh_h") and cfg.mesh_h > ext.min():
                    # (issue 44: the grid generator's check, for a .geo: its elements cannot have the size asked)
                    raise SSIError(f"-ssi_mesh_h {cfg.mesh_h:g} m is larger than the mesh {cfg.mesh} "
                                   f"({ext[0]:g} m x {ext[1]:g} m): its elements cannot have the size asked; "
                                   f"give -ssi_mesh_h <= {ext.min():g} m or a larger extent")
            mesh.check()
            if mesh.in_plane():
                # on the plane, exactly (the lag blocks' flat pattern, bem/bsr.py, holds)
                mesh.require_plane(f"-ssi_mesh {cfg.mesh}", "")
            else:
                # an excavation: the ground z = 0 closed by walls and bottoms, normals out of the soil
                # (refused in one line before any assembly); the general 3x3 block pattern
                surface.check_excavation(mesh, f"-ssi_mesh {cfg.mesh}", planes)
    mesh = mpi.bcast(mesh)
    if cfg.mesh in ("grid", "pit") and not cfg.get("mesh_grade", 0.0):
        # the generators round each stretch's element count: say so where the sizes moved from h
        sz = 2.0 * mesh.element_sizes()              # (node spacing: half an element side)
        lo, hi = float(sz.min()), float(sz.max())
        if hi > 1.01 * cfg.mesh_h or lo < 0.99 * cfg.mesh_h:
            printf(f"[ssi] mesh: element sides {lo:.4g} .. {hi:.4g} m for -ssi_mesh_h {cfg.mesh_h:g} m (each "
                   "stretch between the extent, the patch and the excavation's edges takes a whole number of "
                   "elements)")
    return mesh


def _pit(cfg, Lx, Ly, patch, planes):
    """-ssi_mesh pit: the grid generator's ground with a rectangular excavation (``surface.pit``) of
    -ssi_mesh_params a=,b=,d= (half-widths and depth, m), centred at x=,y= (m; default 0, 0: a long
    narrow excavation off the centre is a trench, runs/trench)."""
    from ..fem.mesh import parse_mesh_params
    p = parse_mesh_params(cfg.get("mesh_params", ""), "-ssi_mesh_params")
    if patch:
        raise SSIError("-ssi_mesh pit: -ssi_mesh_patch is not taken (the pit's groups are ground, walls, bottom and "
                       "pit)")
    if not {"a", "b", "d"} <= set(p) <= {"a", "b", "d", "x", "y"}:
        raise SSIError(f"-ssi_mesh pit: -ssi_mesh_params must give a, b and d (the pit's half-widths and depth, m) "
                       f"and may give x and y (its centre, m), got '{cfg.get('mesh_params', '')}'")
    return surface.pit(Lx, Ly, cfg.mesh_h, p["a"], p["b"], p["d"], p.get("x", 0.0), p.get("y", 0.0), planes)


def read_soil_surface(cfg, comm, planes):
    """Collective: the surface mesh (``read_surface_mesh``), checked against the symmetry planes."""
    mesh = read_surface_mesh(cfg, comm, planes)
    if planes and mesh.n_nodes:
        symmetry.check_mesh(mesh.nodes, planes, float(mesh.element_sizes().max()), mesh.node_spacing())
    return mesh


# Bounds that catch a wrong unit (issue 44: a soil of c_s 5 m/s or rho 10 kg/m^3 ran without a word):
# km/s for m/s puts c_s below 10, g/cm^3 for kg/m^3 puts rho below 100. The softest peats have c_s
# near 30 m/s, hard rock about 3500 m/s (c_p above 1e4 m/s is refused with the options); soils and
# rocks weigh 1200-3000 kg/m^3. Wide on purpose: the tests' reduced soils (c_s 20 m/s) are models.
SOIL_CS = (10.0, 6000.0)          # m/s
SOIL_RHO = (100.0, 5000.0)        # kg/m^3


def soil_plausibility(cs, rho):
    """One line when the soil's shear-wave speed [m/s] or density [kg/m^3] lies outside what soils and
    rocks have (a wrong unit: km/s, g/cm^3), else None. A warning, not a refusal: scaled and
    non-dimensional models (c_s = rho = 1) are legitimate."""
    out = []
    if not SOIL_CS[0] <= cs <= SOIL_CS[1]:
        out.append(f"-ssi_cs {cs:g} m/s (soils and rocks: within {SOIL_CS[0]:g} to {SOIL_CS[1]:g} m/s)")
    if not SOIL_RHO[0] <= rho <= SOIL_RHO[1]:
        out.append(f"-ssi_rho {rho:g} kg/m^3 (soils and rocks: within {SOIL_RHO[0]:g} to {SOIL_RHO[1]:g} kg/m^3)")
    if not out:
        return None
    return ("unusual soil: " + "; ".join(out) + ": check the units (m/s, kg/m^3); a scaled or non-dimensional "
            "model runs as given")


def node_share(comm):
    """Collective: (share, nodes): the fraction of the run's ranks on its most loaded node (1 on one
    machine), which the node's memory limit weighs the run's bytes by, and the number of nodes."""
    from mpi4py import MPI
    mpi = comm.tompi4py()
    node = mpi.Split_type(MPI.COMM_TYPE_SHARED)
    share = mpi.allreduce(node.Get_size(), op=MPI.MAX) / float(mpi.Get_size())
    n_nodes = mpi.allreduce(1 if node.Get_rank() == 0 else 0)
    node.Free()
    return share, n_nodes


class HalfSpace:
    """Everything a BEM run needs, checked before heavy work (collective)."""

    def __init__(self, cfg, comm, log=printf, sources=None, mesh=None, interface=None, record_scheme=None):
        """``sources``: what loads the soil (``petsc_ssi.sources``): surface tractions, summed, and at
        most one rigid motion of a region (prescribed, or a massless footing's); None: those of the
        options (``sources.from_options``: -ssi_load_*, -ssi_disp_*). ``mesh``: the surface mesh when
        the caller has read it (``read_soil_surface``). ``interface``: a coupled run's interface
        (``coupling.interface.build_interface``): its soil elements carry the structure's tractions,
        its centroid is the seismic input's default control point and its nodes are points of
        interest. The seismic input, a source with a duration, comes before the time grid: without
        -ssi_t_end the run lasts the record (``timegrid.TimeGrid.of_run``); nothing is written into
        the options. ``record_scheme``: a coupled structure's integrator when it takes the record as a
        prescribed load (``coupling.step``'s strategies: the staggered coupling's Green scheme), whose
        amplification near Nyquist the record's notes check."""
        self.cfg, self.comm, self.log = cfg, comm, log
        self.record_scheme = record_scheme
        self.mat = Material(cfg.cp, cfg.cs, cfg.rho)
        self.planes = symmetry.parse(cfg.symmetry)
        self.mesh = mesh if mesh is not None else read_soil_surface(cfg, comm, self.planes)
        h = float(self.mesh.element_sizes().max())
        self.h = h
        bad, ang = surface.kinks(self.mesh, self.planes)
        if len(bad):
            printf(f"[ssi] {len(bad)} non-smooth surface nodes (edges/corners, up to {ang.max():.3g} degrees): "
                   f"free term from the interior solid angle (Hartmann)")
        wave = cfg.get("seismic", "none") != "none"
        self._load_warnings(wave)
        # histories are built (and tables read and checked) before any heavy work
        given = list(from_options(cfg, self.mesh) if sources is None else sources)
        self.areas = [s for s in given if is_area(s)]                 # area loads: their own lag vectors (bem.area)
        self.sources = [s for s in given if not is_motion(s) and not is_area(s)]   # tractions: summed (``known_p``)
        self.motion = self._motion_source([s for s in given if is_motion(s)], interface)
        disp = interface.be_elems if interface is not None else self.motion.elements if self.motion else ()
        self._excavation = self._interface_ff = None
        if wave and interface is not None and not self.mesh.flat:
            # the free field's traction on the structure's faces below the ground (walls, bottom): the
            # structure takes the total traction t_sc + t_ff there (``interface_free_field``)
            from ..sources.free_field import InterfaceFreeField
            self._interface_ff = InterfaceFreeField(self.mesh, interface.be_elems, interface.be_nodes, interface.M,
                                                    interface.zero)
        if wave and not self.mesh.flat:       # the scattered field's -t_ff on the excavation's free faces
            self._excavation = self._free_field_source(disp)
            self.sources += [self._excavation] if self._excavation is not None else []
        check_sources(self.mesh, self.sources)
        load = (np.unique(np.concatenate([s.elements for s in self.sources])) if self.sources
                else np.zeros(0, np.int64))
        if interface is not None:
            self._check_interface(load, interface)
        self.regions = Regions(self.mesh, load, disp)
        if interface is not None and not np.array_equal(self.regions.disp_nodes, interface.be_nodes):
            raise SSIError("interface: internal error, node order of the soil regions differs")
        self.bind_sources()
        for src in self.areas:
            src.check(self.mesh.nodes, self.planes)
            if len(disp):
                what = "the structure's interface" if interface is not None else "the footing (-ssi_disp_group)"
                src.check_free(self.mesh.cell_coords()[np.asarray(disp, np.int64)][:, :, :2], what)
        for src in (self.sources if sources is not None else [self._excavation] if self._excavation else []) + \
                self.areas:
            printf(f"[ssi] source: {src.describe()}")
        self.massless = self.motion is not None and self.motion.massless
        if self.motion is not None:       # (a massless footing with no soil around it is refused here)
            self.motion.bind(self.mesh, self.regions, self.planes, h)
            if sources is not None:
                printf(f"[ssi] source: {self.motion.describe()}")
        self.receivers = self._receivers(h)
        # a coupled run's structure: points of interest (the interpolation rule, the diffraction warning)
        self.sites = interface.x if interface is not None else np.zeros((0, 3))
        self.seismic = self._seismic_setup(interface) if wave else None
        # enough steps to reach t_end (a t_end off the step grid is passed, not cut)
        self.grid = timegrid.TimeGrid.of_run(cfg, [self.seismic.duration] if self.seismic is not None else [])
        self.dt, self.n_steps = self.grid.dt, self.grid.n_steps
        self._lags()
        self._warnings(h)
        if self.seismic is not None:
            self._seismic_lines()
        if interface is not None:
            self.diffraction_warning(interface.x, "the structure (interface nodes)")

    def _seismic_setup(self, interface):
        """The seismic input (record and wave checked first), attached to the sources that carry its free
        field; SSIError when nothing would scatter it."""
        seismic = self._seismic_input(self._control_point(interface))
        for src in (self._excavation, self._interface_ff):
            if src is not None:
                src.attach(seismic)
        loaded = any(np.any(s.amplitudes() != 0.0) for s in self.sources + self.areas) or self._excavation is not None
        if interface is None and self.motion is None and not loaded:
            # nothing scatters the wave: the scattered field is zero at every step (issue 44: it was
            # marched, assembly and all, and the output held zeros beside the closed-form free field)
            raise SSIError(f"-ssi_seismic {self.cfg.seismic} on the half-space alone with nothing in it (no "
                           "-ssi_disp_group footing, no loaded -ssi_load_group): the scattered field would be "
                           "zero at every step; give a footing (petsc-ssi input-motion) or a structure "
                           "(-ssi_problem ssi)")
        return seismic

    def _load_warnings(self, wave):
        """One line for each load option that does nothing (``wave``: a seismic input, which loads the
        soil itself; the prescribed motion's options: ``sources.rigid.rigid_motion``) and for a soil whose
        c_s or rho looks like a wrong unit (``soil_plausibility``)."""
        cfg = self.cfg
        if (cfg.load_group or cfg.get("load_area", "")) and cfg.load_p0 == 0.0 and not wave:     # (with a wave: the wave loads it)
            warn("-ssi_load_group is set but -ssi_load_p0 is 0: the soil carries no load of its own")
        if cfg.user_set("load_p0") and cfg.load_p0 != 0.0 and not cfg.load_group and not cfg.get("load_area", ""):
            warn("-ssi_load_p0 is set but no -ssi_load_group: nothing is loaded")
        odd = soil_plausibility(cfg.cs, cfg.rho)
        if odd:
            warn(odd)

    def _receivers(self, h):
        """The receivers of -ssi_receivers, each located on the surface (its symmetry image on the
        meshed part; on a flat surface a point off z = 0 is refused)."""
        out = rec.parse(self.cfg.receivers)
        for p in out:
            q, _ = symmetry.map_point(p, self.planes)
            rec.locate(self.mesh, q)
            if self.mesh.flat and abs(p[2]) > 1e-6 * max(h, 1.0):
                raise SSIError(f"receiver ({p[0]:g}, {p[1]:g}, {p[2]:g}) is not on the surface z = 0")
        return out

    def _free_field_source(self, disp):
        """The free field's traction -t_ff on the excavation's faces (every element below the ground but
        the prescribed region's): ``sources.free_field.FreeFieldTraction``, its wave attached later."""
        from ..sources.free_field import FreeFieldTraction
        X = self.mesh.cell_coords()
        tol = 1e-9 * max(float(np.ptp(self.mesh.nodes, axis=0).max()), 1.0)
        below = np.nonzero(X[..., 2].min(1) < -tol)[0]
        faces = np.setdiff1d(below, np.asarray(disp, np.int64))
        return FreeFieldTraction(faces) if faces.size else None

    def _check_interface(self, load, interface):
        both = np.intersect1d(load, interface.be_elems)
        if both.size:
            names = ", ".join(s.name for s in self.sources)
            raise SSIError(f"{names}: {both.size} loaded soil elements lie under the structure (the "
                           "interface); load the structure instead (-ssi_fem_load_*)")

    def _control_point(self, interface):
        """The seismic input's default control point: a massless footing's x_ref, the prescribed
        region's or the interface's centroid, else the origin."""
        if interface is not None:
            return interface.x.mean(0)
        if self.motion is not None:       # (a massless footing's: its centroid, whatever its x_ref)
            return self.motion.control_point(self.mesh, self.regions, self.planes)
        return np.zeros(3)

    def _motion_source(self, motions, interface):
        """The one rigid-motion source of ``motions`` (``sources.rigid``), or None; SSIError for two, or
        for one beside a coupled run's interface (the structure gives that region's displacements)."""
        if len(motions) > 1:
            raise SSIError(f"{len(motions)} prescribed motions of soil regions ({', '.join(m.name for m in motions)}): "
                           "the soil takes one (give one region)")
        if motions and interface is not None:
            raise SSIError(f"{motions[0].name}: a coupled run's interface is the soil's displacement region (the "
                           "structure gives its displacements); no other motion is prescribed")
        if motions and not len(motions[0].elements):
            return None
        return motions[0] if motions else None

    def _seismic_input(self, ref):
        """Collective: the earthquake of -ssi_seismic (``seismic.input.SeismicInput``), with ``ref``
        the default control point. Refuses a symmetry plane the wave breaks."""
        from ..seismic.input import SeismicInput
        seismic = SeismicInput(self.cfg, self.comm, self.mat.cs, self.mat.cp, self.mat.rho, self.mesh.nodes,
                               ref, self.cfg.dt, scheme=self.record_scheme)
        self._seismic_symmetry(seismic)
        return seismic

    def _seismic_lines(self):
        """The seismic input's log lines and notes, and a warning when the run ends before the wave's
        lead and pads are over."""
        from ..seismic.input import report
        report(self.seismic, self.grid.t_end, self.comm,
               "the wave's lead and any high-pass pad, see the seismic input lines")

    def _seismic_symmetry(self, s):
        """A symmetry plane must hold for the free field ``s``: a uniform (vertical) wave moving along
        the plane's normal needs 'anti', along the plane 'sym'; an oblique or Rayleigh wave may not
        travel across a plane (only along it)."""
        if not self.planes:
            return
        for ax, kind in self.planes:
            if s.kind != "vertical" and abs(s.waves[0].e_h[ax]) > 1e-12:
                raise SSIError(f"-ssi_symmetry {'xy'[ax]}={'sym' if kind > 0 else 'anti'}: the {s.kind} wave "
                               f"travels across this plane (azimuth {self.cfg.seismic_azimuth:g} deg): the free "
                               "field is not symmetric about it; model the whole surface")
        try:
            symmetry.check_compatible(self.planes, s.direction(), None, what="the free field's direction of motion")
        except SSIError as exc:
            raise SSIError(f"{exc}; here the free field of -ssi_seismic {s.kind} moves along "
                           f"{tuple(int(v) for v in s.direction())}") from None

    def free_field_owned(self, t, r0, r1):
        """The free-field displacement of the owned soil dofs [r0, r1) (3 per node) at time t [m]."""
        if self.seismic is None:
            return np.zeros(r1 - r0)
        return self.seismic.u(self.mesh.nodes[r0 // 3:r1 // 3], t).ravel()

    def total_field(self, u, t, out):
        """The total soil displacement u_sc + u_ff at time t in ``out`` (owned rows; no communication),
        or ``u`` itself without a wave [m]."""
        if self.seismic is None:
            return u
        u.copy(out)
        r0, r1 = out.getOwnershipRange()
        out.getArray()[:] += self.free_field_owned(t, r0, r1)
        return out

    @property
    def has_interface_free_field(self):
        """Whether the coupled structure's interface takes a free-field traction (``interface_free_field``)."""
        return self._interface_ff is not None

    def interface_free_field(self, m):
        """The free field's traction t_ff = sigma_ff n_b (n_I, 3) [Pa] on a coupled structure's interface,
        the exact mean over ((m-1) dt, m dt], n_b the soil's outward normal, as the nodal field whose
        consistent force is that of t_ff face by face (``sources.free_field.InterfaceFreeField``); None
        where it vanishes (no wave, or a plane surface: the free field is traction-free on z = 0)."""
        if self._interface_ff is None:
            return None
        return self._interface_ff.step_mean(m, self.dt)

    def free_field_at(self, nodes, t):
        """The free-field displacement (3 n,) of soil ``nodes`` at time t [m] (0 without a wave)."""
        if self.seismic is None:
            return np.zeros(3 * len(nodes))
        return self.seismic.u(self.mesh.nodes[nodes], t).ravel()

    def _lags(self):
        VX = self.mesh.cell_coords()
        ext = np.abs(VX).max(axis=(0, 1))
        if self.planes:
            lo = -ext
        else:
            lo = VX.min(axis=(0, 1))
        hi = VX.max(axis=(0, 1))
        self.r_max = float(np.linalg.norm(hi - lo))
        self.T_N = self.r_max / self.mat.cs
        causal = causal_lags(self.r_max, self.mat, self.dt)
        self.L = max(2, min(causal, self.n_steps + 1))

    def _warnings(self, h):
        cfg = self.cfg
        sizes = self.mesh.element_sizes()
        lmin, lmax = sizes.min(), sizes.max()
        self.beta = (self.mat.cs * self.dt / lmax, self.mat.cp * self.dt / lmin)
        from .stability_map import beta_warning
        msg = beta_warning(cfg.scheme, self.mat.cs * self.dt / lmax, self.mat.cs * self.dt / lmin)
        if cfg.warn_beta and msg:
            warn(msg)
        self._diffracted = []
        for k, p in enumerate(self.receivers):
            self.diffraction_warning(p[None], f"receiver {k} ({p[0]:g}, {p[1]:g}, {p[2]:g})")
        if self.motion is not None:     # the footing's own reaction (an impedance, a prescribed motion's traction)
            self.diffraction_warning(self.mesh.nodes[self.regions.disp_nodes], "the footing")

    def diffraction_warning(self, points, what):
        """Note the earliest time at which waves from the loads, the footing or the structure's interface
        (``_wave_sources``) diffracted at the truncation edge reach any of ``points`` (e.g. a receiver, or
        the structure's interface nodes), path source -> edge -> point at c_p; ``warn_diffraction`` (from
        ``prepare``) says in one line which arrive before t_end. Returns that time (None without a source
        or an edge)."""
        paths = self._edge_paths()
        if paths is None or not len(points):
            return None
        edge, d_se = paths
        t_d = np.inf
        for p in np.atleast_2d(points):
            q, _ = symmetry.map_point(p, self.planes)
            t_d = min(t_d, (d_se + np.linalg.norm(edge[:, :2] - q[:2], axis=1)).min() / self.mat.cp)
        if t_d < self.grid.t_end:
            self._diffracted.append((what, t_d))
        return t_d

    def _edge_paths(self):
        """(edge nodes, each one's distance from the nearest wave source), made once: the sources and the edge do
        not change after the set-up, and ``diffraction_warning`` is called for every receiver; None without a
        source or an edge."""
        if not hasattr(self, "_paths"):
            src, edge = self._wave_sources()[0], self._edge_points()
            self._paths = None
            if len(src) and len(edge):
                self._paths = (edge, np.linalg.norm(src[:, None, :2] - edge[None, :, :2], axis=2).min(0))
        return self._paths

    def warn_diffraction(self):
        """One warning line: the earliest edge-diffracted arrival and every receiver (and the
        structure) it reaches before t_end."""
        if self._diffracted and self.cfg.get("warn_edge", True):
            t0 = min(t for _, t in self._diffracted)
            src = " and ".join(self._wave_sources()[1])
            warn(f"waves from {src} diffracted at the mesh edge (path source -> edge -> point at c_p) arrive "
                 f"before t_end = {self.grid.t_end:g} s, the earliest at t = {t0:.4g} s, at "
                 + ", ".join(f"{w} (t = {t:.4g} s)" for w, t in self._diffracted))
        self._diffracted = []

    def _edge_points(self):
        """Nodes on the truncation edge (not on a symmetry plane)."""
        x = self.mesh.nodes
        out = np.zeros(len(x), bool)
        for ax in (0, 1):
            lo, hi = x[:, ax].min(), x[:, ax].max()
            tol = 1e-9 * max(abs(lo), abs(hi), 1.0)
            on_plane = any(a == ax for a, _ in self.planes)
            out |= np.abs(x[:, ax] - hi) < tol
            if not on_plane:
                out |= np.abs(x[:, ax] - lo) < tol
        return x[out]

    def summary(self):
        mesh = self.mesh
        nimg = len(symmetry.images(self.planes))
        return (f"[ssi] BEM: {mesh.n_cells} nine-node elements ({mesh.n_cells * nimg} with symmetry images), "
                f"{mesh.n_nodes} nodes, {3 * mesh.n_nodes} DOFs; {self.regions.n_t} traction nodes; "
                f"dt {self.dt:g} s, {self.n_steps} steps, scheme {self.cfg.scheme}; "
                f"r_max {self.r_max:.4g} m, T_N = r_max/c_s = {self.T_N:.4g} s; lags stored {self.L} "
                f"(causal limit {causal_lags(self.r_max, self.mat, self.dt)}); "
                f"beta = c dt / l (l: node spacing, half an element side) from c_s dt / l_max = {self.beta[0]:.3f} to "
                f"c_p dt / l_min = {self.beta[1]:.3f}")

    def interp_plan(self):
        """The lag interpolation plan from -ssi_interp* (auto: the paper's rule)."""
        c = self.cfg
        method, TL, k = c.interp, c.interp_tl, c.interp_k
        if method == "auto":
            TL, k, why = self._auto_tl()
            method = "chebyshev"
            printf(f"[ssi] -ssi_interp auto: {why}")
        plan = interp.Plan(method, self.dt, self.L, TL if TL else None, k, c.interp_grading)
        if c.interp != "none" and not plan.active:
            printf("[ssi] lag interpolation falls back to exact lags (T_L >= T_N or no lag to replace)")
        elif c.interp in ("chebyshev", "linear") and plan.active:
            # a T_L the user chose before the Rayleigh wave reaches the farthest point of interest: said
            from ..analytic.free_field import rayleigh_speed
            t_arr, _, _ = self._auto_tl(self.mat.cs / rayleigh_speed(self.mat.cs, self.mat.cp))
            if t_arr is not None and plan.TL < t_arr * (1.0 - 1e-9):
                t_rule, _, _ = self._auto_tl()
                rule = (f"takes T_L = {t_rule:.4g} s here (tau_L = 1.5)" if t_rule is not None else
                        "keeps every lag exact here (its T_L, tau_L = 1.5, would reach T_N)")
                warn(f"-ssi_interp_tl {plan.TL:g} s is before the Rayleigh wave's arrival at the farthest receiver or "
                     f"interface node ({t_arr:.4g} s): the interpolated lags then carry that arrival, where the "
                     f"interpolation is least accurate (runs/pekeris/README.md); the paper's rule, -ssi_interp auto, "
                     + rule)
        self.plan = plan
        return plan

    def area_bytes(self):
        """Bytes of the area loads' lag vectors over the ranks (``bem.area``: 3 rows a node, one column a lag up
        to the last the run reaches or the rectangle's causal limit, per symmetry image), an upper bound."""
        from .windows import causal_lags
        total = 0.0
        nodes = self.mesh.nodes[:, :2]
        for a in getattr(self, "areas", []):
            for (x0, x1, y0, y1), _ in a.images(self.planes):
                far = np.max(np.hypot(np.maximum(np.abs(nodes[:, 0] - x0), np.abs(nodes[:, 0] - x1)),
                                      np.maximum(np.abs(nodes[:, 1] - y0), np.abs(nodes[:, 1] - y1))))
                total += 8.0 * 3 * self.mesh.n_nodes * min(self.n_steps + 1, causal_lags(far, self.mat, self.dt))
        return total

    def _load_points(self):
        """Where the soil's loads start their waves: the loaded cells' nodes and the area loads' corners and
        centres (their meshed parts); (0, 3) without a load."""
        parts = [self.mesh.nodes[self.regions.load_nodes]] if self.regions.n_load else []
        parts += [a.points(self.planes) for a in getattr(self, "areas", [])]
        return np.vstack(parts) if parts else np.zeros((0, 3))

    def _wave_sources(self):
        """Where the waves that the mesh edge diffracts start, and what they are in words: the loads with a
        non-zero traction (a load-free group, -ssi_load_p0 0, starts none), a seismic wave's scattered field on
        an excavation's faces, and the footing's or the structure's interface nodes, which radiate (a prescribed
        or rigid motion, a structure that moves; under a seismic wave with no load, the only source).
        Returns ((n, 3) points, [names])."""
        parts, names = [], []
        loads = [s for s in self.sources if s is not self._excavation and np.any(s.amplitudes() != 0.0)]
        areas = [a for a in self.areas if np.any(a.amplitudes() != 0.0)]
        if loads or areas:
            names.append("the load")
            parts += [self.mesh.nodes[np.unique(self.mesh.cells[s.elements])] for s in loads]
            parts += [a.points(self.planes) for a in areas]
        if self._excavation is not None:
            names.append("the excavation's faces")
            parts.append(self.mesh.nodes[np.unique(self.mesh.cells[self._excavation.elements])])
        if len(self.regions.disp_nodes):
            names.append("the footing" if self.motion is not None else "the structure's interface")
            parts.append(self.mesh.nodes[self.regions.disp_nodes])
        if getattr(self, "seismic", None) is not None and names:
            names[-1] += " (the seismic wave's scattered field)"
        return (np.vstack(parts) if parts else np.zeros((0, 3))), names

    def _auto_tl(self, tau_l=1.5):
        """The paper's rule (``interp.auto``, tau_L = c_s T_L / r) for this problem's points of interest:
        (T_L, k, why); T_L None where it would reach T_N."""
        pts0 = self._load_points()
        src = pts0.mean(0) if len(pts0) else np.zeros(3)
        for ax, _ in self.planes:      # the whole (mirrored) load is centred on the plane
            src[ax] = 0.0
        sites = getattr(self, "sites", np.zeros((0, 3)))
        pts = np.vstack([np.asarray(self.receivers).reshape(-1, 3), sites])
        TL, k, why = interp.auto(self.mat.cs, self.dt, self.L, pts, src, tau_l=tau_l)
        if len(sites):
            why += f" (points of interest: {len(self.receivers)} receivers and {len(sites)} interface nodes)"
        return TL, k, why

    def prepare(self, extra=(), extra_bytes=0.0, extra_what=""):
        """Collective: print the summary (and ``extra`` lines), choose the interpolation
        plan, set up the LagSet and check the memory (with ``extra_bytes`` of the run's other
        dense data); returns (plan, lagset)."""
        printf(self.summary())
        for line in extra:
            printf(line)
        self.warn_diffraction()
        plan = self.interp_plan()
        ls = self.lagset(plan)
        self.lattice = self._lattice(ls)
        if self.lattice is not None and self.cfg.interp == "auto" and plan.active:
            # (toeplitz_plan below keeps every lag exact where that fits: this is the rule's plan, not yet the run's)
            printf("[ssi] -ssi_interp auto: the paper's rule gives " + plan.describe() + "; the toeplitz store "
                   "decides below")
        else:
            printf("[ssi] " + plan.describe())
        if ls.balance is not None:
            n = [b - a for a, b in ls.ranges]
            printf(f"[ssi] soil nodes over {len(n)} ranks: {min(n)}..{max(n)} per rank, -ssi_partition "
                   f"{self.cfg.partition} (estimated work max/mean {ls.balance[0]:.3f}; equal node counts "
                   f"{ls.balance[1]:.3f})")
        elif len(ls.ranges) > 1:
            n = [b - a for a, b in ls.ranges]
            printf(f"[ssi] soil nodes over {len(n)} ranks: {min(n)}..{max(n)} per rank, equal node counts "
                   "(-ssi_lag_store toeplitz splits the history sum by frequency; -ssi_partition to choose)")
        ab = self.area_bytes()
        if ab:
            extra_bytes += ab
            extra_what = (extra_what + " and " if extra_what else "") + "the area loads' lag vectors"
        if self.lattice is not None:
            plan, ls = self.toeplitz_plan(ls, plan, extra_bytes)
        if self.lattice is None:
            self.check_memory(ls, plan, extra_bytes, extra_what)
        else:
            self.check_toeplitz_memory(ls, plan, extra_bytes)
        from . import lagstore
        with collective(self.comm, "checking -ssi_lags_load"):
            self.lags_manifest = lagstore.check(self.cfg, self.comm, self, plan)
        return plan, ls

    def _lattice(self, ls):
        """Collective: the uniform grid of -ssi_lag_store toeplitz (or auto, where it exists), or None
        (the dense lag matrices). Refused in one line, on every rank, before any assembly: a forced
        toeplitz store on a surface that is not a uniform flat grid, or with what it does not do."""
        from .toeplitz import detect
        store = self.cfg.get("lag_store", "dense")
        if store == "dense":
            return None
        why = None
        if int(self.cfg.lag_single_from):
            why = "-ssi_lag_single_from keeps lag matrices in single precision; use -ssi_lag_store dense"
        elif not ls.flat:
            z = self.mesh.cell_coords()[:, :, 2]
            off = np.flatnonzero(np.abs(z).max(axis=1) > 0.0)
            if off.size:
                c = self.mesh.centres()[off[0]]
                why = (f"the surface is not the plane z = 0 (element {off[0]}, centre ({c[0]:.6g}, {c[1]:.6g}, "
                       f"{c[2]:.6g}) m, and {off.size - 1} more: an excavation); use -ssi_lag_store dense")
            else:
                why = "-ssi_lag_pattern full keeps every 3x3 entry; use -ssi_lag_store dense"
        if why is None:
            try:
                lat = detect(ls.VX, self.mesh.nodes, n_cells=self.mesh.n_cells)
            except SSIError as e:
                why = str(e).split(": ", 1)[-1]
                lat = None
        if why is not None:
            if store == "toeplitz":
                raise SSIError(f"-ssi_lag_store toeplitz: {why}")
            if self.cfg.get("toeplitz_precision", "double") != "double":
                raise SSIError(f"-ssi_toeplitz_precision {self.cfg.toeplitz_precision}: -ssi_lag_store auto takes the "
                               f"dense lag matrices here ({why}), which keep no transforms")
            suffix = "; use -ssi_lag_store dense"        # (the refusal's advice: auto has taken it already)
            printf(f"[ssi] lag store: dense lag matrices ({why[:-len(suffix)] if why.endswith(suffix) else why})")
            return None
        printf(f"[ssi] lag store: toeplitz, {lat.describe()}")
        return lat

    def toeplitz_side_bytes(self, ls, plan):
        """Collective: the bytes of a toeplitz run beside its kernels: G lags 1 and 2 as Mats (the later G
        lags are kernels on the store, ``toeplitz.estimate``): block-sparse, 44 B a block (5 values and a
        column), their blocks counted as H's below over the traction elements alone, n_t / (traction
        elements) columns an element, or dense (N x n_t blocks of 5 values) where a lag's fill exceeds
        -ssi_lag_fill or -ssi_lag_storage dense asks, as ``build._traction_g`` stores them; H lags 1 and 2
        as Mats (block-sparse: their wave reaches a few elements) and the step matrix's factors, counted
        from the blocks of the lag-2 window on a sample of rows, 36 B a block, three times over."""
        from .windows import estimate_blocks
        mpi = self.comm.tompi4py()
        N, nt, nimg = self.mesh.n_nodes, self.regions.n_t, max(1, len(ls.Vc) // self.mesh.n_cells)
        rows = ls.rows[::max(1, len(ls.rows) // 256)]          # (a sample of rows: O(rows x elements))
        scale = len(ls.rows) / max(len(rows), 1)
        nb = estimate_blocks(self.mesh.nodes, rows, ls.Vc, ls.VR, 2, self.mat, self.dt, nimg) * scale
        g = 0.0
        tel = np.flatnonzero(np.any(ls.VT >= 0, axis=1))
        if nt and tel.size:
            nbg = estimate_blocks(self.mesh.nodes, rows, ls.Vc[tel], ls.VR[tel], 2, self.mat, self.dt, nimg) * scale
            nbg = mpi.allreduce(nbg) / 4.0 * (nt / max(tel.size / nimg, 1.0))
            st = self.cfg.lag_storage
            for b in nbg[:min(2, plan.Lx)]:
                dense = st == "dense" or (st == "auto" and b / float(N * nt) > self.cfg.lag_fill)
                g += 40.0 * N * nt if dense else 44.0 * b
        return g + 3 * 36.0 * mpi.allreduce(float(nb.sum()))

    def toeplitz_plan(self, ls, plan, extra_bytes=0.0, lattice=None):
        """Collective: (plan, LagSet) of a run on the toeplitz store (the LagSet made again for a new plan: the
        nodes' partition weighs the stored lags). ``-ssi_interp auto`` there keeps
        every lag exact where that fits the node (one line says which): an exact lag costs O(N) memory on the
        store, not O(N^2), and on the paper's building over a 72 m grid the paper's rule moved the histories by
        up to 15 % of the structure's peaks and 47 % of the soil's, at no saving of time
        (runs/building/README.md); where every lag exact would not fit, the paper's rule stays. Other
        -ssi_interp values are kept as given."""
        if self.cfg.interp != "auto" or not plan.active:
            return plan, ls
        lat = lattice if lattice is not None else self.lattice
        exact = interp.Plan("none", self.dt, self.L, None, 0, self.cfg.interp_grading)
        est, limit, share, _ = self._toeplitz_bytes(ls, exact, extra_bytes, lat)
        if share * est <= limit:
            printf(f"[ssi] -ssi_interp auto on the toeplitz store: every lag exact ({share * est / 1e9:.3g} GB on the "
                   f"most loaded node, within {limit / 1e9:.3g} GB; an exact lag costs O(N) here, and the paper's rule "
                   "moved the 72 m building's histories by up to 15 % at no saving of time: runs/building/README.md)")
            printf("[ssi] " + exact.describe())
            self.plan = exact
            return exact, self.lagset(exact)
        printf(f"[ssi] -ssi_interp auto on the toeplitz store: every lag exact would need {share * est / 1e9:.3g} GB on "
               f"the most loaded node, over {limit / 1e9:.3g} GB: the paper's rule stays")
        return plan, ls

    def _toeplitz_bytes(self, ls, plan, extra_bytes=0.0, lat=None):
        """Collective: (bytes over the ranks, the node's limit, this node's share, (kernels' seconds, history's
        seconds, the processes' bytes, the history's seconds step by step)) of a toeplitz run with ``plan``
        (``toeplitz.estimate``, with the processes' resident size and ``extra_bytes``)."""
        from .toeplitz import estimate, kernel_offsets, traction_grid, block_of, geometric_reach
        from mpi4py import MPI
        c = self.cfg
        lat = lat if lat is not None else self.lattice
        limit = c.memory_limit * 1e9 if c.memory_limit > 0 else 0.8 * machine_memory()
        lat.n_offsets = len(kernel_offsets(lat))
        p = self.comm.getSize()
        block = block_of(c)
        g = self.toeplitz_side_bytes(ls, plan)
        est, t_build, t_hist, steps = estimate(lat, self.L, self.n_steps, p, block, 3 * self.mesh.n_nodes, g,
                                               plan=plan, stabilized=c.scheme.startswith("stabili"),
                                               glat=traction_grid(lat, ls.VT),
                                               single=c.get("toeplitz_precision", "double") == "single", per_step=True,
                                               fft_ranks=int(c.get("toeplitz_fft_ranks", 0) or 0),
                                               reach=geometric_reach(c, self) / (0.5 * float(min(lat.h))))
        from .lagset import load_kernels
        load_kernels()                      # the process measured with the compiled kernels it will hold
        rss = self.comm.tompi4py().allreduce(process_rss(), op=MPI.SUM)
        share, _ = node_share(self.comm)
        return est + float(extra_bytes) + rss, limit, share, (t_build, t_hist, rss, steps)

    def check_toeplitz_memory(self, ls, plan, extra_bytes=0.0):
        """Collective: refuse a toeplitz run whose kernels and kept transforms would not fit the node
        (``toeplitz.estimate``), and predict its time loop (``loop_estimate``, ``loop_model``: the history sum
        step by step and a solve with the step matrix's factors each step, ``toeplitz.step_lu_of``;
        ``step_solve_s``: that solve's seconds)."""
        from .toeplitz import step_lu_of, loop_rest
        from .pfft import require
        require(self.comm)                  # (mpi4py-fft on every rank, before the assembly)
        c = self.cfg
        self.lag_fill = c.lag_fill
        p = self.comm.getSize()
        est, limit, share, (t_build, t_hist, rss, steps) = self._toeplitz_bytes(ls, plan, extra_bytes)
        self.mem_estimate = self.mem_peak_estimate = est
        printf(f"[ssi] toeplitz estimate: {est / 1e9:.3g} GB over the ranks (the {p} process{'es' if p > 1 else ''} as now, "
               f"{rss / 1e9:.3g} GB; the history kernels, kept transforms, G and the build's transients, "
               f"{(est - rss - float(extra_bytes)) / 1e9:.3g} GB"
               + (f"; the run's other data, {float(extra_bytes) / 1e9:.3g} GB" if extra_bytes else "")
               + f"), kernels {t_build:.3g} s, history sum {t_hist:.3g} s on {p} rank(s) (bem/toeplitz.py estimate)")
        # the limit holds per node, as in check_memory
        if share * est > limit:
            raise SSIError(f"-ssi_lag_store toeplitz: the history kernels need about {share * est / 1e9:.3g} GB on "
                           f"the most loaded node, more than the {limit / 1e9:.3g} GB available (-ssi_memory_limit, "
                           "per node); use -ssi_interp, a shorter -ssi_t_end, a coarser grid or more nodes")
        one = self.step_solve_s = step_lu_of(c, self, self.lattice, p)[2]
        # (the march's own work a step, a seismic wave's and the field snapshots, spread evenly: toeplitz.loop_rest)
        rest = loop_rest(c, self.n_steps, self.mesh.n_nodes) / max(self.n_steps, 1)
        cum = np.concatenate(([0.0], np.cumsum(steps)))
        self.loop_model = lambda k: float(cum[min(max(int(k), 0), len(cum) - 1)]) + (one + rest) * k
        self.loop_estimate = (t_hist + (one + rest) * self.n_steps,
                              (float(steps[-1]) if len(steps) else 0.0) + one + rest)
        self.ranks_here = int(round(share * p))         # (the slow-run warning's oversubscription test)
        self.loop_source = "bem/toeplitz.py estimate and step_lu"
        self.loop_fit = "jobscripts/toeplitz_fit.py (bem/toeplitz.py RATES and STEP_RATES)"

    def quad_options(self):
        c = self.cfg
        return {"gauss": c.gauss, "singular_order": c.singular_order, "subdivisions": c.subdivisions,
                "near_factor": c.near_factor, "max_subdivisions": c.max_subdivisions, "cache": c.cache,
                "cache_share": c.cache_share}

    def lagset(self, plan=None):
        """The LagSet of this run; ``plan``: the interpolation plan (made here if not given), whose
        matrices and their uses weigh in the partition of the nodes over the ranks. The uses are
        those of a run of L steps (the lags it reaches), not of this run's steps: the partition, and
        with it every rounding of a parallel run, depends on the stored lags only, so a run stopped
        after n steps equals a run of n steps bit for bit (tests/test_output_survives.py)."""
        from .partition import lag_weights
        from ..petsc import lag_small_pages
        plan = plan if plan is not None else self.interp_plan()
        interp = [plan.kernel_time(j)[0] for j in range(plan.k)] if plan.active else []
        # a toeplitz run's history is split over the ranks by frequency, not by node: the nodes go in equal
        # ranges (the step matrix's rows), without the dense lags' work estimate (unless -ssi_partition is given)
        part, weigh = self.cfg.partition, True
        if self.cfg.get("lag_store", "dense") == "toeplitz" and not self.cfg.user_set("partition"):
            part, weigh = "equal", False
        opts = dict(self.quad_options(), partition=part, weigh=weigh, work_lags=plan.Lx,
                    block_pattern=self.cfg.get("lag_pattern", "auto"),
                    small_pages=lag_small_pages(self.cfg.get("huge_pages", "auto")),
                    lag_weights=lag_weights(plan.Lx, self.L, self.cfg.scheme.startswith("stabili"), interp))
        return LagSet(self.comm, self.mesh, self.mat, self.dt, self.L, self.regions, self.planes, opts)

    def predict_loop(self, ls, plan, limit):
        """Collective: the time loop's prediction (``loop_estimate``: (seconds, seconds per step once every
        stored lag is in use), ``loop_terms``: its parts, ``loop_model``: k -> seconds of the first k
        steps) by the model ``petsc-ssi estimate`` evaluates (``cost.loop_terms`` of the counts of this
        run's own partition, without the assembly's element caches)."""
        import os
        from .cost import Counts, load_constants, loop_terms, loop_model
        plan = plan if plan is not None else self.interp_plan()
        p = self.comm.getSize()
        cnt = Counts(self, plan, ls, [p], limit, self.comm, assembly=False, ranges={p: ls.ranges})
        t = loop_terms(cnt, load_constants(self.cfg.get("estimate_constants", ""))[0], p, self.ranks_here,
                       max(os.cpu_count() or 1, 1))
        lags = max(cnt.L, 1)
        self.loop_terms = t
        self.loop_model = loop_model(t, self.n_steps, lags)
        per_step = self.loop_model(self.n_steps) - self.loop_model(self.n_steps - 1) if self.n_steps > lags \
            else t["loop"] / max(self.n_steps, 1)
        self.loop_estimate = (t["loop"], per_step)

    def check_memory(self, ls, plan=None, extra_bytes=0.0, extra_what=""):
        """Collective: refuse runs whose lag matrices would not fit; if the
        dense lags of the automatic storage choice would not fit but block-
        sparse storage would, store every lag block-sparse (and say so).
        ``extra_bytes``: memory of the whole run (all ranks) that lives beside the
        stored lags after assembly (the coupling's dense interface matrices)."""
        c = self.cfg
        limit = c.memory_limit * 1e9 if c.memory_limit > 0 else 0.8 * machine_memory()
        # the limit holds per node: the run's peak is shared by its ranks, of which
        # ``share`` run on the most loaded node (all of them on one machine)
        share, n_nodes = node_share(self.comm)
        extra_bytes = float(extra_bytes)
        lags = plan.Lx if plan is not None and plan.active else self.L
        extra = [plan.kernel_time(j)[0] for j in range(plan.k)] if plan is not None and plan.active else []
        self.lag_fill = c.lag_fill
        sf = int(c.lag_single_from)
        if sf > max([lags] + list(extra)):
            warn(f"-ssi_lag_single_from {sf}: beyond the {max([lags] + list(extra))} stored lags, every lag "
                 "stays in double precision")
        est, peak, nd = self._lag_memory(ls, lags, extra, extra_bytes, (share, n_nodes, limit))
        self.mem_estimate = est
        self.mem_peak_estimate = peak
        self.ranks_here = int(round(share * self.comm.getSize()))
        self.predict_loop(ls, plan, limit)
        where = (f", {share * peak / 1e9:.3g} GB on the most loaded of {n_nodes} nodes" if n_nodes > 1 else "")
        more = f", {extra_what} {extra_bytes / 1e9:.3g} GB" if extra_bytes else ""
        self.log(f"[ssi] memory estimate: lag matrices {est / 1e9:.3g} GB ({nd} dense lags){more}, "
                 f"peak {peak / 1e9:.3g} GB{where} (limit {limit / 1e9:.3g} GB per node)")
        if share * peak > limit:
            raise SSIError(f"the lag matrices need about {share * peak / 1e9:.3g} GB at assembly on "
                           f"{'the most loaded node' if n_nodes > 1 else 'this node'}, more than the "
                           f"{limit / 1e9:.3g} GB available (-ssi_memory_limit, per node); use symmetry planes, "
                           f"-ssi_interp, a coarser mesh, a shorter -ssi_t_end or more nodes")

    def _lag_memory(self, ls, lags, extra, extra_bytes, node):
        """Collective: (bytes of the stored lags, the assembly's peak, the dense lags) of ``lags`` exact lags
        and the interpolating ``extra``, with ``extra_bytes`` beside them; node = (share, nodes, limit) of
        ``check_memory``. Refuses, from a sample of rows, a run far over the limit even with every lag
        block-sparse; stores every lag block-sparse (``lag_fill``) when the automatic choice's dense lags
        would not fit and block-sparse ones would."""
        c = self.cfg
        share, n_nodes, limit = node
        sf = int(c.lag_single_from)
        load = not c.get("lags_load")           # (a run with loaded lags does not assemble)
        # fast first: the blocks of a sample of rows; a run far over the limit even with every lag
        # block-sparse is refused now, before the full O(N E) count
        est0, peak0, _ = ls.estimate_memory(lags, "sparse", c.lag_fill, extra, sample=64, single_from=sf)
        peak0 = max(peak0, est0 + extra_bytes)
        if share * peak0 > 1.5 * limit:
            raise SSIError(f"the lag matrices need about {share * peak0 / 1e9:.3g} GB at assembly (estimated from a "
                           f"sample of rows, every lag block-sparse) on {'the most loaded node' if n_nodes > 1 else 'this node'}, "
                           f"more than the {limit / 1e9:.3g} GB available (-ssi_memory_limit, per node); use symmetry "
                           "planes, -ssi_interp, a coarser mesh, a shorter -ssi_t_end or more nodes")
        est, peak, nd = ls.estimate_memory(lags, c.lag_storage, c.lag_fill, extra, single_from=sf, load=load)
        peak = max(peak, est + extra_bytes)
        if share * peak > limit and c.lag_storage == "auto":
            est2, peak2, _ = ls.estimate_memory(lags, "sparse", c.lag_fill, extra, single_from=sf, load=load)
            peak2 = max(peak2, est2 + extra_bytes)
            if share * peak2 <= limit:
                self.log(f"[ssi] memory: {nd} dense lags would need a {peak / 1e9:.3g} GB peak, over the "
                         f"{limit / 1e9:.3g} GB limit: all lags block-sparse ({peak2 / 1e9:.3g} GB)")
                self.lag_fill = 1.01
                est, peak, nd = est2, peak2, 0
        return est, peak, nd

    def bind_sources(self):
        """Evaluate each source at the loaded nodes; refuse amplitudes the symmetry planes contradict
        where they do: at a loaded node on a plane (``symmetry.on_plane``, as ``zero_dofs``) the components the
        plane's reflection makes odd (S = -1) must vanish. A load off the plane is mirrored with those
        components' signs flipped (under x=anti a vertical load at x > 0 and its opposite at x < 0), as
        an area load is (``sources.area``)."""
        nodes = self.regions.load_nodes
        for src in self.sources:
            x = self.mesh.nodes[nodes[src.bind(self.mesh, nodes)]]
            for ax, kind in self.planes:
                on = symmetry.on_plane(x, ax, self.h)
                try:
                    vals, where = src.amplitudes(on), " at its nodes on the plane"
                except TypeError:       # a source written for amplitudes() alone: checked everywhere, as before
                    vals, where = src.amplitudes(), ""
                for v in vals:
                    symmetry.check_compatible([(ax, kind)], v, None, where=where)

    def known_p(self):
        """callable(n) -> the traction of step n at the loaded nodes (3 n_load,) [Pa]: the sum of
        the sources' step means (``petsc_ssi.sources``)."""
        srcs, nl, dt = self.sources, self.regions.n_load, self.dt
        if len(srcs) == 1 and len(srcs[0].idx) == nl:        # one source over the whole region
            return lambda n: srcs[0].step_mean(n, dt).ravel()

        def kp(n):
            out = np.zeros((nl, 3))
            for s in srcs:
                out[s.idx] += s.step_mean(n, dt)
            return out.ravel()
        return kp

    def disp_factor(self, n):
        """h(t_n) of the prescribed motion."""
        return self.motion.factor(self.grid.time(n))

    def known_u(self):
        """callable(n) -> the prescribed displacements of step n at the region's nodes (3 n_disp,):
        the motion source's values at t_n (``sources.rigid``: h(t_n) [u0 + theta0 x (x - x_ref)], zero for
        a massless footing before its correction)."""
        if not self.regions.n_disp:
            return lambda n: np.zeros(0)
        if self.seismic is not None:           # the BEM carries the scattered field: u_sc = u - u_ff
            nodes = self.regions.disp_nodes
            return lambda n: self.motion.values(self.grid.time(n)) - self.free_field_at(nodes, self.grid.time(n))
        return lambda n: self.motion.values(self.grid.time(n))
