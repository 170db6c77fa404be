"""The SSI frequency shift (issue 11): a one-storey building on the soil of the paper's building,
its coupled sway frequency against the replacement-oscillator estimate built from the code's own
static springs.

The case
--------
Soil: c_p = 208, c_s = 100 m/s, rho = 1800 kg/m^3 (G = 18 MPa, nu = 0.3497), grid mesh 4 m x 4 m
with the foundation's edges followed (`-ssi_mesh_patch 1,1`), dt = 5 ms.
Structure (concrete E = 30 GPa, nu = 0.2, rho = 2500 kg/m^3): a 2 m x 2 m foundation slab of
shells (t = 0.5 m, 5000 kg; relative to the soil it is rigid: the plane fit of its settlement
under a couple leaves 0.24% of the peak), four 0.2 m x 0.2 m corner columns (frames, 3 elements
each, 600 kg) and a roof slab at h = 1.5 m (t = 0.3 m plus 4000 kg/m^2 added mass: 19000 kg):
close to a single-degree-of-freedom sway oscillator. Two meshes: "coarse" (soil elements
h = 1 m, nodes every 0.5 m, 4 x 4 shells per slab) and "fine" (h = 0.5 m, 8 x 8 shells).

1. Fixed-base sway frequency f: `petsc-ssi modes -ssi_fem_fixed foundation` (modes 1 and 2, x
   and y sway, equal); between the columns as cantilevers and as fixed-fixed Euler beams (the
   roof slab is not rigid in bending, the frames are Timoshenko).
2. Static springs of the foundation slab alone on the same soil mesh, from quasi-static coupled
   runs (load ramped over 0.1 s, held to 0.3 s; the settled value is the mean of the last 8 steps,
   constant to 1e-6): K_h = F / mean(u_x) for a horizontal force on every slab node
   (`-ssi_fem_point_load foundation,1000,0,0`), K_r = M / theta_y for a couple of vertical forces
   -+1 kN on the nodes of the edges x = +-1 (M = 2 (n+1) kN m), theta_y from the least-squares
   plane through the interface nodes' u_z (u_z = -theta_y x).
3. Replacement oscillator (every mass of the model enters, as Dunkerley's sum of the one-mass
   frequencies, of which the formula is an instance): f_h = sqrt(K_h / m_tot) / 2 pi with m_tot =
   24600 kg (roof, columns and foundation), f_r = sqrt(K_r / I_b) / 2 pi with I_b the mass moment
   of inertia about the y axis through the foundation's centre, sum m_i (x_i^2 + z_i^2) of the
   model's lumped nodal masses plus the shells' and frames' rotary inertia (53078 kg m^2 coarse,
   52328 fine; of it m_roof h^2 = 43 000), and 1/f~^2 = 1/f^2 + 1/f_h^2 + 1/f_r^2.
   (Veletsos-Meek's convention, roof mass only, m h^2, gives f~ = 5.43 Hz coarse, 6% above
   the coupled peak: the 5000 kg foundation slab is not negligible here.)
4. Coupled run: a 10 ms box pulse of 1 kN in x on every roof node, alpha_m = 0 (radiation
   damping only), 2 s (401 samples); the roof centre's u_x amplitude spectrum zero-padded to
   8192 points (pad 16: df = 0.0244 Hz; the record's resolution 1/(N dt) is 0.5 Hz, the response
   decays with zeta ~ 3% to 17% of its peak by the end). The peak does not move from t_end = 1.5 s
   to 4 s nor with dt = 2.5 ms, and zero crossings give the same 5.10 Hz.

Measured (2 cores shared with other jobs)
-----------------------------------------
                     coarse (h = 1 m)        fine (h = 0.5 m)
  f (fixed base)     7.872 Hz                7.634 Hz
  K_h                111.3e6 N/m             106.0e6 N/m    (Pais & Kausel 100.35e6: +11.0%, +5.6%)
  K_r                153.9e6 N m/rad         135.0e6 N m/rad (Pais & Kausel 110.7e6: +39%, +22%)
  f_h, f_r           10.71, 8.570 Hz         10.45, 8.084 Hz
  f~                 5.098 Hz                4.902 Hz
  f_ssi (peak)       5.103 Hz                4.883 Hz
  f_ssi / f~ - 1     +0.1%                   -0.4%
  time (pytest)      modes 1.0 s, K_h 1.2 s,    modes 1.2 s, K_h 1.7 s,
                     K_r 0.3 s, transient 0.8 s  K_r 1.9 s, transient 7.2 s;  the whole file 18 s

Tolerances
----------
- f_ssi < f (the shift's sign) and |f_ssi / f~ - 1| < 5%. The estimate neglects the frequency
  dependence of the impedances and the soil's mass participation, and Dunkerley's sum is a lower
  bound; here a0 = 2 pi f_ssi B / c_s = 0.32 and the errors partly cancel: measured 0.1% and
  0.4% on the two meshes (literature: usually 5-15% for stiff short buildings; 5% keeps ten
  times the measured margin). It still fails if the coupling did not act (f_ssi = f: +54%), if
  either spring were off by a factor of 2 (f~ moves 6-10%), or if the foundation's mass were
  left out of the dynamic model's counterpart (6%).
- The springs against closed forms for a rigid square (half-width B = 1 m) on a half-space,
  Pais & Kausel (1988): K_h = 9.2 G B / (2 - nu), K_r = 4.0 G B^3 / (1 - nu); Gazetas (1991):
  K_h = 9 G B / (2 - nu), K_ry = 3 G / (1 - nu) I_by^0.75 with I_by = (2B)^4 / 12. The error is
  discretisation (the edge tractions of a rigid punch are singular), not truncation (a soil mesh
  of 8 m instead of 4 m changes K_h and K_r by 0.2%): it shrinks about like h (Kh 11.0% -> 5.6%,
  Kr 39% -> 22%), and the order-1 extrapolation 2 K(h/2) - K(h) is within 0.3% (K_h) and 4.9%
  (K_r) of Pais & Kausel. Asserted: f_h within [0, +8%] and f_r within [0, +22%] of the
  closed-form f_h, f_r on the coarse mesh (K: +11%, +39%), both errors at least 1.5 times smaller
  on the fine mesh, and the extrapolated springs within 8% of Pais & Kausel (within the 7% spread
  of the two closed forms for rocking, plus a margin).
"""
import os
import re
import time

import h5py
import numpy as np
import pytest

from helpers import cli, run_ssi

pytestmark = pytest.mark.run

CP, CS, RHO = 208.0, 100.0, 1800.0
G = RHO * CS ** 2
NU_S = ((CP / CS) ** 2 - 2) / (2 * ((CP / CS) ** 2 - 1))
B = 1.0                                   # half-width of the 2 m x 2 m foundation
E, NU, RC = 30e9, 0.2, 2500.0
H = 1.5                                   # roof height (mid-planes)
NZ = 3                                    # frame elements per column
COL = 0.2                                 # column section COL x COL
T_FND, T_ROOF, ADDED = 0.5, 0.3, 4000.0   # slab thicknesses, roof added mass (kg/m^2)
DT = 5e-3
F = 1000.0
MESHES = {"coarse": dict(n=4, h=1.0), "fine": dict(n=8, h=0.5)}

KH_PK = 9.2 * G * B / (2 - NU_S)                            # Pais & Kausel (1988), square
KR_PK = 4.0 * G * B ** 3 / (1 - NU_S)
KH_GAZ = 9.0 * G * B / (2 - NU_S)                           # Gazetas (1991), square (chi = 1)
KR_GAZ = 3.0 * G / (1 - NU_S) * ((2 * B) ** 4 / 12) ** 0.75


def building_msh(path, n, roof=True):
    """Foundation slab (n x n shells on [-B, B]^2, z = 0; its nodes are soil nodes), four corner
    columns of NZ frames and a roof slab of n x n shells at z = H (roof=False: the slab alone)."""
    from slab_building import one_storey_msh
    return one_storey_msh(path, n, B=B, H=H, nz=NZ, roof=roof)


def structure_opts(msh, roof=True):
    """{-ssi_ option without the prefix: value} of the parts."""
    spec = {"foundation": ("shell", {"thickness": T_FND}),
            "roof": ("shell", {"thickness": T_ROOF, "added_mass": ADDED}),
            "columns": ("frame", {"section": f"{COL},{COL}"})}
    parts = ("foundation", "roof", "columns") if roof else ("foundation",)
    o = {"fem_mesh": msh, "fem_parts": ",".join(parts), "fem_interface": "foundation"}
    for p in parts:
        el, extra = spec[p]
        o.update({f"fem_part_{p}_element": el, f"fem_part_{p}_E": E, f"fem_part_{p}_nu": NU,
                  f"fem_part_{p}_rho": RC})
        o.update({f"fem_part_{p}_{k}": v for k, v in extra.items()})
    return o


def soil_opts(h, t_end, output):
    return dict(cp=CP, cs=CS, rho=RHO, mesh_size="4,4", mesh_h=h, mesh_patch=f"{B},{B}", dt=DT, t_end=t_end,
                output=output, output_stride=0, warn_beta=0)


def lumped_masses(n):
    """The model's lumped nodal masses (a quarter of each rectangular shell cell to its nodes, half
    of each frame element to its ends): (coordinates, masses)."""
    x = np.linspace(-B, B, n + 1)
    w = np.full(n + 1, 2 * B / n)
    w[[0, -1]] *= 0.5
    W = np.outer(w, w).ravel()
    X, Y = (a.ravel() for a in np.meshgrid(x, x, indexing="ij"))
    pts, ms = [], []
    for z, mpa in ((0.0, RC * T_FND), (H, RC * T_ROOF + ADDED)):
        pts.append(np.column_stack([X, Y, np.full(X.size, z)]))
        ms.append(W * mpa)
    me = RC * COL ** 2 * H / NZ
    wz = np.full(NZ + 1, me)
    wz[[0, -1]] *= 0.5
    for i in (-B, B):
        for j in (-B, B):
            pts.append(np.column_stack([np.full(NZ + 1, i), np.full(NZ + 1, j), np.linspace(0, H, NZ + 1)]))
            ms.append(wz)
    return np.vstack(pts), np.concatenate(ms)


def oscillator(f, Kh, Kr, m_tot, I_b):
    fh = np.sqrt(Kh / m_tot) / (2 * np.pi)
    fr = np.sqrt(Kr / I_b) / (2 * np.pi)
    return fh, fr, (1 / f ** 2 + 1 / fh ** 2 + 1 / fr ** 2) ** -0.5


def settled(series, k=8):
    """Mean of the last k steps; asserts the run has settled (the k values agree to 1e-4)."""
    tail = np.asarray(series)[-k:]
    assert np.ptp(tail) <= 1e-4 * np.abs(tail).max(), tail
    return float(tail.mean())


def measure(d, n, h):
    """Every number of one mesh: fixed-base modes, springs, coupled peak, oscillator."""
    from petsc_ssi import spectrum
    r = {"times": {}}
    msh = building_msh(str(d / "building.msh"), n)
    fnd = building_msh(str(d / "foundation.msh"), n, roof=False)

    t0 = time.perf_counter()
    out = str(d / "modes.h5")
    args = ["modes", "-ssi_problem", "fem", "-ssi_fem_fixed", "foundation", "-ssi_modes_n", "4",
            "-ssi_output", out]
    for k, v in structure_opts(msh).items():
        args += ["-ssi_" + k, str(v)]
    p = cli(args, timeout=300)
    with h5py.File(out, "r") as fh5:
        r["modes"] = np.asarray(fh5.attrs["frequencies_hz"], float)
    r["f"] = float(r["modes"][0])
    # part masses and rotary inertia (ry) as the model prints them
    r["parts"] = {m.group(1): (float(m.group(2)), float(m.group(3))) for m in re.finditer(
        r"part (\w+): .*? mass ([-+.\deE]+) kg rotary inertia \(rx, ry, rz\) = \([-+.\deE]+, ([-+.\deE]+),",
        p.stdout)}
    r["times"]["modes"] = time.perf_counter() - t0

    # static springs: the foundation slab alone, loads ramped over 0.1 s and held
    ramp = d / "ramp.txt"
    ramp.write_text("0 0\n0.1 1\n100 1\n")
    quasi = dict(soil_opts(h, 0.3, str(d / "spring.h5")), fem_load_history="table", fem_load_table=str(ramp),
                 **structure_opts(fnd, roof=False))
    t0 = time.perf_counter()
    it = run_ssi(fem_point_load=f"foundation,{F},0,0", **quasi)["interface"]
    r["Kh"] = (n + 1) ** 2 * F / settled(it["uf"][:, :, 0].mean(axis=1))
    r["times"]["Kh"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    ys = np.linspace(-B, B, n + 1)
    couple = ";".join(f"{s * B},{y},0,0,0,{-s * F}" for s in (1, -1) for y in ys)   # M_y = 2 (n+1) F B
    it = run_ssi(fem_point_load=couple, **quasi)["interface"]
    x = it["x"]
    A = np.column_stack([np.ones(len(x)), x[:, 0], x[:, 1]])
    coef = np.linalg.lstsq(A, it["uf"][:, :, 2].T, rcond=None)[0]         # per step
    r["theta"] = -coef[1]
    r["Kr"] = 2 * (n + 1) * F * B / settled(r["theta"])
    uz = it["uf"][-1, :, 2]
    r["plane_residual"] = float(np.abs(A @ coef[:, -1] - uz).max() / np.abs(uz).max())
    r["times"]["Kr"] = time.perf_counter() - t0

    # the coupled transient: a 10 ms horizontal pulse on the roof, radiation damping only
    t0 = time.perf_counter()
    res = run_ssi(fem_point_load=f"roof,{F},0,0", fem_load_history="box", fem_load_t0=0.01, fem_alpha_m=0.0,
                  structure_receivers=f"0,0,{H};0,0,0", **soil_opts(h, 2.0, str(d / "ssi.h5")),
                  **structure_opts(msh))
    s = res["structure"]
    r["t"], r["u_roof"] = s["t"], s["u"][:, 0, 0]
    fr, a, info = spectrum.amplitude_spectrum(r["t"], r["u_roof"], pad=16)
    fp, _, _ = spectrum.peaks(fr, a, 1, fmin=0.5, fmax=30.0)
    r["f_ssi"], r["spectrum_info"] = float(fp[0]), info
    r["times"]["transient"] = time.perf_counter() - t0

    P, M = lumped_masses(n)
    r["m_tot"] = float(M.sum())
    r["I_b"] = float((M * (P[:, 0] ** 2 + P[:, 2] ** 2)).sum() + sum(v[1] for v in r["parts"].values()))
    r["fh"], r["fr"], r["f_est"] = oscillator(r["f"], r["Kh"], r["Kr"], r["m_tot"], r["I_b"])
    m_roof = float(M[P[:, 2] > H - 1e-9].sum())
    r["f_est_VM"] = oscillator(r["f"], r["Kh"], r["Kr"], m_roof, m_roof * H ** 2)[2]
    print(f"\n[{n}x{n}] f {r['f']:.4f} Hz, K_h {r['Kh']:.4e} N/m ({r['Kh'] / KH_PK - 1:+.1%} PK), "
          f"K_r {r['Kr']:.4e} N m/rad ({r['Kr'] / KR_PK - 1:+.1%} PK), f_h {r['fh']:.4f}, f_r {r['fr']:.4f}, "
          f"f~ {r['f_est']:.4f} (roof mass only {r['f_est_VM']:.4f}), f_ssi {r['f_ssi']:.4f} Hz "
          f"({r['f_ssi'] / r['f_est'] - 1:+.2%}); m_tot {r['m_tot']:.0f} kg, I_b {r['I_b']:.0f} kg m^2; "
          f"{info['summary']}; times " + ", ".join(f"{k} {v:.1f} s" for k, v in r["times"].items()))
    return r


@pytest.fixture(scope="module")
def cases(tmp_path_factory):
    out = {}
    for name, m in MESHES.items():
        out[name] = measure(tmp_path_factory.mktemp(name), **m)
    return out


def test_fixed_base_structure_is_a_sway_oscillator(cases):
    """The fixed-base model is the structure described: its masses are the lumped masses the
    oscillator uses; the first two modes are the x and y sway (equal by symmetry), between the
    columns as cantilevers and as fixed-fixed Euler-Bernoulli beams under the roof's mass."""
    for name, r in cases.items():
        P, M = lumped_masses(MESHES[name]["n"])
        assert sum(v[0] for v in r["parts"].values()) == pytest.approx(M.sum(), rel=1e-9), r["parts"]
        assert set(r["parts"]) == {"foundation", "roof", "columns"}
        assert r["modes"][1] == pytest.approx(r["modes"][0], rel=1e-6)
        k_ff = 4 * 12 * E * COL ** 4 / 12 / H ** 3
        m_top = float(M[P[:, 2] > H - 1e-9].sum())
        f_ff = np.sqrt(k_ff / m_top) / (2 * np.pi)
        assert f_ff / 2 < r["f"] < f_ff, (name, r["f"], f_ff)


def test_static_springs_against_closed_forms(cases):
    """K_h and K_r of the code (quasi-static coupled runs) against Pais & Kausel's rigid square:
    stiff by the discretisation of the singular edge tractions, within the stated bands on the
    coarse mesh, at least 1.5 times closer on the fine one, and the order-1 extrapolation within
    8% of Pais & Kausel; Gazetas's forms are reported for comparison. The slab moves rigidly."""
    c, f = cases["coarse"], cases["fine"]
    for r in (c, f):
        assert r["plane_residual"] < 0.01, r["plane_residual"]
    m, I = c["m_tot"], c["I_b"]
    fh_pk, fr_pk = np.sqrt(KH_PK / m) / (2 * np.pi), np.sqrt(KR_PK / I) / (2 * np.pi)
    assert 0 < c["fh"] / fh_pk - 1 < 0.08, (c["fh"], fh_pk)
    assert 0 < c["fr"] / fr_pk - 1 < 0.22, (c["fr"], fr_pk)
    for key, ref in (("Kh", KH_PK), ("Kr", KR_PK)):
        ec, ef = c[key] / ref - 1, f[key] / ref - 1
        assert 0 < ef < ec / 1.5, (key, ec, ef)
        extrap = 2 * f[key] - c[key]
        assert abs(extrap / ref - 1) < 0.08, (key, extrap / ref - 1)
    print(f"\nGazetas: K_h coarse {c['Kh'] / KH_GAZ - 1:+.1%}, fine {f['Kh'] / KH_GAZ - 1:+.1%}; "
          f"K_r coarse {c['Kr'] / KR_GAZ - 1:+.1%}, fine {f['Kr'] / KR_GAZ - 1:+.1%}")


@pytest.mark.parametrize("name", list(MESHES))
def test_ssi_frequency_shift(cases, name):
    """The coupled sway peak lies below the fixed-base frequency and within 5% of the
    replacement-oscillator estimate built from the code's own springs on the same soil mesh
    (measured +0.1% coarse, -0.4% fine); the spectrum's grid is fine enough to show it."""
    r = cases[name]
    assert r["spectrum_info"]["df"] < 0.005 * r["f_est"]
    assert r["f_ssi"] < 0.8 * r["f"], (r["f_ssi"], r["f"])                      # a real shift
    assert abs(r["f_ssi"] / r["f_est"] - 1) < 0.05, (r["f_ssi"], r["f_est"])
    assert r["f_ssi"] < r["f_est_VM"]                                              # roof mass only: higher
