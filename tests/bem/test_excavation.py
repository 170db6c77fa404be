"""The BEM on a soil surface with an excavation (issue 42, item 1): the ground z = 0 with a rectangular pit
(``-ssi_mesh pit``: walls and bottom), the general 3x3 blocks (bem/bsr.py FULL: the pairs are not all in
one plane), the free term from the solid angle at the rim, the bottom's edges and the corners, receivers on
the ground, the walls and the bottom.

What shows it right, each a check that fails on a wrong normal, free term or integration path:
  * a pit of depth d -> 0 is the flat surface: a uniform pressure on the pit's bottom against the same
    pressure on the flat surface's patch, at receivers on the bottom's centre and on the ground; the
    difference falls linearly with d (measured 1.8 %, 6.7 %, 3.6 % of each receiver's peak at d = h/8 and
    0.77 %, 3.5 %, 1.9 % at h/16, on 1 m elements, 0.04 s);
  * reciprocity (Betti; independent of the flat case): a pressure on the bottom and one on a ground
    patch beside the pit, each the same history: int_A f . u_B = int_B f . u_A at every step. The
    collocation BEM is not symmetric, so this holds to the discretisation: measured 3.6 % of the peak
    at h = 1 m and 2.6 % at h = 0.5 m (the flat surface's same check, a patch for the bottom: 2.5 % at
    h = 1 m);
  * -n 2 equals -n 1, and bad geometry is refused in one line before any assembly at -n 2."""
import h5py
import numpy as np
import pytest

from helpers import cli, run_bem
from test_history_block import same
from test_integrity import refused

pytestmark = pytest.mark.mpi

COMMON = dict(problem="bem", load_p0=1000, warn_beta=0, output_overwrite=1)


def receivers(path):
    with h5py.File(path) as f:
        return f["receivers/u"][:]                     # (steps, receivers, 3) [m]


def snapshots(path):
    """The displacement snapshots (steps, nodes, 3) [m] in step order."""
    with h5py.File(path) as f:
        ks = sorted((k for k in f if k.startswith("displacement_")), key=lambda k: int(k.split("_")[-1]))
        return np.array([f[k][:].reshape(-1, 3) for k in ks])


def depth_errors(tmp_path, depths, L=6, t_end=0.04):
    """Per depth, each receiver's largest difference from the flat surface's over its peak: the bottom's
    centre (0, 0, -d) against (0, 0, 0), and ground points (2, 0, 0), (2, 2, 0)."""
    common = dict(COMMON, mesh_size=f"{L},{L}", mesh_h=1, dt=0.0025, t_end=t_end, output_stride=0)
    flat = str(tmp_path / "flat.h5")
    run_bem(mesh_patch="1,1", load_group="load", receivers="0,0,0;2,0,0;2,2,0", output=flat, **common)
    uf = receivers(flat)
    out = []
    for d in depths:
        path = str(tmp_path / f"pit{d}.h5")
        run_bem(mesh="pit", mesh_params=f"a=1,b=1,d={d}", load_group="bottom", receivers=f"0,0,{-d};2,0,0;2,2,0",
                output=path, **common)
        u = receivers(path)
        out.append([np.abs(u[:, k] - uf[:, k]).max() / np.abs(uf[:, k]).max() for k in range(3)])
    return np.array(out)


def test_a_shallow_pit_tends_to_the_flat_surface(tmp_path):
    """d = 0.25 and 0.125 m on 1 m elements: each receiver's difference from the flat surface at least
    halves... within [0.35, 0.65] of the deeper one's (linear in d), and under 8 % at d = h/8."""
    e = depth_errors(tmp_path, [0.25, 0.125], t_end=0.03)
    assert np.all(e[0] > 0)
    ratio = e[1] / e[0]
    assert np.all((0.35 < ratio) & (ratio < 0.65)), ratio
    assert e[1].max() < 0.08, e


# slow tier: the depth sequence to h/16 (4 pit runs, 20 s; two depths stay in the default tier)
@pytest.mark.slow
def test_the_pit_converges_linearly_in_depth_to_the_flat_surface(tmp_path):
    e = depth_errors(tmp_path, [0.5, 0.25, 0.125, 0.0625])
    print("differences from the flat surface (rows d = 0.5, 0.25, 0.125, 0.0625 m):", e)
    ratio = e[1:] / e[:-1]
    assert np.all((0.4 < ratio) & (ratio < 0.7)), ratio
    assert np.all(ratio[-1] < 0.6), ratio
    assert e[-1].max() < 0.04, e


def reciprocity(tmp_path, h, L=6, d=1.0):
    """max_n |int_A f . u_B - int_B f . u_A| / max_n |int_A f . u_B| for a pressure on the pit's bottom (A)
    and on a ground patch beside it (B: x in [1, 3], y in [-1, 1]), each the same smooth history."""
    from petsc_ssi.mesh.surface import pit
    from petsc_ssi.bem.resultants import area_moments
    m = pit(L, L, h, 1.0, 1.0, d)
    box = "box:1.2,2.8,-0.8,0.8"
    common = dict(COMMON, mesh="pit", mesh_params=f"a=1,b=1,d={d}", mesh_size=f"{L},{L}", mesh_h=h,
                  dt=0.0025 * h, t_end=0.03, output_stride=1)
    run_bem(load_group="bottom", output=str(tmp_path / "A.h5"), **common)
    run_bem(load_group=box, output=str(tmp_path / "B.h5"), **common)
    uA, uB = snapshots(str(tmp_path / "A.h5")), snapshots(str(tmp_path / "B.h5"))

    def weights(elems):                      # int_region N_a dGamma at each node [m^2]
        nodes = np.unique(m.cells[elems])
        w = np.zeros(m.n_nodes)
        w[nodes] = area_moments(m, elems, nodes)[0]
        return w
    wA, wB = weights(m.groups["bottom"]), weights(m.select(box))
    assert abs(wB.sum() - 4.0) < 1e-12 and abs(wA.sum() - 4.0) < 1e-12
    sA, sB = uB[:, :, 2] @ wA, uA[:, :, 2] @ wB          # (f = (0, 0, -p0) on both: the factor cancels)
    assert np.abs(sA).max() > 0
    return np.abs(sA - sB).max() / np.abs(sA).max()


def test_reciprocity_between_the_pits_bottom_and_the_ground(tmp_path):
    r = reciprocity(tmp_path, 1.0)
    assert r < 0.05, r


# slow tier: reciprocity at h = 0.5 m (20 s; h = 1 m stays)
@pytest.mark.slow
def test_reciprocity_improves_with_the_mesh(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    r1, r2 = reciprocity(tmp_path / "a", 1.0), reciprocity(tmp_path / "b", 0.5)
    assert r2 < 0.8 * r1 and r2 < 0.03, (r1, r2)


PIT = ["-ssi_problem", "bem", "-ssi_mesh", "pit", "-ssi_mesh_params", "a=1,b=1,d=1", "-ssi_mesh_size", "6,6",
       "-ssi_mesh_h", "1", "-ssi_load_group", "bottom", "-ssi_load_p0", "1000", "-ssi_dt", "0.0025",
       "-ssi_t_end", "0.015", "-ssi_receivers", "0,0,-1;1,0,-0.5;2,0,0", "-ssi_output_stride", "2",
       "-ssi_warn_beta", "0"]


# slow tier: a pit run at -n 1 and -n 2 (25 s; the -n 2 refusal below stays)
@pytest.mark.slow
def test_two_ranks_equal_one(tmp_path):
    """-n 2 gives -n 1's displacements, tractions and receivers to 1e-12 of their scale."""
    a, b = str(tmp_path / "a.h5"), str(tmp_path / "b.h5")
    cli(PIT + ["-ssi_output", a])
    cli(PIT + ["-ssi_output", b], nranks=2)
    same(a, b, 1e-12)
    assert np.abs(receivers(a)).max() > 0


def test_bad_geometry_is_refused_on_every_rank(tmp_path):
    """The .geo's pit turned upside down (d < 0: walls and bottom above the ground) is refused in one line
    at -n 2 before any assembly."""
    r = cli(["-ssi_problem", "bem", "-ssi_mesh", "meshes/pit.geo", "-ssi_mesh_params", "a=1,b=1,d=-1",
             "-ssi_mesh_size", "6,6", "-ssi_mesh_h", "1", "-ssi_load_group", "pit", "-ssi_load_p0", "1000",
             "-ssi_t_end", "0.01", "-ssi_output", str(tmp_path / "c.h5")], nranks=2, check=False)
    line = refused(r)
    assert "lies above the ground z = 0" in line and "assembly" not in r.stdout, r.stdout
