"""Declarations of the half-space's options (group "bem": soil, mesh, integration, storage, loads,
prescribed motion, interpolation, guard). Units are SI; the free surface is z = 0, soil in z < 0."""
import os

from ..options import register, register_check, positive, at_least
from .. import common_options  # noqa: F401  (the common options every problem reads)
from ..seismic import options as _seismic_options  # noqa: F401  (the soil takes an earthquake: -ssi_seismic*)

# ---------------------------------------------------------------- BEM soil
register("cp", "real", 548.0, "m/s", "P-wave speed of the half-space", "bem", validator=positive)
register("cs", "real", 316.0, "m/s", "S-wave speed of the half-space", "bem", validator=positive)
register("rho", "real", 2000.0, "kg/m^3", "density of the half-space", "bem", validator=positive)
register("mesh", "str", "grid", "", "surface mesh: 'grid' (structured generator), 'pit' (the grid's ground with a "
         "rectangular excavation of -ssi_mesh_params a=,b=,d=: half-widths and depth in m, and x=,y=: its centre in m, "
         "default 0,0, so a long narrow one off the centre is a trench; groups ground, walls, bottom, pit) or a gmsh .geo/.msh file of nine-node quads", "bem")
register("mesh_size", "str", "16,16", "m", "grid/.geo: full extent 'Lx,Ly' of the surface, centred at the origin", "bem")
register("mesh_h", "real", 1.0, "m", "grid/.geo: element size (node spacing is h/2)", "bem", validator=positive)
register("mesh_patch", "str", "", "m", "grid/.geo: half-widths 'a,b' of a central patch named 'load' whose edges the mesh follows", "bem")
register("mesh_grade", "real", 0.0, "", "grid: clustering of the grid lines toward the patch's edges at the same number "
         "of elements, 0 (uniform) to 1 (cosine); a rigid footing's tractions are singular there", "bem",
         validator=lambda v: None if 0.0 <= v <= 1.0 else "must be in [0, 1]")
register("mesh_params", "str", "", "", ".geo soil mesh: more parameters 'name=value,...' (gmsh ONELAB 'Parameters/name'), "
         "beside Lx, Ly, xmin, ymin, h, a, b", "bem")
register("scheme", "enum", "stabilized", "", "time marching: plain (paper eq. 6) or stabilized (eq. 7)", "bem",
         choices=("plain", "stabilized", "stabilised"))
register("subdivisions", "int", 4, "per side", "equal subdivisions of each element side in natural coordinates", "bem",
         validator=at_least(1))
register("near_factor", "real", 2.0, "", "subdivide more near the collocation point: at least near_factor*h/d per side (0: off)", "bem",
         validator=lambda v: None if v >= 0 else "must be >= 0")
register("max_subdivisions", "int", 32, "per side", "cap on the near-field subdivision", "bem", validator=at_least(1))
register("gauss", "int", 2, "per direction", "Gauss points per subdivision and direction (paper: 2)", "bem", validator=at_least(1))
register("singular_order", "int", 12, "", "Gauss order of the polar (radial and angular) singular integration", "bem",
         validator=at_least(2))
register("cache", "bool", True, "", "integrate each distinct (collocation point, element) geometry once and reuse it for translated copies (exact)", "bem")
register("cache_share", "bool", True, "", "with -ssi_cache on several ranks: integrate each distinct geometry once over all "
         "ranks (its owner rank integrates it and sends it to the ranks that meet it) instead of once per rank", "bem")
register("partition", "enum", "balanced", "", "soil nodes per rank: contiguous ranges of equal estimated history "
         "products (bem/partition.py) or PETSc's equal node counts (the default on the toeplitz store, which splits "
         "its history by frequency, unless this option is given)", "bem",
         choices=("balanced", "equal"))
register("symmetry", "str", "", "", "symmetry planes, e.g. 'x=sym,y=sym' or 'x=anti': mesh only x>=0 / y>=0; every load and "
         "motion is mirrored, the components the plane makes odd (u_x on x=sym; u_y, u_z on x=anti) with their "
         "sign flipped: a load whose nodes on the plane carry such a component is refused (a vertical patch "
         "across x=anti), one off the plane is mirrored into its opposite; the mesh reaches the plane with its nodes on it "
         "(a node nearer than 1e-3 of its elements' node spacing but not on it is refused)", "bem")
register("lag_store", "enum", "dense", "", "how the lags of the history sum are stored: dense (the lag matrices, "
         "-ssi_lag_storage) or toeplitz (a uniform flat grid of equal elements, with or without symmetry planes: the H "
         "and G lags from 3 on as block-Toeplitz kernels in Fourier space, O(N) a lag instead of O(N^2), the history "
         "sum by FFTs over the ranks, lags 1-2 as Mats: bem/toeplitz.py; the same answer to round-off; refused in one line naming the first element off the grid); "
         "auto: toeplitz where the grid allows it, else dense (said in one log line)", "bem",
         choices=("dense", "toeplitz", "auto"))
register("toeplitz_precision", "enum", "double", "", "-ssi_lag_store toeplitz: the precision of the kept states' "
         "transforms (27 complex numbers per frequency and state on each side's FFT grid, kept while a kernel reads "
         "the state): double, or single (half their memory; the products still accumulate in double, the kernels "
         "stay double; the answer moves by about the single-precision rounding of the states: bem/toeplitz.py)",
         "bem", choices=("double", "single"))
register("toeplitz_fft_ranks", "int", 0, "ranks", "-ssi_lag_store toeplitz: at most this many ranks hold frequencies "
         "and make the 2-D FFTs (mpi4py-fft's slabs, bem/pfft.py; the others only send their nodes' states and take "
         "their sums); 0: every rank that a slab decomposition can take, min(ranks, Mx, My // 2 + 1) (a tuning knob "
         "where the transforms' all-to-all costs more than it divides)", "bem", validator=lambda v: None if v >= 0 else "must be >= 0")
register("lag_storage", "enum", "auto", "", "lag matrices: dense (MATDENSE), sparse (BAIJ 3x3) or auto by fill", "bem",
         choices=("auto", "dense", "sparse"))
register("history_block", "int", 0, "steps", "time-blocked history sum: the known part of the next b steps' history "
         "sums formed together, one matrix-panel product per stored matrix (1: step by step, the reference; 0: "
         "automatic: the size that minimises a modelled time per step, from the stored matrices' bytes; 16 on the "
         "toeplitz store)", "bem",
         validator=lambda v: None if 0 <= v <= 32 else "must be in [0, 32]")
register("step_mirror", "enum", "auto", "", "auto: where the soil surface, its prescribed-displacement and traction "
         "nodes mirror about x = c and/or y = c (c the mesh's mid-point) and the step matrix commutes with the "
         "reflections, its LU is that of the 2 or 4 independent blocks of the symmetric and antisymmetric parts (fewer "
         "entries in the factors: faster step solves; checked on a test right-hand side, else the matrix as it is, "
         "said in one line; bem/mirror.py); off: the matrix as it is", "bem", choices=("auto", "off"))
register("step_blr", "real", -1.0, "", "the step matrix's MUMPS LU in block low-rank form (ICNTL(35) 2) at this "
         "precision CNTL(7): faster step solves on large grids, the factors checked on a test right-hand side "
         "(residual <= 1e-12, else full rank, said in one line); 0: full rank; -1 (auto): 1e-15 from 20 000 DOFs on, "
         "full rank below (bem/march.py)", "bem",
         validator=lambda v: None if v == -1 or 0 <= v < 1e-3 else "must be -1 (auto), 0 (full rank) or in (0, 1e-3)")
register("history_sub", "int", 0, "steps", "sub-blocks of the time-blocked history sum: at each sub-block's "
         "start the terms of the block's states known by then are formed as panel products too, so only lags up to "
         "about s + 2 stay in per-step products (s >= -ssi_history_block: one level; 0: automatic, with the block "
         "size)", "bem", validator=lambda v: None if 0 <= v <= 32 else "must be in [0, 32]")
register("lag_pattern", "enum", "auto", "", "the entries a 3x3 block of the lag matrices stores: auto (where every "
         "collocation point and element lie in one plane, as on every surface petsc-ssi accepts, H keeps the 4 "
         "entries coupling in-plane with out-of-plane components and G the 5 of the in-plane pair and zz, the others "
         "being exact zeros: bem/bsr.py; on a surface with an excavation H's blocks whose pairs all lie in one "
         "horizontal plane, the ground's or the pit's bottom's, keep those 4 and the others all 9: bsr.SplitBSR) or "
         "full (all 9 everywhere: the general path, to check the flat one or to measure what it saves; the same "
         "results to round-off)", "bem", choices=("auto", "full"))
register("lag_fill", "real", 0.95, "", "auto storage: lags with block fill above this are dense (0.95: dense where it "
         "stores fewer bytes; per block of the whole lag dense 8 m B against 8 m + 4 B per stored block, m the "
         "entries of the block pattern, -ssi_lag_pattern)", "bem",
         validator=lambda v: None if 0 <= v <= 1 else "must be in [0, 1]")
register("lag_single_from", "int", 0, "lag", "store the lags from this one on in single precision: float32 "
         "block-sparse (4 m + 4 B per 3x3 block of m stored entries, against 8 m + 4 B block-sparse or 8 m B per block "
         "dense; m = 4 for H on a flat surface, -ssi_lag_pattern), also the "
         "interpolating matrices that stand for them (an interpolating matrix counts as the lag of its kernel time, "
         "rounded down: the first one is usually the last exact lag); the products accumulate in double. 0: every "
         "lag in double; lags 1 and 2 (the step matrix) stay double", "bem",
         validator=lambda v: None if v == 0 or v >= 3 else "must be 0 (off) or a lag >= 3 (lags 1 and 2 form the "
         "step matrix and stay double)")
register("memory_limit", "real", 0.0, "GB", "refuse runs whose lag matrices need more than this per node (0: 80% of this machine's memory); the run's estimated peak is shared by its ranks", "bem",
         validator=lambda v: None if v >= 0 else "must be >= 0")
register("load_group", "str", "", "", "loaded elements: a physical group name, or 'box:x0,x1,y0,y1' (element centres inside)", "bem")
register("load_area", "str", "", "m", "a loaded rectangle 'x0,x1,y0,y1' of the surface z = 0, integrated as it is "
         "whatever the cells (it need not follow them; sources/area.py); instead of -ssi_load_group, with its p0 "
         "and history", "bem")
register("load_p0", "real", 0.0, "N/m^2", "uniform pressure on the loaded elements or -ssi_load_area (p0 > 0 pushes the surface down)", "bem")
register("load_history", "enum", "heaviside", "", "time history of the load: heaviside, box (p0 on [0, t0)), table", "bem",
         choices=("heaviside", "box", "table"))
register("load_t0", "real", 0.025, "s", "duration of the box pulse", "bem", validator=positive)
register("load_table", "str", "", "", "file of 't value' rows (value multiplies p0), linearly interpolated", "bem")
register("disp_group", "str", "", "", "elements with a prescribed displacement (group name or 'box:...')", "bem")
register("disp_value", "str", "0,0,0", "m", "prescribed displacement 'ux,uy,uz' (times the history): the translation "
         "u0 of the rigid motion u = h(t) [u0 + theta0 x (x - x_ref)]", "bem")
register("disp_rotation", "str", "0,0,0", "rad", "small rotation 'rx,ry,rz' theta0 of the prescribed rigid motion "
         "about the axes through -ssi_disp_ref (times the history)", "bem")
register("disp_ref", "str", "0,0,0", "m", "reference point x_ref of the rigid motion and of the recorded moments of "
         "the -ssi_disp_group region's traction", "bem")
register("disp_history", "enum", "heaviside", "", "time history of the prescribed displacement: heaviside, box, table, "
         "smoothstep ((1 - cos(pi t/t0))/2 up to t0, then 1)", "bem", choices=("heaviside", "box", "table", "smoothstep"))
register("disp_t0", "real", 0.025, "s", "duration of the box history, rise time of the smoothstep", "bem", validator=positive)
register("disp_table", "str", "", "", "file of 't value' rows for the prescribed displacement", "bem")
register("disp_rigid", "enum", "prescribed", "", "the -ssi_disp_group region's rigid motion: prescribed "
         "(-ssi_disp_value/_rotation/_history), or massless: a rigid massless footing under the seismic input "
         "(-ssi_seismic), its motion the unknown that makes the soil's resultant force and moment on it zero "
         "every step (kinematic interaction; the foundation input motion about -ssi_disp_ref, default the "
         "region's centroid, written to the output group input_motion; petsc-ssi input-motion)", "bem",
         choices=("prescribed", "massless"))
register("lags_save", "str", "", "", "save the assembled lag matrices (PETSc binary FILE and FILE.json with the "
         "key of what they depend on and the CRC32 of FILE's content; on the toeplitz store the step matrix, lags 1-2 and "
         "the kernels, frequency-major, k_y-major: any rank count loads them) for -ssi_lags_load", "bem")
register("lags_load", "str", "", "", "load the lag matrices a run saved with -ssi_lags_save instead of assembling "
         "them (refused, naming the difference, unless mesh, material, dt, scheme, symmetry, interpolation, "
         "quadrature and traction nodes are the same, on the toeplitz store also the store, and a file "
         "whose content differs from its CRC32s)", "bem")
register("interp", "enum", "none", "", "lag-matrix interpolation beyond T_L: none, chebyshev (eqs. 9, 11), linear (eqs. 10, 12), auto (paper's rule; on "
         "the toeplitz store every lag exact where that fits the node, said in one line)", "bem",
         choices=("none", "chebyshev", "linear", "auto"))
register("interp_tl", "real", 0.0, "s", "threshold time T_L: lags with (l-1) dt < T_L are exact (auto: chosen)", "bem",
         validator=lambda v: None if v >= 0 else "must be >= 0")
register("interp_k", "int", 0, "", "number k of interpolating matrices (auto: one every 5 steps)", "bem",
         validator=lambda v: None if v >= 0 else "must be >= 0")
register("interp_grading", "real", 1.0, "", "multi-linear node grading exponent p in T_j = T_L + (T_N-T_L)((j-1)/(k-1))^p", "bem",
         validator=lambda v: None if v > 0 else "must be > 0")
register("guard", "bool", True, "", "stop a run whose solution norm is clearly diverging, naming the likely cause (with "
         "-ssi_seismic only a non-finite norm: the scattered field grows as the wave arrives)", "bem")
register("guard_factor", "real", 100.0, "", "guard: stop when |u| exceeds this times the largest |u| of the first half of the run so far", "bem",
         validator=lambda v: None if v > 1 else "must be > 1")
register("check_stability", "bool", False, "", "only check stability: run a coarse surrogate (3x3-element quarter model, same "
         "element size, dt, scheme, interpolation) for a few hundred steps and print a verdict (runs/stability)", "bem")
register("check_stability_steps", "int", 400, "steps", "-ssi_check_stability: at least this many steps (and at least "
         "3 x the surrogate's causal lags)", "bem", validator=at_least(100))
register("warn_beta", "bool", True, "", "warn when beta_s = c_s dt / l leaves what the stability map (runs/stability) "
         "found stable for the scheme in use", "bem")
register("warn_edge", "bool", True, "", "warn when waves from the loads, the footing or the structure, diffracted at the "
         "mesh's edge, reach a receiver, the footing or the structure before t_end (petsc-ssi impedance states its "
         "a0 band instead)", "bem")


MAX_CP = 1.0e4           # m/s: beyond any soil or rock (a P-wave speed of 1e7 m/s ran: nu -> 0.5, dt c_p / h huge)


def _bem_checks(cfg):
    if cfg.cs >= cfg.cp:
        return f"-ssi_cs {cfg.cs} must be smaller than -ssi_cp {cfg.cp}"
    if cfg.cp < cfg.cs * 2 ** 0.5 * 0.999999:
        return (f"-ssi_cp/-ssi_cs = {cfg.cp / cfg.cs:.4f} < sqrt(2): Poisson's ratio would be negative "
                "(not supported)")
    if cfg.cp > MAX_CP:
        r2 = (cfg.cp / cfg.cs) ** 2
        return (f"-ssi_cp {cfg.cp:g} m/s is faster than any soil or rock (granite about 6000 m/s; Poisson's ratio "
                f"{(r2 - 2) / (2 * (r2 - 1)):.9f}): check the units (m/s) or give a P-wave speed <= {MAX_CP:g} m/s")
    if cfg.t_end < cfg.dt:
        return f"-ssi_t_end {cfg.t_end} is shorter than one step -ssi_dt {cfg.dt}"
    if cfg.mesh in ("grid", "pit"):
        try:
            lx, ly = (float(v) for v in str(cfg.mesh_size).split(","))
        except ValueError:
            lx = ly = None                   # the mesh generator reports the format
        if lx is not None and min(lx, ly) <= 0:
            return f"-ssi_mesh_size {cfg.mesh_size}: the mesh's extent must be positive in x and y [m]"
        if cfg.mesh_h <= 0:
            return f"-ssi_mesh_h {cfg.mesh_h:g}: the element size must be positive [m]"
        if lx is not None and cfg.mesh_h > min(lx, ly):
            return (f"-ssi_mesh_h {cfg.mesh_h:g} m is larger than the mesh (-ssi_mesh_size {cfg.mesh_size}): the grid "
                    f"would have elements of {min(lx, ly):g} m, not the size asked; give -ssi_mesh_h <= "
                    f"{min(lx, ly):g} m or a larger -ssi_mesh_size")
    if cfg.mesh_grade and (cfg.mesh != "grid" or not cfg.mesh_patch):
        return ("-ssi_mesh_grade: only the grid generator (-ssi_mesh grid) grades its lines, toward the edges of "
                "-ssi_mesh_patch; give both, or leave -ssi_mesh_grade out")
    if cfg.mesh not in ("grid", "pit") and not os.path.isfile(cfg.mesh):
        return f"-ssi_mesh {cfg.mesh}: no such file"
    if cfg.interp in ("chebyshev", "linear") and (cfg.interp_k < 1 or cfg.interp_tl <= 0):
        return f"-ssi_interp {cfg.interp} needs -ssi_interp_tl > 0 and -ssi_interp_k >= 1 (or use -ssi_interp auto)"
    if cfg.mesh_patch:
        try:
            a, b = (float(v) for v in str(cfg.mesh_patch).split(","))
            lx, ly = (float(v) for v in str(cfg.mesh_size).split(","))
        except ValueError:
            a = b = lx = ly = None           # the mesh generator reports the format
        if a is not None and (a >= lx / 2 or b >= ly / 2):
            return (f"-ssi_mesh_patch {cfg.mesh_patch}: the patch (half-widths) reaches the edge of the mesh "
                    f"-ssi_mesh_size {cfg.mesh_size} (full extent); make the mesh larger or the patch smaller")
    if cfg.get("disp_rigid", "prescribed") == "massless" and cfg.get("coupling") is None:   # (ssi: its own check)
        if not cfg.disp_group:
            return "-ssi_disp_rigid massless: give the footing as -ssi_disp_group (a group or 'box:x0,x1,y0,y1')"
        if cfg.get("seismic", "none") == "none":
            return ("-ssi_disp_rigid massless needs a seismic input (-ssi_seismic vertical|sh|sv|p|rayleigh): "
                    "without a wave a massless footing stays at rest")
        for name in ("disp_value", "disp_rotation", "disp_history", "disp_t0", "disp_table"):
            if cfg.user_set(name):
                return f"-ssi_disp_rigid massless: the footing's motion is the unknown; drop -ssi_{name}"
    if int(cfg.get("toeplitz_fft_ranks", 0) or 0) and cfg.get("lag_store", "dense") == "dense":
        return ("-ssi_toeplitz_fft_ranks: the FFTs are the toeplitz store's; add -ssi_lag_store toeplitz (or auto on a "
                "uniform flat grid)")
    if int(cfg.get("lag_single_from", 0) or 0) and cfg.get("lag_store", "dense") == "toeplitz":
        return ("-ssi_lag_single_from keeps lag matrices in single precision, which the toeplitz store has not "
                "(its kernels stay double; -ssi_toeplitz_precision single rounds its kept transforms): drop one of them")
    if cfg.get("toeplitz_precision", "double") != "double" and cfg.get("lag_store", "dense") == "dense":
        return ("-ssi_toeplitz_precision single: the kept transforms are the toeplitz store's; add -ssi_lag_store "
                "toeplitz (or auto on a uniform flat grid)")
    if cfg.load_group and cfg.get("load_area", ""):
        return ("-ssi_load_group and -ssi_load_area: give one of them (the area is the loaded rectangle itself, "
                "the group its cells)")
    if cfg.get("load_area", ""):
        from ..petsc import SSIError
        from ..sources.area import parse_rect
        try:
            parse_rect(cfg.load_area)
        except SSIError as exc:
            return str(exc)
    loaded = cfg.load_group or cfg.get("load_area", "")
    if cfg.load_history == "table" and loaded and not os.path.isfile(cfg.load_table):
        return f"-ssi_load_table '{cfg.load_table}': no such file"
    return None


register_check(("bem",), _bem_checks)
