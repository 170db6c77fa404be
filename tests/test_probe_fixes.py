"""What an independent probe of the large-site and excavation features found said wrongly or not at all
(commit 56ec32d): each case is refused in one line naming its cause, or warned, or logged.

  * a negative -ssi_mesh_size was reported as a too-large -ssi_mesh_h (telling the user to give a
    negative element size);
  * a mesh parameter whose value is not a number was 'not name=value'; one given twice took the last;
  * -ssi_load_p0 on a group with a pit's walls put a vertical shear on them silently;
  * the generators' element sides, rounded to whole counts per stretch, were not logged;
  * the toeplitz store's refusal on an excavation blamed -ssi_lag_pattern.
"""
import pytest

from helpers import cli
from test_integrity import refused

pytestmark = pytest.mark.run

BEM = ["-ssi_problem", "bem", "-ssi_cp", "548", "-ssi_cs", "316", "-ssi_rho", "2000", "-ssi_warn_beta", "0",
       "-ssi_dt", "1.5e-3", "-ssi_t_end", "0.003"]
PIT = ["-ssi_mesh", "pit", "-ssi_mesh_size", "6,6", "-ssi_mesh_h", "1"]


@pytest.mark.parametrize("args,msg", [
    (["-ssi_mesh", "grid", "-ssi_mesh_size", "6,-6", "-ssi_mesh_h", "1"],
     "-ssi_mesh_size 6,-6: the mesh's extent must be positive"),
    (PIT + ["-ssi_mesh_params", "a=1,b=1x,d=1"], "-ssi_mesh_params: 'b=1x': the value '1x' is not a number"),
    (PIT + ["-ssi_mesh_params", "a=1,b=1,d=1,d=2"], "-ssi_mesh_params: 'd' given twice (1 and 2)"),
    (PIT + ["-ssi_mesh_params", "a=1,b=1,d=1", "-ssi_lag_store", "toeplitz"],
     "-ssi_lag_store toeplitz: the surface is not the plane z = 0 (element "),
])
def test_bad_input_is_refused_naming_its_cause(tmp_path, args, msg):
    err = refused(cli(BEM + args + ["-ssi_output", str(tmp_path / "x.h5")], check=False))
    assert msg in err, err


def test_a_load_on_a_pits_walls_is_warned_and_rounded_element_sides_are_logged(tmp_path):
    """The pit group holds the walls and the bottom: 8 of its 12 elements are walls (1 m pit of 1 m
    elements); on 7 x 5 m with h = 1 the grid's stretches take 0.875 and 1.25 m elements."""
    r = cli(BEM + PIT + ["-ssi_mesh_params", "a=1,b=1,d=1", "-ssi_load_group", "pit", "-ssi_load_p0", "1000",
                         "-ssi_output", str(tmp_path / "p.h5")])
    assert ("-ssi_load_group pit: 8 of its 12 elements are not horizontal" in r.stdout
            and "a shear on a wall, not a pressure" in r.stdout), r.stdout[-3000:]
    r = cli(BEM + ["-ssi_mesh", "grid", "-ssi_mesh_size", "7,5", "-ssi_mesh_h", "1", "-ssi_symmetry", "x=sym,y=sym",
                   "-ssi_load_group", "box:0,1,0,1", "-ssi_load_p0", "1000", "-ssi_output", str(tmp_path / "g.h5")])
    assert "[ssi] mesh: element sides 0.875 .. 1.25 m for -ssi_mesh_h 1 m" in r.stdout, r.stdout[-3000:]
    r = cli(BEM + ["-ssi_mesh", "grid", "-ssi_mesh_size", "8,8", "-ssi_mesh_h", "1", "-ssi_load_group",
                   "box:0,1,0,1", "-ssi_load_p0", "1000", "-ssi_output", str(tmp_path / "h.h5")])
    assert "[ssi] mesh: element sides" not in r.stdout                  # (sizes as asked: no line)


def test_a_threshold_time_before_the_rayleigh_arrival_is_warned(tmp_path):
    """-ssi_interp linear with T_L = 0.015 s on an 11 x 7 m grid: the receiver 5 m from the load's centre sees
    the Rayleigh wave at 5 / c_R = 0.0172 s (c_R = 290.5 m/s for c_s 316, c_p 548), so lags that carry it are
    interpolated: one warning naming both times and the paper's rule (1.5 x 5 / 316 = 0.0237 s). T_L = 0.03 s,
    after the arrival: no warning."""
    base = BEM[:-2] + ["-ssi_t_end", "0.15", "-ssi_mesh", "grid", "-ssi_mesh_size", "11,7", "-ssi_mesh_h", "1",
                       "-ssi_load_group", "box:-1,1,-1,1", "-ssi_load_p0", "1000", "-ssi_receivers", "3,0,0;5,0,0",
                       "-ssi_interp", "linear", "-ssi_interp_k", "6"]
    r = cli(base + ["-ssi_interp_tl", "0.015", "-ssi_output", str(tmp_path / "a.h5")])
    w = [ln for ln in r.stdout.splitlines() if ln.startswith("petsc-ssi: warning: -ssi_interp_tl")]
    assert len(w) == 1 and "0.015 s is before the Rayleigh wave's arrival" in w[0] and "(0.01721 s)" in w[0] \
        and "T_L = 0.02373 s" in w[0], r.stdout[-3000:]
    # (the others through `petsc-ssi estimate`, whose set-up is the run's: HalfSpace.interp_plan warns in both)
    r = cli(["estimate"] + base + ["-ssi_interp_tl", "0.03", "-ssi_output", str(tmp_path / "b.h5")])
    assert "warning: -ssi_interp_tl" not in r.stdout and "estimate of this BEM run" in r.stdout, r.stdout[-3000:]
    # a receiver so far from the load (9.5 m on an 8 x 8 m grid) that the paper's rule would reach T_N: the warning
    # says the rule keeps every lag exact (it was a TypeError, formatting the rule's T_L None)
    r = cli(["estimate", "-ssi_problem", "bem", "-ssi_mesh_size", "8,8", "-ssi_mesh_h", "1", "-ssi_load_group",
             "box:2.5,4,2.5,4",
             "-ssi_load_p0", "1000", "-ssi_cp", "200", "-ssi_cs", "100", "-ssi_dt", "0.0025", "-ssi_t_end", "0.12",
             "-ssi_receivers", " -3.5,-3.5,0", "-ssi_interp", "linear", "-ssi_interp_tl", "0.01", "-ssi_interp_k", "3",
             "-ssi_warn_beta", "0", "-ssi_output", str(tmp_path / "c.h5")])
    w = [ln for ln in r.stdout.splitlines() if ln.startswith("petsc-ssi: warning: -ssi_interp_tl")]
    assert len(w) == 1 and "0.01 s is before the Rayleigh wave's arrival" in w[0] \
        and "keeps every lag exact here" in w[0], r.stdout[-3000:]


def test_a_failed_step_matrix_lu_is_named():
    """MUMPS's failed factorisation of the soil's step matrix (here forced: 1 MB of working memory per rank)
    is one line naming INFOG(1) and the options that give MUMPS room, on every rank, not the -3 of the first
    solve's MUMPS call with a traceback."""
    args = ["-ssi_problem", "bem", "-ssi_mesh_size", "6,6", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
            "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.0025", "-ssi_t_end", "0.01",
            "-ssi_bem_mat_mumps_icntl_23", "1"]
    for n in (1, 2):
        r = cli(args, nranks=n, check=False)
        text = r.stdout + r.stderr
        assert r.returncode != 0 and "Traceback" not in text, text[-2000:]
        assert text.count("the soil's step matrix") == 1 and "MUMPS's LU failed, INFOG(1) = -" in text
        assert "-ssi_bem_mat_mumps_icntl_14" in text
