"""The interface columns Z = A^-1 H_s E_I on a region around the interface (coupling/columns.py,
-ssi_interface_columns): the coupled run with unilateral contact (it lifts off) on a 28 m grid whose region
holds about half the soil's DOFs equals the run with the step matrix's factors (every row) to 1e-12 of each
field's scale until contact's first change of status, and to 1e-9 after it: the lift-off amplifies
round-off about 1e4 within a few steps, so any change of summation order moves the run by that much (the
full path against itself with the history's step products summed in another order: 7e-11; region against
full 4e-11-1.1e-10); at -n 2 against -n 1 MUMPS's parallel sums add 1e-10-1e-9, as on the full path, so the
two-rank check is the bonded quarter model's, region and full both at -n 2. A bonded run equals the full
solve to 1e-12; a first margin too small for round-off is doubled (the log says so); auto keeps the full
solve where the region would hold most of the grid."""
import os
import re
import sys

import h5py
import numpy as np
import pytest

from helpers import cli

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bem"))
from test_history_block import SSI, fields, same, scales  # noqa: E402

pytestmark = pytest.mark.mpi

# a 2 m x 2 m footing (4 soil elements) on a 28 m x 28 m grid of 1 m elements (9747 DOFs), toeplitz store
BIG = ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "28,28",
       "-ssi_mesh_h", "1", "-ssi_mesh_patch", "2,2", "-ssi_fem_box_cells", "4,4,1", "-ssi_fem_box_size", "2,2,0.25",
       "-ssi_fem_box_origin", "-1,-1,0", "-ssi_fem_E", "3e8", "-ssi_fem_rho", "2000", "-ssi_dt", "0.0125",
       "-ssi_t_end", "0.5", "-ssi_fem_load_group", "top", "-ssi_fem_load_p0", "1000", "-ssi_fem_load_history",
       "box", "-ssi_fem_load_t0", "0.05", "-ssi_contact", "unilateral", "-ssi_receivers", "1,0,0;6,0,0",
       "-ssi_output_stride", "5", "-ssi_warn_beta", "0", "-ssi_lag_store", "toeplitz"]


def region_line(out):
    m = re.search(r"interface columns: on the (\d+) soil DOFs within ([\d.]+) m of the interface \((\d+) % of "
                  r"(\d+); margin ([\d.]+) x the step matrix's reach ([\d.]+) m[^)]*\).*truncation residual "
                  r"([\d.e+-]+)",
                  out)
    assert m, out[-3000:]
    return m


def test_region_columns_equal_the_full_solve(tmp_path):
    full, reg = (str(tmp_path / f"{k}.h5") for k in ("full", "reg"))
    out_f = cli(BIG + ["-ssi_output", full, "-ssi_interface_columns", "full"]).stdout
    assert "interface columns: on the" not in out_f
    out = cli(BIG + ["-ssi_output", reg]).stdout                 # auto: the region
    m = region_line(out)
    n_reg, n_all, mult = int(m.group(1)), int(m.group(4)), float(m.group(5))
    assert n_all == 9747 and 0.3 * n_all < n_reg < 0.6 * n_all and mult == 4.0
    assert float(m.group(7)) <= 1e-14
    same(full, reg, rtol=1e-9)
    with h5py.File(reg) as f:
        closed = f["interface/closed"][...]
    assert closed.any() and not closed.all()        # contact is active: it lifts off
    first = int(np.flatnonzero((closed[1:] != closed[:-1]).any(axis=1))[0]) + 1
    assert first >= 3                                # (records before it to compare)
    A, B = fields(full), fields(reg)
    S = scales(A)
    for k in ("interface/p", "interface/ub", "interface/uf"):
        assert np.abs(A[k][:first] - B[k][:first]).max() <= 1e-12 * S[k], k


def test_a_margin_too_small_is_doubled(tmp_path):
    """A first margin of one reach leaves a residual above round-off: the margin is doubled until it is
    not (the log line's margin and its first try's residual), and the bonded run equals the full solve to
    1e-12; the region's KSP takes options under its own prefix (-ssi_bem_columns_)."""
    full, reg = str(tmp_path / "full.h5"), str(tmp_path / "reg.h5")
    bonded = BIG + ["-ssi_contact", "bonded", "-ssi_t_end", "0.2"]
    cli(bonded + ["-ssi_output", full, "-ssi_interface_columns", "full"])
    out = cli(bonded + ["-ssi_output", reg, "-ssi_interface_columns", "region",
                        "-ssi_interface_columns_margin", "1",
                        "-ssi_bem_columns_pc_factor_mat_solver_type", "mumps"]).stdout     # (its KSP's own prefix)
    m = region_line(out)
    assert float(m.group(5)) >= 2.0 and float(m.group(7)) <= 1e-14
    first = re.search(r"tried first: ([\d.]+) m: residual ([\d.e+-]+)", out)
    assert first and float(first.group(2)) > 1e-14, out[-2000:]
    same(full, reg)                                  # (bonded: no free flight)


def test_mirror_image_columns_equal_the_solved_ones(tmp_path):
    """The footing centred on the grid: the region's interface columns fall into orbits of the mirror group
    (x = 0, y = 0), so only an orbit's representative node's columns are solved (3 x 3 of the 5 x 5 interface
    nodes: 27 of 75) and the others are their signed mirror images (coupling/columns.py). At -n 2 (the images
    cross the ranks) the bonded run equals the one whose columns are all solved (-ssi_step_mirror off: no blocks,
    no orbits) to 1e-12 of each field's scale."""
    bonded = BIG + ["-ssi_contact", "bonded", "-ssi_t_end", "0.2"]
    ref, got = str(tmp_path / "ref.h5"), str(tmp_path / "got.h5")
    out0 = cli(bonded + ["-ssi_output", ref, "-ssi_step_mirror", "off"]).stdout
    assert "mirror images" not in region_line(out0).group(0)
    out = cli(bonded + ["-ssi_output", got], nranks=2).stdout
    line = [x for x in out.splitlines() if "interface columns: on the" in x][0]
    assert "27 of 75 columns solved, the others their mirror images" in line, line
    same(ref, got)


def _bonded_reference(tmp_path, capfd):
    """The in-process fallback tests' case (BIG bonded, 0.1 s): (options, the reference run's file, its log)."""
    from helpers import run_ssi
    opts = dict(zip((a[len("-ssi_"):] for a in BIG[0::2]), BIG[1::2]))
    opts.update(contact="bonded", t_end="0.1")
    ref = str(tmp_path / "ref.h5")
    run_ssi(**opts, output=ref)
    return opts, ref, capfd.readouterr().out


def test_an_image_right_hand_side_off_its_mirror_solves_every_column(tmp_path, monkeypatch, capfd):
    """Where an image column's right-hand side is not its representative's mirrored to MIRROR_TOL (forced here:
    a negative bound), every column is solved, said in one line, and the run is the same. Likewise on the
    structure's side: where a mirrored structure column is not the solved one to FEM_IMAGE_TOL (forced), or the
    structure's matrix does not commute with the reflections (forced), every structure column is solved."""
    from helpers import run_ssi
    from petsc_ssi.coupling import columns, step
    opts, ref, out = _bonded_reference(tmp_path, capfd)
    assert "27 of 75 columns solved" in out and "27 BEM and 27 FEM solves" in out
    got = str(tmp_path / "got.h5")
    monkeypatch.setattr(columns, "MIRROR_TOL", -1.0)
    run_ssi(**opts, output=got)
    out = capfd.readouterr().out
    assert "differs from its mirrored representative's by" in out and "every column solved" in out, out[-2000:]
    assert "columns solved, the others" not in out
    same(ref, got)
    monkeypatch.undo()
    monkeypatch.setattr(step, "FEM_IMAGE_TOL", -1.0)
    run_ssi(**opts, output=got)
    out = capfd.readouterr().out
    assert "the structure's all solved (a mirrored column differs from the solved one by" in out, out[-2000:]
    assert "27 BEM and 75 FEM solves (of 75 columns, the others mirror images)" in out, out[-2000:]
    same(ref, got)
    # a structure whose matrix does not commute with the reflections (forced: the check's defect made 1)
    monkeypatch.undo()
    monkeypatch.setattr(columns, "commutation_defect", lambda A, R: 1.0)
    run_ssi(**opts, output=got)
    out = capfd.readouterr().out
    assert "the structure's all solved (its matrix D commutes with the reflections only to 1 > 1e-10)" in out, out
    same(ref, got)


def test_auto_keeps_the_full_solve_on_a_small_grid(tmp_path):
    """The 2 m x 2 m grid under a 1 m footing: the region would hold nearly every DOF, so auto solves
    with the step matrix's factors and says why."""
    out = cli(SSI + ["-ssi_t_end", "0.05", "-ssi_output", str(tmp_path / "a.h5")]).stdout
    line = [s for s in out.splitlines() if "interface columns:" in s]
    assert line and "with the step matrix's factors" in line[0] and "% of the soil's DOFs" in line[0]
    share = float(re.search(r"holds (\d+) %", line[0]).group(1))
    assert share > 60 and np.isfinite(share)


# the quarter of BIG's footing and grid with the symmetry planes x = 0 and y = 0 (their zero DOFs)
QUARTER = [a for a in BIG] + ["-ssi_symmetry", "x=sym,y=sym"]
for k, v in (("-ssi_fem_box_cells", "2,2,1"), ("-ssi_fem_box_size", "1,1,0.25"), ("-ssi_fem_box_origin", "0,0,0"),
             ("-ssi_contact", "bonded"), ("-ssi_t_end", "0.1")):
    QUARTER[QUARTER.index(k) + 1] = v


def test_a_quarter_model_on_two_ranks(tmp_path):
    """Symmetry planes (their zero DOFs in the region's matrix) on 2 ranks, the region near the corner of the
    quarter grid (a rank may hold few of its rows or of its ring's), a first margin of one reach doubled twice:
    equal to the full solve to 1e-12."""
    full, reg = str(tmp_path / "full.h5"), str(tmp_path / "reg.h5")
    cli(QUARTER + ["-ssi_output", full, "-ssi_interface_columns", "full"], nranks=2)
    out = cli(QUARTER + ["-ssi_output", reg, "-ssi_interface_columns", "region", "-ssi_interface_columns_margin",
                         "1"], nranks=2).stdout
    m = region_line(out)
    assert int(m.group(4)) == 2523 and int(m.group(1)) < 2523 and float(m.group(5)) == 4.0
    same(full, reg)


def test_auto_falls_back_to_the_full_solve_after_a_doubled_margin(tmp_path):
    """auto with a first margin of 2 reaches: its residual is above round-off, the doubled margin's region
    holds more than 60 % of the DOFs, so the columns go with the step matrix's factors (the log names the
    first try's residual), and the run equals the full solve's bit for bit up to round-off (1e-12)."""
    bonded = BIG + ["-ssi_contact", "bonded", "-ssi_t_end", "0.1"]
    bonded[bonded.index("-ssi_mesh_size") + 1] = "24,24"     # (a 24 m grid: 64 % of it within the doubled margin)
    full, auto = str(tmp_path / "full.h5"), str(tmp_path / "auto.h5")
    cli(bonded + ["-ssi_output", full, "-ssi_interface_columns", "full"])
    out = cli(bonded + ["-ssi_output", auto, "-ssi_interface_columns_margin", "2"]).stdout
    line = [x for x in out.splitlines() if "interface columns:" in x]
    assert line and "with the step matrix's factors" in line[0], out[-2000:]
    first = re.search(r"([\d.]+) m: residual ([\d.e+-]+)", line[0])
    assert first and float(first.group(2)) > 1e-14 and int(re.search(r"holds (\d+) %", line[0]).group(1)) > 60
    same(full, auto)


def test_a_failed_region_lu_falls_back_to_the_full_solve(tmp_path):
    """MUMPS does not raise a failed factorisation at set-up (its solves then stop with INFOG(1) = -3: seen at
    3.5 reaches on the uniform 72 m building, INFOG(1) = -9, before the region's workspace relaxation): the
    region's LU is checked, and a failure (here forced: 1 MB of working memory, INFOG(1) = -19) is said in
    one line and the columns go with the step matrix's factors, equal to the full solve's."""
    bonded = BIG + ["-ssi_contact", "bonded", "-ssi_t_end", "0.1"]
    full, reg = str(tmp_path / "full.h5"), str(tmp_path / "reg.h5")
    cli(bonded + ["-ssi_output", full, "-ssi_interface_columns", "full"])
    out = cli(bonded + ["-ssi_output", reg, "-ssi_bem_columns_mat_mumps_icntl_23", "1"]).stdout
    line = [x for x in out.splitlines() if "interface columns:" in x]
    assert line and "MUMPS's LU failed, INFOG(1) = -" in line[0] and "with the step matrix's factors" in line[0]
    same(full, reg)


def test_mirror_images_in_the_staggered_step_with_lift_off(tmp_path):
    """The staggered step (-ssi_coupling staggered) corrects the soil by the open nodes' columns alone,
    x -= Z[:, O] delta_O, which the mirror images form from the representatives' columns (columns.MirroredZ, a
    subset O of the columns): with unilateral contact (it lifts off) the run equals the one whose columns are all
    solved and kept (-ssi_step_mirror off) to 1e-9 of each field's scale (the correction acts from the first open
    node on, where the lift-off amplifies round-off: the module docstring), and to 1e-12 before it (the step
    solves and the interface algebra)."""
    stag = BIG + ["-ssi_coupling", "staggered", "-ssi_t_end", "0.3"]
    ref, got = str(tmp_path / "ref.h5"), str(tmp_path / "got.h5")
    cli(stag + ["-ssi_output", ref, "-ssi_step_mirror", "off"])
    out = cli(stag + ["-ssi_output", got]).stdout
    assert "27 of 75 columns solved, the others their mirror images" in out, out[-2000:]
    same(ref, got, rtol=1e-9)
    with h5py.File(got) as f:
        closed = f["interface/closed"][...]
    assert closed.any() and not closed.all()        # some nodes open: the correction by a subset of the columns
    first = int(np.flatnonzero((closed[1:] != closed[:-1]).any(axis=1))[0]) + 1
    A, B = fields(ref), fields(got)
    S = scales(A)
    for k in ("interface/p", "interface/ub", "interface/uf"):
        assert np.abs(A[k][:first] - B[k][:first]).max() <= 1e-12 * S[k], k


# (the released variant in the slow tier: 21 s in the CI of 78ea95b, the make-test budget; its sibling stays)
@pytest.mark.parametrize("release", [False, pytest.param(True, marks=pytest.mark.slow)])
def test_a_building_of_frames_and_shells_mirrors_its_columns(tmp_path, release):
    """The CI building of frames and shells (tests/coupling/test_building_ci.py: a shell foundation slab, four
    columns, a roof slab; rotations at every node) centred on a 28 m grid under an off-centre soil load: the
    structure's columns D^-1 T^T e_j are mirror images too (their rotations mirrored as a pseudovector:
    columns.structure_reflections), 27 of 75 solved on each side; at -n 2 the run equals the one with every
    column solved (-ssi_step_mirror off) to 1e-12 of each field's scale. With the roof hinged to the columns
    (-ssi_fem_part_roof_release rotations) its corner nodes carry a second rotation triple, mirrored as the first."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from test_building_ci import building_msh, structure_opts, soil_opts
    msh = building_msh(str(tmp_path / "b.msh"))
    case = (["-ssi_problem", "ssi"] + soil_opts(size="28,28", t_end=0.05) + structure_opts(msh)
            + (["-ssi_fem_part_roof_release", "rotations"] if release else [])
            + ["-ssi_lag_store", "toeplitz", "-ssi_contact", "bonded", "-ssi_receivers", "0,0,0;3,0,0",
               "-ssi_output_stride", "5"])
    ref, got = str(tmp_path / "ref.h5"), str(tmp_path / "got.h5")
    out0 = cli(case + ["-ssi_output", ref, "-ssi_step_mirror", "off"]).stdout
    assert "mirror images" not in out0
    out = cli(case + ["-ssi_output", got], nranks=2).stdout
    line = [x for x in out.splitlines() if "interface matrices" in x][0]
    assert "27 BEM and 27 FEM solves (of 75 columns, the others mirror images)" in line, out[-3000:]
    same(ref, got)
