"""The rigid disk's static horizontal-rocking coupling (issue 46, the rocking terms) against the welded
disk's: K_hr = M_y per u_x and K_rh = F_x per theta_y about the disk's centre on the surface, in
units of R K_h, from the BEM runs of `petsc-ssi impedance` (disk.opts' soil and mesh, nu = 1/3) beside the independent welded
disk of petsc_ssi/analytic/disk_static.py (-0.081; -0.0812 extrapolated,
runs/impedance/coupling_published.py). The published "about -0.03" that issue 46 quoted is not this
model's value: the welded disk gives -0.03 only near nu = 0.45 and a relaxed contact gives 0
(runs/impedance/README.md, the coupling section). The BEM's K_hr / K_rh - 1 comes from the meshed
surface's truncation (0.35, 0.18, 0.10 on 4, 6, 10 m surfaces at 0.5 m elements; the same to three
digits for 0.35 and 0.25 m elements on 6 m), so the tests take the 6 m surface and hold each term to
20 % of the welded value and their mean to 6 %."""
import pytest

pytestmark = pytest.mark.run

NU = 1.0 / 3.0


def bem_coupling(tmp_path, h, L=6.0, t_end=0.1, beta=0.5):
    """(K_hr, K_rh) / (R K_h) of the BEM's disk (R = 1 m; runs/impedance/disk.opts' soil and mesh) at
    element size h on an L x L surface, dt = beta h / c_s: the horizontal and the rocking unit steps of `petsc-ssi
    impedance` (its quarter model, x_ref the centre), run in this process; the static values are the
    resultants of the last step."""
    from test_haskind import run
    common = dict(cp=632, cs=316, rho=2000, mesh="meshes/disk_soil.geo", mesh_size=f"{L:g},{L:g}", mesh_h=h,
                  mesh_patch="1,1", disp_group="load", dt=beta * h / 316, t_end=t_end, symmetry="x=anti,y=sym",
                  output_stride=0, warn_beta=0, output=str(tmp_path / "d.h5"))
    _, _, rh_ = run(dict(common, disp_value="1,0,0"))
    _, _, rr_ = run(dict(common, disp_rotation="0,1,0"))
    kh = rh_["resultants"]["force"][-1, 0]
    return rh_["resultants"]["moment"][-1, 1] / kh, rr_["resultants"]["force"][-1, 0] / kh


def welded(nu=NU, rings=8):
    from petsc_ssi.analytic.disk_static import stiffness
    K = stiffness(rings, 4 * rings, 1.0, nu)
    return 0.5 * (K[2, 0] + K[0, 2]) / K[0, 0]


def test_disk_coupling_coarse(tmp_path):
    """0.5 m elements (16 cells around the rim) with dt = h / c_s and a 0.04 s record (the static
    values equal the command's, dt = h / (2 c_s) over 0.1 s, to 1e-4): K_hr -0.0912, K_rh -0.0775,
    mean -0.0844 against the welded -0.081 (measured +12, -4.5, +4 %); both terms negative, as the
    welded disk's."""
    hr, rh = bem_coupling(tmp_path, 0.5, t_end=0.04, beta=1.0)
    w = welded()
    assert hr < 0 and rh < 0 and w < 0
    assert abs(hr / w - 1) < 0.2 and abs(rh / w - 1) < 0.2, (hr, rh, w)
    assert abs(0.5 * (hr + rh) / w - 1) < 0.06, (hr, rh, w)


# slow tier: the finest mesh of runs/impedance/coupling_published.py (0.25 m, 32 cells around the
# rim; 2 min, 1.9 GB); test_disk_coupling_coarse is its default-tier sibling
@pytest.mark.slow
def test_disk_coupling_finest_mesh(tmp_path):
    """0.25 m elements on the 6 m surface: K_hr -0.0877, K_rh -0.0804, mean -0.0841 against the welded
    -0.081 (+8, -1, +4 %)."""
    hr, rh = bem_coupling(tmp_path, 0.25)
    w = welded(rings=12)
    assert abs(hr / w - 1) < 0.2 and abs(rh / w - 1) < 0.2, (hr, rh, w)
    assert abs(0.5 * (hr + rh) / w - 1) < 0.06, (hr, rh, w)


def test_the_quoted_value_is_not_the_welded_disks_at_this_poisson_ratio():
    """The independent welded disk's coupling in units of R K_h falls with nu roughly as (1 - 2 nu):
    -0.174, -0.081, -0.029, -0.006 at nu = 0, 1/3, 0.45, 0.49 (8 rings). At the code's nu = 1/3 it is
    2.7 times the quoted -0.03, which it reaches only near nu = 0.45."""
    quoted = -0.03
    w13, w45 = welded(NU), welded(0.45)
    assert w13 / quoted > 2.5
    assert abs(w45 / quoted - 1) < 0.2
