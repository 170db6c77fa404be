"""Storey demands (fem/demands.py): base shear, overturning moment, inter-storey drift ratios.

The structure: a two-storey shear frame of the project's frame elements: four columns (0.2 x 0.2 m,
E 30 GPa, two elements per storey of h = 3 m) on a 12 m x 12 m plan, clamped at z = 0, and beams
1000 times stiffer (rigid-ish floors) at z = 3 and 6 m.

Checks:
(a) static lateral loads: the drift ratios equal the hand solution of the shear frame (storey
    stiffness 4 k, k = 1 / (h^3 / (12 E I) + h / (kappa G A)) for a fixed-fixed Timoshenko column),
    the base shear is the loads' sum and the overturning moment their moment, both to round-off;
(b) dynamic equilibrium every step of a fixed-base run under a record (support motion, relative-
    motion form, the Green's-function integrator): the mean base shear of two steps equals minus the
    sum of the inertia forces with the absolute acceleration (the integrator's own: velocity
    difference over the step plus its ground-acceleration loads) and the dashpots' forces, to
    round-off, with and without mass-proportional damping;
(d) the peak envelopes written to the output equal max |series| and the time of it;
and the bad inputs are refused in one line before assembly.
"""
import h5py
import numpy as np
import pytest

from fem_helpers import run_cli

pytestmark = pytest.mark.mpi

E, NU, B, H, L = 30e9, 0.2, 0.2, 3.0, 12.0
LEVELS = (0.0, 3.0, 6.0)


def frame_msh(path):
    """The shear frame's .msh: groups columns, beams, base, lev1, lev2 (the corner nodes of each
    floor) and all (every node)."""
    from petsc_ssi.mesh.gmsh import write_msh
    corners = [(0, 0), (L, 0), (L, L), (0, L)]
    X, col, beam = [], [], []
    levels = {0: [], 1: [], 2: []}
    for (x, y) in corners:
        ids = []
        for k in range(5):                         # z = 0, 1.5, 3, 4.5, 6
            ids.append(len(X))
            X.append((x, y, 1.5 * k))
        col += [(ids[k], ids[k + 1]) for k in range(4)]
        levels[0].append(ids[0]); levels[1].append(ids[2]); levels[2].append(ids[4])
    for lev in (1, 2):
        n = levels[lev]
        beam += [(n[i], n[(i + 1) % 4]) for i in range(4)]
    groups = {"columns": ("line2", np.array(col)), "beams": ("line2", np.array(beam)),
              "base": ("point", np.array(levels[0])[:, None]), "lev1": ("point", np.array(levels[1])[:, None]),
              "lev2": ("point", np.array(levels[2])[:, None]), "all": ("point", np.arange(len(X))[:, None])}
    write_msh(path, np.array(X, float), groups)
    return np.array(X, float)


def frame_opts(msh):
    o = {"fem_mesh": msh, "fem_parts": "columns,beams", "fem_fixed": "base",
         "fem_part_columns_element": "frame", "fem_part_columns_E": E, "fem_part_columns_nu": NU,
         "fem_part_columns_rho": 2500, "fem_part_columns_section": f"{B},{B}",
         "fem_part_columns_orientation": "1,0,0",
         "fem_part_beams_element": "frame", "fem_part_beams_E": 1000 * E, "fem_part_beams_nu": NU,
         "fem_part_beams_rho": 2500, "fem_part_beams_section": "0.3,0.6", "fem_part_beams_added_mass": 2000,
         "fem_part_beams_orientation": "0,0,1", "structure_drift_levels": ",".join(map(str, LEVELS))}
    return o


class Opts:
    """Set -ssi_ options in the PETSc database for a block; resolve the fem problem's."""

    def __init__(self, **opts):
        self.opts = {k: str(v) for k, v in opts.items()}

    def __enter__(self):
        from petsc_ssi.petsc import init
        PETSc = init()
        import petsc_ssi.app.kinds  # noqa: F401  (every option declared)
        from petsc_ssi.app.kinds import resolve
        self.db = PETSc.Options()
        for k, v in self.opts.items():
            self.db.setValue("ssi_" + k, v)
        return resolve("fem")

    def __exit__(self, *exc):
        for k in self.opts:
            self.db.delValue("ssi_" + k)


@pytest.fixture(scope="module")
def msh(tmp_path_factory):
    p = str(tmp_path_factory.mktemp("frame") / "frame.msh")
    frame_msh(p)
    return p


def test_static_shear_frame_drifts_shear_and_moment(msh, PETSc):
    """(a) Lateral loads F1 = 40 kN at z = 3 and F2 = 60 kN at z = 6 (x), and 20 kN at z = 6 (y),
    spread over each floor's four corners: storey shears V2 = F2, V1 = F1 + F2, storey drift ratio
    V / (4 k h). The hand solution neglects the columns' axial shortening under the overturning
    moment (the floors rock: relative O(4 b^2 / L^2) = 1e-3) and the beams' flexibility: agreement
    within 0.3 % (measured below 0.2 %). Base shear and overturning moment: round-off."""
    from petsc_ssi.fem.model import build_model
    from petsc_ssi.fem.static import static_solve
    from petsc_ssi.fem.parts import rect_section
    from petsc_ssi.fem.demands import DemandSpec, Demands
    F1, F2, F2y = 40e3, 60e3, 20e3
    loads = f"lev1,{F1 / 4},0,0;lev2,{F2 / 4},{F2y / 4},0"
    with Opts(fem_point_load=loads, **frame_opts(msh)) as cfg:
        model = build_model(cfg, PETSc.COMM_WORLD)
        u = static_solve(model.K, model.load_vec(), model.fixed, model.mesh.coords, dofmap=model.dofmap)
        d = Demands(DemandSpec(cfg, model, "-ssi_receivers"), model, PETSc.COMM_WORLD)
    d.record(0.0, u)
    a = d.arrays()
    s = rect_section(B, B)
    G = E / (2 * (1 + NU))
    k = 1.0 / (H ** 3 / (12 * E * s["Iy"]) + H / (5.0 / 6.0 * G * s["area"]))
    hand = np.array([[(F1 + F2), F2y], [F2, F2y]]) / (4 * k * H)      # (storey, x/y)
    dr = a["drift_ratio"][0]
    assert dr.shape == (2, 2)
    err = np.abs(dr - hand).max() / np.abs(hand).max()
    print(f"static drift ratios {dr.ravel()} vs hand {hand.ravel()}: max rel. difference {err:.2e}")
    assert err < 3e-3, (dr, hand)
    assert np.array_equal(a["base_rotation"][0], [0.0, 0.0])                # a fixed base does not rock
    assert np.array_equal(a["drift_ratio_deformation"], a["drift_ratio"])
    assert np.allclose(a["base_shear"][0], [F1 + F2, F2y], rtol=1e-9, atol=0)
    ref = np.array([L / 2, L / 2, 0.0])                # auto: the base nodes' centroid at z = 0
    assert np.allclose(d.spec.ref, ref)
    Mx, My = -6.0 * F2y, 3.0 * F1 + 6.0 * F2           # M = sum z e_z x F about the base
    assert np.allclose(a["overturning_moment"][0], [Mx, My], rtol=1e-9, atol=0)
    d.destroy()


def run_fem(cfg):
    from petsc_ssi.fem.problem import FEMTransient
    prob = FEMTransient(cfg)
    res = prob.run()
    return prob, res


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """A short table 't a' [m/s^2]: two sine cycles of 4 Hz with an off-grid knot spacing."""
    t = np.arange(0.0, 0.5 + 1e-9, 0.0037)
    a = 2.0 * np.sin(2 * np.pi * 4.0 * t) * np.sin(np.pi * t / 0.5) ** 2
    p = tmp_path_factory.mktemp("rec") / "rec.txt"
    np.savetxt(p, np.c_[t, a], header="units: m/s2")
    return str(p)


@pytest.mark.parametrize("alpha_m, a1", [(0.0, 0.0), (3.0, 0.0), (3.0, 2e-3)])
def test_fixed_base_equilibrium_every_step(msh, record, tmp_path, alpha_m, a1):
    """(b) and (d). Fixed base under the record along x (relative-motion form, Green's-function
    integrator, dt 5 ms, 100 steps): every step the mean base shear of steps n-1, n equals

        -sum_free m [(v^n - v^{n-1})/dt + (ag^n + ag^{n-1})/2] - alpha_m sum_free m [vbar + dt (ag^n - ag^{n-1})/4]
        - sum_base m (a_g(t_n) + a_g(t_{n-1}))/2

    (fem/demands.py: the integrator's own equation on the free dofs summed over x; ag^n the mean
    ground acceleration over [t_n - dt/2, t_n + dt/2], the integrator's load; the base's nodes move
    with the ground, a_g(t_n) the record's value) to 1e-9 of its peak; the overturning moment
    likewise with the inertia forces' moment (rotary inertia included). The output's peak envelopes
    equal max |series| and the first time of it.
    With Rayleigh's stiffness-proportional part a1 K (issue 43) the reactions hold a1 (K v)_c (the
    dashpots across the members), and the impulse form's correction C M^{-1} dt (f^{n-1} - f^n)/4 has
    the part a1 (e^T K e) dt (ag^{n-1} - ag^n)/4, e the free nodes' unit x translation (the same
    derivation with C = alpha_m M + a1 K)."""
    out = str(tmp_path / "fb.h5")
    o = frame_opts(msh)
    o.update(problem="fem", seismic="vertical", seismic_record=record, seismic_units="m/s2", seismic_taper=0,
             seismic_baseline="none", dt=0.005, t_end=0.5, output=out, output_overwrite=1, output_stride=0,
             receivers="group:all")
    if a1:
        o["fem_rayleigh"] = f"{alpha_m!r},{a1!r}"
    else:
        o["fem_alpha_m"] = alpha_m
    with Opts(**o) as cfg:
        prob, res = run_fem(cfg)
    dt = 0.005
    rec = prob.rec.structure.rec.all_arrays()
    t, v = rec["t"], rec["velocity"]                   # (K,), (K, N, 3): every node, mean velocity at t_n
    nodes = prob.model.receiver_nodes
    assert len(t) == 101 and len(nodes) == 20
    dm, m = prob.model.dofmap, prob.model.m.getArray(readonly=True)
    z = prob.model.mesh.coords[nodes, 2]
    free = z > 1e-9
    ag = np.array([prob.support.mean_acceleration("x", tn - dt / 2, tn + dt / 2) for tn in t])
    agp = prob.support.acceleration("x", t)             # the record's value at t_n [m/s^2]
    assert np.abs(agp).max() > 1.0
    vt = v.copy()                                       # (K, N, 3) translations' velocities
    mt = m[dm.translation_dofs(nodes)]                  # (N, 3) [kg]
    # the rotations' velocities: no load acts on them, so the scheme's u^n - u^{n-1} = dt (v^n + v^{n-1}) / 2
    # holds there exactly (fem/demands.py); at rest at t = 0
    th = rec["rotation"]
    om = np.zeros_like(th)
    for n in range(1, len(t)):
        om[n] = 2.0 * (th[n] - th[n - 1]) / dt - om[n - 1]
    mr = m[dm.rotation_dofs(nodes)]                     # (N, 3) rotary masses [kg m^2]

    def inertia(vel, mass, ground):
        """(K-1, N, 3): the integrator's force balance on each node (the step means)."""
        dvel = (vel[1:] - vel[:-1]) / dt
        vbar = 0.5 * (vel[1:] + vel[:-1])
        gx = np.zeros((len(t) - 1, 1, 3))
        if ground:
            gx[:, 0, 0] = 0.5 * (ag[1:] + ag[:-1]) + alpha_m * dt * (ag[1:] - ag[:-1]) / 4
        out = -mass[None] * (dvel + gx + alpha_m * vbar)
        out[:, ~free] = 0.0
        if ground:                                      # the base nodes move with the ground: a_g(t_n)
            out[:, ~free, 0] = -mass[None, ~free, 0] * 0.5 * (agp[1:] + agp[:-1])[:, None]
        return out

    f = inertia(vt, mt, True)
    fr = inertia(om, mr, False)
    dVM = np.zeros(4)                                   # the a1 correction's (V_x, V_y, M_x, M_y) per unit
    if a1:                                              # a1 (K e) dt (ag^{n-1} - ag^n)/4 on the free dofs
        ex = np.zeros(dm.size)
        allz = prob.model.mesh.coords[:, 2]
        ex[dm.translation_dofs(np.flatnonzero(allz > 1e-9))[:, 0]] = 1.0
        e = dm.vec_from_global(ex)
        Ke = e.duplicate()
        prob.model.K.mult(e, Ke)
        ck = Ke.getArray(readonly=True).copy()          # one rank: the whole vector, in global order
        ck[np.asarray(prob.model.fixed, np.int64)] = 0.0
        R = dm.rigid_body_modes(prob.model.mesh.coords, centre=np.array([L / 2, L / 2, 0.0]))
        dVM = a1 * dt / 4 * (R[:, [0, 1, 3, 4]].T @ ck)
        assert dVM[0] == pytest.approx(a1 * dt / 4 * e.dot(Ke), rel=1e-12)   # = e^T K e
    dem = res["demands"]
    V = dem["base_shear"]
    Vbar = 0.5 * (V[1:] + V[:-1])
    scale = np.abs(V[:, 0]).max()
    assert scale > 1e3                                  # kN-range shear under a 2 m/s^2 record
    dag = (ag[:-1] - ag[1:])[:, None]
    err = np.abs(Vbar - f.sum(axis=1)[:, :2] - dag * dVM[:2]).max() / scale
    print(f"alpha_m {alpha_m}: max |mean base shear + inertia and dashpot forces| / peak = {err:.2e} "
          f"(peak {scale:.4g} N)")
    assert err < 1e-9
    # moments about the reference (L/2, L/2, 0): M = sum (x - x_ref) x f + the rotary terms
    r = prob.model.mesh.coords[nodes] - np.array([L / 2, L / 2, 0.0])
    mom = np.cross(r[None], f).sum(axis=1) + fr.sum(axis=1)
    M = dem["overturning_moment"]
    Mbar = 0.5 * (M[1:] + M[:-1])
    errM = np.abs(Mbar - mom[:, :2] - dag * dVM[2:]).max() / np.abs(M[:, 1]).max()
    print(f"alpha_m {alpha_m}: max |mean overturning moment - moment of the inertia forces| / peak = {errM:.2e}")
    assert errM < 1e-9
    with h5py.File(out, "r") as fh:
        g = fh["demands"]
        assert g["base_shear"].attrs["unit"] == "N" and g["overturning_moment"].attrs["unit"] == "N m"
        assert "exerts on the ground through its base" in g["base_shear"].attrs["convention"]
        tt = g["t"][()]
        for name in ("base_shear", "overturning_moment", "drift_ratio"):
            s = g[name][()]
            i = np.argmax(np.abs(s), axis=0)
            assert np.array_equal(g["peak_" + name][()], np.take_along_axis(np.abs(s), i[None], 0)[0])
            assert np.array_equal(g["peak_" + name + "_time"][()], tt[i])
            assert g["peak_" + name + "_time"].attrs["unit"] == "s"
        assert g["drift_ratio"].shape == (101, 2, 2) and list(g["levels"][()]) == list(LEVELS)
        assert np.array_equal(g["base_shear"][()], dem["base_shear"])


@pytest.mark.parametrize("opts,words", [
    ({"structure_drift_levels": "0,3,4.2"}, "no node of the structure within 0.01 m (-ssi_structure_level_tol) "
                                            "of z = 4.2 m (the nearest node levels: 4.5, 3, 6 m)"),
    ({"structure_drift_levels": "3,0"}, "increasing"),
    # levels that share nodes (issue 44: a tolerance of metres gave drift 0 every step)
    ({"structure_drift_levels": "0,3,6", "structure_level_tol": 3.5}, "the levels z = 0 and 3 m share"),
    ({"structure_drift_levels": "3,3.001"}, "the levels z = 3 and 3.001 m share 4 node(s)"),
    ({"structure_drift_levels": "0,a"}, "expected levels"),
    ({"structure_drift_pairs": "0:7"}, "receiver 7 does not exist (-ssi_receivers gives 2 receiver(s)"),
    ({"structure_drift_pairs": "1:0"}, "must lie above"),
    ({"structure_drift_pairs": "0-1"}, "expected 'lower:upper'"),
    ({"structure_moment_ref": "1,2"}, "expected 'x,y,z'"),
])
def test_bad_demand_options(msh, PETSc, opts, words):
    """Each misuse is an SSIError of the replicated check (DemandSpec, before any assembly)."""
    from petsc_ssi.fem.model import build_model
    from petsc_ssi.fem.demands import DemandSpec
    from petsc_ssi.petsc import SSIError
    o = frame_opts(msh)
    o.update(receivers="0,0,0;0,0,6", **opts)
    with Opts(**o) as cfg:
        model = build_model(cfg, PETSc.COMM_WORLD, assemble_matrices=False, log=lambda s: None)
        with pytest.raises(SSIError) as exc:
            DemandSpec(cfg, model, "-ssi_receivers")
    assert words in str(exc.value), str(exc.value)


def test_a_level_without_nodes_is_refused_in_one_line_before_assembly(msh, tmp_path):
    """Under mpirun -n 2 the run ends with one error line, before the matrices are assembled."""
    o = frame_opts(msh)
    o["structure_drift_levels"] = "0,3,4.2"
    args = ["-ssi_problem", "fem", "-ssi_t_end", "0.01", "-ssi_dt", "0.005", "-ssi_output", str(tmp_path / "b.h5")]
    for k, v in o.items():
        args += ["-ssi_" + k, str(v)]
    p = run_cli(args, n=2)
    errors = [ln for ln in p.stderr.splitlines() if ln.startswith("petsc-ssi: error:")]
    assert p.returncode == 2 and len(errors) == 1, p.stdout[-2000:] + p.stderr[-2000:]
    assert "z = 4.2 m" in errors[0], errors[0]
    assert "integrator" not in p.stdout and "alpha_m" not in p.stdout       # make_model_integrator's line


def test_two_ranks_equal_one(msh, record, tmp_path):
    """The fixed-base run under the record on 2 ranks writes the demands of 1 rank (the functionals'
    rows are split over the ranks and reduced every step) to 1e-10 relative."""
    out = {}
    for n in (1, 2):
        args = ["-ssi_problem", "fem", "-ssi_seismic", "vertical", "-ssi_seismic_record", record,
                "-ssi_seismic_units", "m/s2", "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none",
                "-ssi_dt", "0.005", "-ssi_t_end", "0.2", "-ssi_output_stride", "0", "-ssi_fem_alpha_m", "1",
                "-ssi_output", str(tmp_path / f"n{n}.h5"), "-ssi_receivers", "0,0,0;0,0,6",
                "-ssi_structure_drift_pairs", "0:1"]
        for k, v in frame_opts(msh).items():
            args += ["-ssi_" + k, str(v)]
        p = run_cli(args, n=n)
        assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
        with h5py.File(tmp_path / f"n{n}.h5", "r") as f:
            out[n] = {k: f["demands/" + k][()] for k in ("base_shear", "overturning_moment", "drift_ratio")}
    assert out[1]["drift_ratio"].shape == (41, 3, 2)            # two level storeys and one receiver pair
    for k in out[1]:
        a, b = out[1][k], out[2][k]
        assert np.abs(a).max() > 0 and np.abs(a - b).max() <= 1e-10 * np.abs(a).max(), k


def test_restart_from_a_checkpoint_without_demands(msh, record, tmp_path):
    """A checkpoint of a version before the demands (its serial group without them) restarts: the
    steps up to it are NaN (with a warning), the later ones equal the uninterrupted run's bit for
    bit, and the peaks skip the unknown steps. (A checkpoint with them restores them bit for bit:
    tests/test_checkpoint.py.)"""
    import shutil
    args = ["-ssi_problem", "fem", "-ssi_seismic", "vertical", "-ssi_seismic_record", record,
            "-ssi_seismic_units", "m/s2", "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none",
            "-ssi_dt", "0.005", "-ssi_t_end", "0.1", "-ssi_output_stride", "0"]
    for k, v in frame_opts(msh).items():
        args += ["-ssi_" + k, str(v)]
    ref = tmp_path / "ref.h5"
    p = run_cli(args + ["-ssi_output", str(ref), "-ssi_checkpoint", str(tmp_path / "ck-%d.h5"),
                        "-ssi_checkpoint_every", "10"])
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    ck = tmp_path / "ck-10.h5"
    with h5py.File(ck, "a") as f:
        assert "demands_values" in f["serial"]
        del f["serial/demands_t"], f["serial/demands_values"]
        # the SHA-256 of the attributes and of the datasets' CRC32 lists, as that version's writer
        # would have stamped it (issue 44: a dataset removed from a checkpoint is otherwise refused)
        from petsc_ssi.io.checkpoint import attrs_digest
        crcs = {}
        f.visititems(lambda n, o: crcs.__setitem__(n, [int(c) for c in o.attrs["crc32"]])
                     if isinstance(o, h5py.Dataset) and "crc32" in o.attrs else None)
        f.attrs["attrs_sha256"] = attrs_digest(f.attrs, crcs)
    rs = tmp_path / "rs.h5"
    shutil.copy(ref, rs)
    p = run_cli(args + ["-ssi_output", str(rs), "-ssi_restart", str(ck)])
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    assert "the checkpoint holds no storey demands" in p.stdout
    with h5py.File(ref, "r") as f, h5py.File(rs, "r") as g:
        a, b = f["demands/base_shear"][()], g["demands/base_shear"][()]
        assert np.array_equal(f["demands/t"][()], g["demands/t"][()]) and len(a) == 21
        assert np.isnan(b[:11]).all() and np.array_equal(a[11:], b[11:])
        i = 11 + np.argmax(np.abs(a[11:, 0]))
        assert g["demands/peak_base_shear"][0] == abs(a[i, 0])
        assert g["demands/peak_base_shear_time"][0] == f["demands/t"][i]
