"""A structure in an excavation (issue 42, items 2 and 4): the coupled FEM-BEM run on a soil surface with a
pit, the structure's faces below the ground (walls and bottom) matched to the soil's, and under a wave
the free field's traction t_ff = sigma_ff n on them handed to the structure with the soil's scattered
traction (``sources.free_field.InterfaceFreeField``; the contact law takes the total).

The check that needs no reference solution: a pit filled with finite elements of the same soil
(-ssi_fem_cp/-ssi_fem_cs/-ssi_fem_rho: a soil region) scatters nothing, so the coupled run must
reproduce the free field, in the region and in the soil around it:
  * vertically incident S (a sin^4 pulse of 40 ms, wavelength 12.6 m), pit 2 x 2 x 1 m, soil elements
    1 m, bricks 0.5 m: the region's top centre and a node inside it follow the closed-form free field
    within 5e-4 of its peak (measured 1.9e-4 and 1.3e-4), the interface nodes within 3e-3 (1.35e-3),
    the soil's surface 1 m from the pit within 5e-4 (1.8e-4); the force of the soil on the region is
    the region's inertia int rho u_ff'' dV = rho A (c_s / 2) [v(t - t0 + d/c_s) - v(t - t0 - d/c_s)]
    within 2 % of its peak (measured 1.0 %);
  * oblique SV at 30 degrees: the interface nodes within 1.5e-2 of the free field's peak (8.4e-3);
  * with 0.5 m elements and 0.25 m bricks (slow tier) the errors fall: interface 1.35e-3 -> 6.9e-4
    (vertical), 8.4e-3 -> 4.4e-3 (SV); the region's top 1.9e-4 -> 1.0e-4;
  * the free field's traction on the interface is needed: scaled by 0 (the soil's scattered traction
    alone, what a plane surface needs) the interface nodes are off by 9.0e-3 of the peak, by 8.9e-3 with
    twice it and 1.7e-2 with its opposite, against 1.1e-3 with it (measured once by scaling the term in a
    scratch copy, with the nodal tractions at the nodes' mean normals that preceded the consistent
    force; not kept as a test);
  * the quarter model (symmetry planes x = 0 anti, y = 0 sym through the pit) equals the whole to 1e-12;
  * -n 2 equals -n 1; refusals in one line.
Known and not fixed: the interface's nodal scattered traction (the output's interface/p minus
interface/pff) is a self-equilibrated field of the size of t_ff over the whole bottom (0.75 of its peak
at the nine-node elements' corners, 0.15-0.45 at the other nodes, at both meshes:
runs/soil_region/edge_traction.py), though its resultant is 1 % of the free field's; it does not fall
with the mesh; displacements and resultants do.
"""
import h5py
import numpy as np
import pytest

from helpers import cli, sin4_pulse

pytestmark = pytest.mark.mpi

CS, CP, RHO = 316.0, 548.0, 2000.0


pulse = sin4_pulse          # (tests/helpers.py)


def args(tmp, name, h=1.0, wave="vertical", angle=0.0, T=0.04, extra=()):
    n, nz = int(round(4 / h)), int(round(2 / h))
    return ["run", "-ssi_problem", "ssi", "-ssi_mesh", "pit", "-ssi_mesh_params", "a=1,b=1,d=1",
            "-ssi_mesh_size", "6,6", "-ssi_mesh_h", str(h), "-ssi_dt", str(0.0025 * h), "-ssi_t_end", "0.14",
            "-ssi_seismic", wave, "-ssi_seismic_angle", str(angle),
            "-ssi_seismic_record", pulse(tmp / f"p{T}.txt", T), "-ssi_seismic_units", "m/s2",
            "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none",
            "-ssi_fem_mesh", "box", "-ssi_fem_box_cells", f"{n},{n},{nz}", "-ssi_fem_box_size", "2,2,1",
            "-ssi_fem_box_origin", "-1,-1,-1", "-ssi_fem_interface", "xmin,xmax,ymin,ymax,base",
            "-ssi_fem_cp", str(CP), "-ssi_fem_cs", str(CS), "-ssi_fem_rho", str(RHO),
            "-ssi_receivers", "2,0,0", "-ssi_structure_receivers", "0,0,0;0,0,-0.5",
            "-ssi_output", str(tmp / name), "-ssi_output_overwrite", "1", "-ssi_warn_beta", "0", *extra]


def free_field_x(f, P, t):
    """Vertical S: u_x(z, t) = [D(t - t0 - z/c_s) + D(t - t0 + z/c_s)] / 2 at points P, times t [m]."""
    D, td, t0 = f["seismic/x_displacement"][:], f["seismic/x_t"][:], float(f["seismic/t0"][()])
    return np.stack([0.5 * (np.interp(t - t0 - p[2] / CS, td, D, left=0.0) +
                            np.interp(t - t0 + p[2] / CS, td, D, left=0.0)) for p in P], axis=1)


def interface_error(path):
    """max |u_f - u_ff| over the interface nodes and steps / max |u_ff|."""
    with h5py.File(path) as f:
        g = f["interface"]
        uf, uff = g["uf"][:], g["uff"][:]
    return np.abs(uf - uff).max() / np.abs(uff).max()


def region_errors(tmp, name):
    """(region's receivers' error, soil receiver's error, force error), each / its free-field peak."""
    path = str(tmp / name)
    with h5py.File(path.replace(".h5", "_structure.h5")) as fs, h5py.File(path) as f:
        ts, Ps, us = fs["receivers/t"][:], fs["receivers/points"][:], fs["receivers/u"][:]
        uffs = free_field_x(f, Ps, ts)
        t, P, u = f["receivers/t"][:], f["receivers/points"][:], f["receivers/u"][:]
        uff = free_field_x(f, P, t)
        ti, F = f["interface/t"][:], f["interface/force_fe"][:, 0]
        D, td, t0 = f["seismic/x_displacement"][:], f["seismic/x_t"][:], float(f["seismic/t0"][()])
    pk = np.abs(uffs).max()
    e_region = np.abs(us[:, :, 0] - uffs).max() / pk
    e_soil = max(np.abs(u[:, 0, 0] - uff[:, 0]).max(), np.abs(u[:, 0, 1:]).max()) / pk
    # the region's inertia, the step's mean: (rho A c_s / 2) [v(t + d/c_s) - v(t - d/c_s)] averaged over
    # (t_{n-1}, t_n] is a difference of displacements over dt (A = 4 m^2, d = 1 m)
    dt, d = ti[1] - ti[0], 1.0

    def vmean(s):
        return (np.interp(ti - t0 + s, td, D, left=0.0) - np.interp(ti - dt - t0 + s, td, D, left=0.0)) / dt
    F_ref = RHO * 4.0 * CS / 2.0 * (vmean(d / CS) - vmean(-d / CS))
    e_force = np.abs(F - F_ref).max() / np.abs(F_ref).max()
    return e_region, e_soil, e_force


def quarter(tmp, name, **kw):
    """The same run on the quarter x >= 0, y >= 0 with x=anti, y=sym (a wave polarised along x)."""
    a = args(tmp, name, **kw)
    n = a.index("-ssi_fem_box_cells")
    c = [int(v) // (2 if k < 2 else 1) for k, v in enumerate(a[n + 1].split(","))]
    a[n + 1] = ",".join(map(str, c))
    a[a.index("-ssi_fem_box_size") + 1] = "1,1,1"
    a[a.index("-ssi_fem_box_origin") + 1] = "0,0,-1"
    a[a.index("-ssi_fem_interface") + 1] = "xmax,ymax,base"
    return a + ["-ssi_symmetry", "x=anti,y=sym"]


def test_a_pit_filled_with_the_same_soil_moves_with_the_free_field(tmp_path):
    cli(args(tmp_path, "v.h5"))
    # symmetry planes through the pit: the quarter model is the whole one (interface nodes matched by
    # position; every series to 1e-12 of its largest value: measured 3e-13 for the traction)
    cli(quarter(tmp_path, "q.h5"))
    with h5py.File(tmp_path / "v.h5") as fa, h5py.File(tmp_path / "q.h5") as fb:
        xa, xb = fa["interface/x"][:], fb["interface/x"][:]
        idx = [int(np.nonzero(np.all(np.abs(xa - p) < 1e-9, axis=1))[0][0]) for p in xb]
        assert len(idx) == 19 and len(xa) == 57
        for k in ("uf", "ub", "p", "pff"):
            A, B = fa["interface/" + k][:][:, idx], fb["interface/" + k][:]
            assert np.abs(A - B).max() <= 1e-12 * np.abs(A).max(), k
        assert np.abs(fa["receivers/u"][:] - fb["receivers/u"][:]).max() <= 1e-12 * np.abs(fa["receivers/u"][:]).max()
    e_region, e_soil, e_force = region_errors(tmp_path, "v.h5")
    assert e_region < 5e-4, e_region
    assert e_soil < 5e-4, e_soil
    assert e_force < 0.02, e_force
    assert interface_error(tmp_path / "v.h5") < 3e-3
    with h5py.File(tmp_path / "v.h5") as f:
        g = f["interface"]
        x, pff = g["x"][:], g["pff"][:]
        assert g["pff"].attrs["unit"] == "N/m^2"
    # the walls and the bottom are the interface (57 nodes of 12 elements), and the free field's traction
    # is there and not zero (sigma_xz on the bottom, a vertical shear on the x walls)
    assert len(x) == 57 and x[:, 2].min() == -1.0 and np.abs(pff).max() > 1e3


def test_an_oblique_sv_wave_too(tmp_path):
    cli(args(tmp_path, "sv.h5", wave="sv", angle=30.0))
    assert interface_error(tmp_path / "sv.h5") < 1.5e-2


# slow tier: 0.5 m elements and 0.25 m bricks (25 s each); the default-tier siblings above run 1 m
@pytest.mark.slow
@pytest.mark.parametrize("wave,angle,coarse", [("vertical", 0.0, 1.35e-3), ("sv", 30.0, 8.38e-3)])
def test_the_filled_pit_converges_with_the_mesh(tmp_path, wave, angle, coarse):
    cli(args(tmp_path, "f.h5", h=0.5, wave=wave, angle=angle))
    e = interface_error(tmp_path / "f.h5")
    assert e < 0.6 * coarse, (e, coarse)            # measured 0.51 and 0.52 of the 1 m mesh's error
    if wave == "vertical":
        e_region, _, _ = region_errors(tmp_path, "f.h5")
        assert e_region < 1.5e-4, e_region          # 1.0e-4 (1.9e-4 on the 1 m mesh)


# slow tier: two runs, 10-20 s; the default tier's siblings: the refusals below at -n 2, and the filled pit
# at -n 1
@pytest.mark.slow
def test_two_ranks_equal_one(tmp_path):
    cli(args(tmp_path, "a.h5", T=0.02))
    cli(args(tmp_path, "b.h5", T=0.02), nranks=2)
    compared = 0
    for stem in ("", "_structure"):
        with h5py.File(tmp_path / f"a{stem}.h5") as fa, h5py.File(tmp_path / f"b{stem}.h5") as fb:
            names = []
            fa.visititems(lambda k, o: names.append(k) if isinstance(o, h5py.Dataset) and o.dtype.kind == "f"
                          and ("displacement" in k or "interface/" in k or "receivers/u" in k) else None)
            for k in names:
                if "residual" in k or "error" in k:          # round-off diagnostics
                    continue
                a, b = fa[k][...], fb[k][...]
                assert np.abs(a - b).max() <= 1e-9 * max(np.abs(a).max(), 1e-300), k
                compared += np.abs(a).max() > 0
    assert compared >= 8                      # fields that move, soil and structure


@pytest.mark.parametrize("extra,msg", [
    (("-ssi_fem_box_origin", "-1,-1,0.5"), "none of these faces lies below the ground z = 0"),
    (("-ssi_fem_box_origin", "-1,-1,0"), "no soil element has all nine nodes on the structure"),
])      # (the wave speeds' refusals: tests/fem/test_soil_parts.py)
def test_bad_input_is_refused_in_one_line_on_every_rank(tmp_path, extra, msg):
    p = cli(args(tmp_path, "r.h5", T=0.02, extra=extra), nranks=2, check=False)
    assert p.returncode != 0
    lines = [ln for ln in (p.stdout + p.stderr).splitlines() if "error" in ln]
    assert lines and all(msg in ln for ln in lines), p.stdout + p.stderr
    assert len(lines) == 1 or len(set(lines)) == 1


# slow tier: the 6 m box's quarter model (7 s); the default tier's siblings: the 1D reference below and the
# filled pit above (the same coupling of a soil region under a wave)
@pytest.mark.slow
def test_a_soft_layer_in_a_narrow_box_resonates_as_a_box(tmp_path):
    """runs/soil_region/soft_layer.py at W = 6 m, H = 2 m (its quarter model, -ssi_symmetry x=anti,y=sym): the
    surface centre's transfer function peaks near the rigid-walled box's first mode f0 sqrt(1 + 2 (2H/W)^2) =
    27.1 Hz (measured 27.95 Hz), well above the 1D layer's c_s1/4H = 19.75 Hz, and amplifies more than the 1D
    layer's 1/alpha = 2.22 (measured 4.77): the box's width matters at W/H = 3."""
    from helpers import run_script
    m = run_script("runs", "soil_region", "soft_layer.py")
    out = str(tmp_path / "W6.h5")
    m.run(6.0, 1, out)
    f, tf = m.transfer(out)
    keep = f <= 40.0
    k = int(np.argmax(tf[keep]))
    fr = m.F0 * np.sqrt(1 + 2 * (2 * m.H / 6.0) ** 2)
    assert abs(f[keep][k] - fr) < 0.05 * fr, (f[keep][k], fr)
    assert tf[keep][k] > 1.5 / m.ALPHA


def test_the_one_d_reference_is_the_layer_on_its_half_space():
    """soft_layer.one_d(complex_=True), the 1D layer's response to the outcrop motion at the ground surface,
    against an independent 1D model (100 linear elements on the half-space's exact dashpot boundary, Newmark
    at 20 us: measured 2.2e-3 of the peak, the column drifting slowly on its dashpot after the pulse; 4.7e-4
    on the record of the runs); the textbook ratio alone (the outcrop at the layer's base) lags it
    by H/c_s = 6.3 ms, far outside that tolerance."""
    from helpers import run_script
    m = run_script("runs", "soil_region", "soft_layer.py")
    T = 0.02

    def outcrop(t):
        return 1e-5 * np.where((t > 0.005) & (t < 0.005 + T), np.sin(np.pi * (t - 0.005) / T) ** 4, 0.0)
    t, top = m.one_d_column(0.15, outcrop)
    n = 16 * len(t)
    fr = np.fft.rfftfreq(n, t[1] - t[0])
    U = np.fft.rfft(outcrop(t), n)
    one = np.fft.irfft(U * m.one_d(fr, True), n)[:len(t)]
    base = np.fft.irfft(U / (np.cos(2 * np.pi * fr / m.CS1 * m.H) + 1j * m.ALPHA * np.sin(2 * np.pi * fr / m.CS1 * m.H)),
                        n)[:len(t)]
    peak = np.abs(top).max()
    assert np.abs(top - one).max() < 5e-3 * peak
    assert np.abs(top - base).max() > 0.3 * peak
    assert np.allclose(m.one_d(fr[:50]), np.abs(m.one_d(fr[:50], True)))


@pytest.mark.parametrize("zeta", [0.05, 0.2])
def test_the_damped_one_d_reference_is_the_damped_layer_on_its_half_space(zeta):
    """soft_layer.one_d(zeta=...), the layer with stiffness-proportional damping a1 K (ratio zeta at f0) in its
    complex modulus, against the same independent 1D column with C = a1 K in the layer (measured 2.8e-3 and
    3.8e-3 of the peak, the elastic column's 2.2e-3); the damping lowers the peak ratio below the elastic
    layer's 1/alpha = 2.22 (1.91 at 18.7 Hz and 1.44 at 15.6 Hz) and the response (the column's peak 30 % and
    53 % under the elastic one's)."""
    from helpers import run_script
    m = run_script("runs", "soil_region", "soft_layer.py")
    T = 0.02

    def outcrop(t):
        return 1e-5 * np.where((t > 0.005) & (t < 0.005 + T), np.sin(np.pi * (t - 0.005) / T) ** 4, 0.0)
    t, top = m.one_d_column(0.15, outcrop, zeta=zeta)
    _, elastic = m.one_d_column(0.15, outcrop)
    n = 16 * len(t)
    fr = np.fft.rfftfreq(n, t[1] - t[0])
    one = np.fft.irfft(np.fft.rfft(outcrop(t), n) * m.one_d(fr, True, zeta=zeta), n)[:len(t)]
    peak = np.abs(top).max()
    assert np.abs(top - one).max() < 5e-3 * peak
    assert peak < (0.9 if zeta < 0.1 else 0.6) * np.abs(elastic).max()
    a0, a1 = m.rayleigh(zeta)
    assert a0 == 0.0 and abs(a1 * np.pi * m.F0 - zeta) < 1e-12 * zeta
    assert 1.0 < m.one_d(np.array([m.F0]), zeta=zeta)[0] < 1 / m.ALPHA


# slow tier: the soft layer's quarter model against the whole one and the 10 m box against the 1D layer
# (about 90 s); the default tier's siblings: the 6 m box's quarter model and the 1D reference above
@pytest.mark.slow
def test_the_soft_layer_quarter_model_equals_the_whole_one(tmp_path):
    """W = 6 m: the quarter model's surface centre equals the whole model's to round-off."""
    import h5py
    from helpers import run_script
    m = run_script("runs", "soil_region", "soft_layer.py")
    u = {}
    for q in (True, False):
        out = str(tmp_path / f"W6{q}.h5")
        m.run(6.0, 1, out, quarter=q)
        with h5py.File(out.replace(".h5", "_structure.h5")) as fs:
            u[q] = fs["receivers/u"][:, 0, :]
    assert np.abs(u[True] - u[False]).max() < 1e-9 * np.abs(u[False]).max()


# slow tier: see test_the_soft_layer_quarter_model_equals_the_whole_one
@pytest.mark.slow
def test_the_centre_of_a_wide_soft_box_follows_the_one_d_layer_until_the_walls_waves_arrive(tmp_path):
    """W = 10 m (W/H = 5): until t0 + (W/2)/c_s the centre's velocity (low-passed 25-40 Hz) is the 1D layer's
    within 6 % of its peak (measured 3.5 %); over the whole run it is not (measured 40 %: the walls' waves,
    trapped in the soft layer, keep ringing at the centre)."""
    from helpers import run_script
    m = run_script("runs", "soil_region", "soft_layer.py")
    out = str(tmp_path / "W10.h5")
    m.run(10.0, 1, out)
    e_edge, e_all, rms = m.window_errors(out, 10.0)
    assert e_edge < 0.06, e_edge
    assert e_all > 0.2 and rms > 1.2, (e_all, rms)


def test_unilateral_contact_in_a_pit_is_warned_about(tmp_path):
    """Unilateral contact in an excavation with open nodes free in every direction (-ssi_contact_separation free,
    the default) warns at set-up that its active set does not settle there (test_pit_contact.py); with auto it
    does not warn."""
    a = args(tmp_path, "u.h5", T=0.02, extra=("-ssi_contact", "unilateral"))
    a[a.index("-ssi_t_end") + 1] = "0.005"
    p = cli(a)
    assert "the active set is known not to settle there" in p.stdout + p.stderr
    p = cli(a + ["-ssi_contact_separation", "auto"])
    assert "not to settle" not in p.stdout + p.stderr


def test_the_pit_footing_mesh_puts_nodes_every_half_h_on_the_pit(tmp_path):
    """meshes/pit_footing.geo: the region's walls and bottom carry the pit's nine-node grid (nodes every h/2),
    the footing's base is shared with the region's top; a footing half-width off the h/2 lattice is refused
    in one line (run in a subprocess: a gmsh error in this process would fail its next .geo)."""
    from helpers import run_script
    from petsc_ssi.mesh import gmsh as reader
    p = {"a": 1.0, "b": 1.0, "d": 1.0, "c": 0.5, "hf": 0.5, "h": 1.0, "fill": 1.0}
    m = reader.read("meshes/pit_footing.geo", dim=3, params=p, user=tuple(p))
    pit = m.coords[m.groups["pit"].nodes]
    assert len(pit) == 57                      # the 12 nine-node soil elements' nodes of -ssi_mesh pit
    assert np.allclose(np.round(pit * 2) / 2, pit)
    assert len(set(m.groups["base"].nodes) & set(m.groups["soil"].nodes)) == 9
    fp = run_script("runs", "soil_region", "footing.py")
    a = [s.replace("c=0.5,", "c=0.3,") for s in fp.args("filled", 1.0, str(tmp_path / "r.h5"),
                                                                fp.pulse_table(str(tmp_path / "p.txt")))]
    r = cli(["run"] + a, check=False)
    lines = [ln for ln in (r.stdout + r.stderr).splitlines() if "error" in ln]
    assert r.returncode != 0 and len(lines) == 1 and "must be multiples of h/2" in lines[0], r.stdout + r.stderr


# slow tier: four runs, 51-67 s on 1 rank; the default-tier siblings: the filled pit and the pit_footing mesh above
@pytest.mark.slow
def test_a_footing_on_the_filled_pit_responds_as_on_the_plain_half_space(tmp_path):
    """runs/soil_region/footing.py: a stiff 1 x 1 x 0.5 m block on a 2 x 2 x 1 m pit filled with the same soil
    against the block on the flat half-space, under a vertical and a horizontal force pulse (40 ms): the top
    centre's max |u_filled - u_plain| / peak falls with the mesh, 4.1e-2 -> 1.4e-2 (u_z) and 8.2e-2 -> 4.6e-2
    (u_x) from h = 1 m to 0.5 m (bricks h/2, dt 2.5 ms x h in both)."""
    from helpers import run_script
    m = run_script("runs", "soil_region", "footing.py")
    err = {}
    for h in (1.0, 0.5):
        paths = {case: m.run(case, h, str(tmp_path))[0] for case in ("plain", "filled")}
        err[h] = m.compare(paths["filled"], paths["plain"])[0]
    assert err[1.0]["z"] < 0.05 and err[1.0]["x"] < 0.10, err            # 0.041, 0.082
    assert err[0.5]["z"] < 0.02 and err[0.5]["x"] < 0.055, err           # 0.014, 0.046
    assert err[0.5]["z"] < 0.5 * err[1.0]["z"] and err[0.5]["x"] < 0.7 * err[1.0]["x"], err   # 0.34, 0.55


# slow tier: two coupled runs with contact (20 s); the default tier's siblings: tests/coupling/test_pit_contact.py
# (the same case on one rank, Kuhn-Tucker checked every step)
@pytest.mark.slow
def test_pit_contact_auto_two_ranks_equal_one(tmp_path):
    """Unilateral contact in the pit with -ssi_contact_separation auto and -ssi_contact_preload earth:0.5 (the case of
    test_pit_contact.py, to 70 ms: the first wall opens and its edge lifts): -n 2 takes the same statuses in the same
    iterations as -n 1 (rank 0 decides, stuck nodes included), the interface values equal to round-off (measured
    1.4e-14 in u, 3.2e-11 in p)."""
    a = ["run", "-ssi_problem", "ssi", "-ssi_mesh", "pit", "-ssi_mesh_params", "a=1,b=1,d=1", "-ssi_mesh_size", "6,6",
         "-ssi_mesh_h", "1", "-ssi_dt", "0.0025", "-ssi_t_end", "0.07", "-ssi_seismic", "vertical",
         "-ssi_seismic_record", pulse(tmp_path / "p.txt", 0.04), "-ssi_seismic_units", "m/s2", "-ssi_seismic_scale", "10",
         "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none", "-ssi_fem_mesh", "box",
         "-ssi_fem_box_cells", "4,4,3", "-ssi_fem_box_size", "2,2,1.5", "-ssi_fem_box_origin", "-1,-1,-1",
         "-ssi_fem_interface", "xmin,xmax,ymin,ymax,base", "-ssi_fem_E", "3e10", "-ssi_fem_nu", "0.2",
         "-ssi_fem_rho", "2500", "-ssi_contact", "unilateral", "-ssi_contact_separation", "auto",
         "-ssi_contact_preload", "earth:0.5", "-ssi_warn_beta", "0", "-ssi_output_overwrite", "1"]
    out = {}
    for n in (1, 2):
        cli(a + ["-ssi_output", str(tmp_path / f"n{n}.h5")], nranks=n)
        with h5py.File(tmp_path / f"n{n}.h5") as f:
            out[n] = {k: f["interface"][k][:] for k in ("closed", "iterations", "ub", "uf", "p")}
    assert (~out[1]["closed"].astype(bool)).any()
    for k in ("closed", "iterations"):
        assert np.array_equal(out[1][k], out[2][k]), k
    for k, tol in (("ub", 1e-12), ("uf", 1e-12), ("p", 1e-9)):
        assert np.abs(out[1][k] - out[2][k]).max() <= tol * np.abs(out[1][k]).max(), k


# slow tier: see test_the_soft_layer_quarter_model_equals_the_whole_one (the default tier's sibling for the
# damped layer: test_the_damped_one_d_reference_is_the_damped_layer_on_its_half_space)
@pytest.mark.slow
def test_a_wide_box_of_a_damped_soft_layer_tends_to_the_one_d_layer(tmp_path):
    """W = 20 m (W/H = 10), the layer damped a1 K with ratio 0.2 at f0: the walls' waves die out crossing the
    layer, and the box's centre has the damped 1D layer's peak transfer ratio within 5 % (measured 1.0 %)
    and its whole record within 10 % of the 1D peak velocity (measured 5.8 %; the elastic box: 40 %)."""
    from helpers import run_script
    m = run_script("runs", "soil_region", "soft_layer.py")
    out = str(tmp_path / "W20.h5")
    m.run(20.0, 2, out, zeta=0.2)
    f, tf = m.transfer(out)
    keep = f <= 35.0
    one = m.one_d(f[keep], zeta=0.2)
    assert abs(tf[keep].max() / one.max() - 1) < 0.05, (tf[keep].max(), one.max())
    e_edge, e_all, rms = m.window_errors(out, 20.0, 0.2)
    assert e_all < 0.10, e_all
