"""Issue 30, "wrong or silent": inputs that used to run on with a wrong result, do nothing silently,
or crash, now refused in one line ('petsc-ssi: error: ...', exit status 2, every rank, before the
work) or named in one warning line. Each check here fails on the code before its fix."""
import pytest

from helpers import cli

pytestmark = pytest.mark.run


def one_line_error(r):
    """The single error line of a refused run (exit status 2, no traceback)."""
    errs = [ln for ln in r.stderr.splitlines() if ln.startswith("petsc-ssi: error: ")]
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert len(errs) == 1, r.stdout
    assert "Traceback" not in r.stderr, r.stderr
    return errs[0]


# ------------------------------------------------------------ options files that include each other

@pytest.mark.parametrize("n", [1, 2])
def test_options_files_in_a_cycle_are_named(tmp_path, n):
    """A file that includes itself, or three that include each other, made PETSc recurse to a
    segmentation fault; now one line names the cycle, before PETSc starts."""
    (tmp_path / "self.opts").write_text(f"-ssi_dt 1e-3\n-options_file {tmp_path}/self.opts\n")
    line = one_line_error(cli(["-options_file", str(tmp_path / "self.opts")], nranks=n, check=False))
    assert line == f"petsc-ssi: error: -options_file {tmp_path}/self.opts includes itself (remove its -options_file line)"
    if n > 1:
        return                     # the rest is the same check before PETSc starts: -n 1 only (cheap tests)
    (tmp_path / "a.opts").write_text(f"-ssi_dt 1e-3\n-options_file {tmp_path}/b.opts\n")
    (tmp_path / "b.opts").write_text(f"# b\n-options_file {tmp_path}/c.opts\n")
    (tmp_path / "c.opts").write_text(f"-ssi_t_end 1\n-options_file {tmp_path}/a.opts\n")
    line = one_line_error(cli(["-options_file", str(tmp_path / "a.opts")], nranks=n, check=False))
    assert f"{tmp_path}/a.opts -> {tmp_path}/b.opts -> {tmp_path}/c.opts -> {tmp_path}/a.opts: " \
           "the options files include each other in a cycle" in line, line
    # an included file that is missing is named with the file that includes it
    (tmp_path / "d.opts").write_text(f"-options_file {tmp_path}/nope.opts\n")
    line = one_line_error(cli(["-options_file", str(tmp_path / "d.opts")], nranks=n, check=False))
    assert f"nope.opts (included by {tmp_path}/d.opts): No such file" in line, line


def test_options_petsc_refuses_at_start_are_one_line(tmp_path):
    """An options file PETSc itself refuses in PetscInitialize (here a YAML file it cannot parse, which the
    check before PETSc starts does not read) printed PETSc's page and then a Python traceback of petsc4py's
    init: now PETSc's message and one line, exit status 2."""
    (tmp_path / "bad.yaml").write_text("a: [\n")
    line = one_line_error(cli(["-options_file_yaml", str(tmp_path / "bad.yaml")], check=False))
    assert line.startswith("petsc-ssi: error: PETSc did not start (error code "), line


# ------------------------------------------------------------ impedance: symmetry planes of the footing

IMP = ["impedance", "-ssi_cp", "548", "-ssi_cs", "316", "-ssi_rho", "2000", "-ssi_mesh_size", "6,4",
       "-ssi_mesh_h", "0.5", "-ssi_dt", "8e-4", "-ssi_t_end", "0.012", "-ssi_warn_beta", "0",
       "-ssi_output_overwrite"]


def _K0(csv_path):
    import csv
    with open(csv_path) as fh:
        return {row["mode"]: float(row["K0"]) for row in csv.DictReader(fh)}


# slow tier: the make-test budget (10-20 s); the default tier's sibling: test_impedance_needs_soil_around_the_footing
@pytest.mark.slow
def test_impedance_of_an_off_centre_footing_uses_only_its_planes(tmp_path):
    """A 2 m x 2 m footing on x in [0, 2] m: the plane x = 0 used to be applied anyway (the footing
    mirrored into one twice as long: K0 1.45 times too large here, 2.9 in the issue's case). Now
    only y = 0 is used, the line says so, x_ref is the footing's centre, and K0 (vertical, rocking)
    equals the whole surface's (-ssi_impedance_symmetry 0) to 1e-6 (the plane's round-off only)."""
    args = IMP + ["-ssi_disp_group", "box:0,2,-1,1", "-ssi_impedance_modes", "vertical,rocking"]
    r = cli(args + ["-ssi_output", str(tmp_path / "sym.h5")])
    assert ("[impedance] symmetry planes used: y = 0 (x = 0 not used: the footing (spanning x in [0, 2] m) is "
            "not symmetric about it); reference point x_ref = (1, 0, 0) m") in r.stdout, r.stdout
    cli(args + ["-ssi_output", str(tmp_path / "whole.h5"), "-ssi_impedance_symmetry", "0"])
    a, b = _K0(tmp_path / "sym-impedance.csv"), _K0(tmp_path / "whole-impedance.csv")
    for mode in ("vertical", "rocking"):
        assert abs(a[mode] / b[mode] - 1) < 1e-6, (mode, a[mode], b[mode])


@pytest.mark.parametrize("n", [1, 2])
def test_impedance_needs_soil_around_the_footing(tmp_path, n):
    """The whole meshed surface as the footing (-ssi_disp_group surface), or a footing reaching the
    surface's edge, was run and compared with Pais & Kausel without a word; now refused in one line
    before the runs."""
    args = IMP + ["-ssi_output", str(tmp_path / "i.h5"), "-ssi_impedance_modes", "vertical"]
    line = one_line_error(cli(args + ["-ssi_disp_group", "surface"], nranks=n, check=False))
    assert line == ("petsc-ssi: error: -ssi_disp_group surface: the footing is the whole meshed surface; petsc-ssi "
                    "impedance needs the footing as a part of the surface with soil around it (mesh a larger "
                    "surface or name a smaller group)")
    if n > 1:
        return
    r = cli(args + ["-ssi_disp_group", "box:1,3,-1,1"], check=False)
    assert "the footing reaches the edge of the meshed surface (at x = 3, y = " in one_line_error(r)
    assert "[impedance] mode" not in r.stdout


# ------------------------------------------------------------ options that do nothing in the run given

BEM = ["-ssi_mesh_size", "4,4", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1", "-ssi_load_group", "load",
       "-ssi_load_p0", "1", "-ssi_dt", "0.005", "-ssi_t_end", "0.01", "-ssi_warn_beta", "0", "-ssi_output_overwrite"]
FEM = ["-ssi_problem", "fem", "-ssi_fem_box_cells", "2,2,2", "-ssi_t_end", "0.01", "-ssi_dt", "0.005",
       "-ssi_output", ""]
BUILDING = ["static", "-options_file", "runs/building/fixed-base.opts", "-ssi_output_overwrite"]


@pytest.mark.parametrize("n", [1, 2])
def test_options_of_another_kind_of_run_are_named(tmp_path, n):
    """-ssi_fem_* and -ssi_contact in a BEM run, -ssi_lags_load and -ssi_memory_limit in a FEM run: one
    warning line naming them, before the run (the run goes on: a shared options file is legitimate)."""
    r = cli(BEM + ["-ssi_output", str(tmp_path / "b.h5"), "-ssi_fem_E", "1e9", "-ssi_contact", "bonded"], nranks=n)
    warns = [ln for ln in r.stdout.splitlines() if ln.startswith("petsc-ssi: warning: options this run does not read")]
    assert warns == ["petsc-ssi: warning: options this run does not read (fem, ssi options; it reads the common and "
                     "bem, seismic ones): -ssi_fem_E -ssi_contact"], r.stdout
    assert r.stdout.index(warns[0]) < r.stdout.index("[ssi] BEM:"), r.stdout
    if n == 1:
        r = cli(FEM + ["-ssi_lags_load", str(tmp_path / "lags"), "-ssi_memory_limit", "3"])
        assert ("petsc-ssi: warning: options this run does not read (bem options; it reads the common and fem, "
                "seismic ones): -ssi_lags_load -ssi_memory_limit") in r.stdout, r.stdout


@pytest.mark.parametrize("n", [1, 2])
def test_solver_options_without_our_prefix_are_refused(tmp_path, n):
    """-ksp_type / -pc_type reach no solver (ours are -ssi_bem_, -ssi_fem_, -ssi_modes_ prefixed):
    refused in one line, naming the prefixed spelling, instead of a run with the defaults."""
    r = cli(FEM + ["-ksp_type", "gmres", "-pc_type", "jacobi"], nranks=n, check=False)
    line = one_line_error(r)
    assert line.startswith("petsc-ssi: error: -ksp_type: no solver of petsc-ssi reads PETSc options without its "
                           "prefix; write -ssi_bem_ksp_type or -ssi_fem_ksp_type"), line
    assert line.endswith("(also: -pc_type)"), line
    assert "[fem]" not in r.stdout


COUPLED = ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800",
           "-ssi_mesh_size", "2,2", "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5",
           "-ssi_fem_box_cells", "4,4,1", "-ssi_fem_box_size", "1,1,0.5", "-ssi_dt", "0.0125", "-ssi_t_end", "0.025",
           "-ssi_warn_beta", "0", "-ssi_output_overwrite"]


@pytest.mark.parametrize("n", [1, 2])
def test_interface_offset_on_bricks_is_refused(tmp_path, n):
    """-ssi_interface_offset offsets a shell slab's interface; on brick faces it did nothing, silently."""
    r = cli(COUPLED + ["-ssi_output", str(tmp_path / "c.h5"), "-ssi_interface_offset", "1"], nranks=n, check=False)
    assert one_line_error(r) == ("petsc-ssi: error: -ssi_interface_offset: the interface (-ssi_fem_interface base) "
                                 "has no shell slab nodes; the offset applies to a shell foundation slab only and "
                                 "does nothing here: drop it")
    assert "assembl" not in r.stdout.lower(), r.stdout


MESH_PARAMS = [
    ("nbxx=2", "-ssi_fem_mesh_params nbxx=2: 'meshes/building.geo' has no parameter 'nbxx' (its parameters: h, half, "
               "hc, hs, nbx, nby, ns, sx, sy)"),
    ("h=-1", "-ssi_fem_mesh_params h=-1: 'meshes/building.geo' declares h >= 0.001"),
    ("half=2", "-ssi_fem_mesh_params half=2: 'meshes/building.geo' allows half in {0, 1}"),
    ("ns=2.5", "-ssi_fem_mesh_params ns=2.5: 'meshes/building.geo' declares ns an integer"),
]


@pytest.mark.parametrize("params, msg", MESH_PARAMS, ids=[p for p, _ in MESH_PARAMS])
def test_mesh_params_the_geo_cannot_use_are_refused(tmp_path, params, msg):
    """gmsh takes an undeclared ONELAB parameter (a misspelt name) or a value out of the .geo's declared
    range without a word: the building was meshed with its defaults, or with h = -1, and solved."""
    r = cli(BUILDING + ["-ssi_output", str(tmp_path / "s.h5"), "-ssi_fem_mesh_params", params], check=False)
    assert one_line_error(r) == "petsc-ssi: error: " + msg
    assert "[static]" not in r.stdout


@pytest.mark.parametrize("n", [1, 2])
def test_mesh_params_without_a_geo_and_a_zero_mass_per_area_are_refused(tmp_path, n):
    if n == 1:
        line = one_line_error(cli(FEM + ["-ssi_fem_mesh_params", "h=1"], check=False))
        assert line.startswith("petsc-ssi: error: -ssi_fem_mesh_params: the box generator (-ssi_fem_mesh box) has no "
                               "parameters"), line
    line = one_line_error(cli(BEM + ["-ssi_output", str(tmp_path / "b.h5"), "-ssi_mesh_params", "h=1"], nranks=n,
                              check=False))
    assert line.startswith("petsc-ssi: error: -ssi_mesh_params: the grid generator (-ssi_mesh grid) has no "
                           "parameters"), line
    if n > 1:
        return
    # mass_per_area 0 meant 'not given': the slab kept rho * thickness, silently
    r = cli(BUILDING + ["-ssi_output", str(tmp_path / "s.h5"), "-ssi_fem_part_roof_mass_per_area", "0"], nranks=n,
            check=False)
    assert one_line_error(r) == ("petsc-ssi: error: -ssi_fem_part_roof_mass_per_area 0: must be > 0 (0 does nothing: "
                                 "the shell's mass per area stays rho * thickness; for a massless shell set "
                                 "-ssi_fem_part_roof_rho 0)")


@pytest.mark.parametrize("args, msg", [
    (["--spectrum", "--fmax", "-1"], "--fmax -1: must be > 0 Hz"),
    (["--spectrum", "--peaks", "-3"], "--peaks -3: must be >= 0"),
    (["--spectrum", "--min-sep", "-1"], "--min-sep -1: must be >= 0 Hz"),
    (["--transfer", "0", "0", "--eps", "0"], "--eps 0: must be > 0"),
])
def test_post_numbers_out_of_range_are_refused(tmp_path, args, msg):
    """post --fmax -1 kept no frequency and --peaks -3 printed none, with status 0."""
    import h5py
    import numpy as np
    path = str(tmp_path / "r.h5")
    t = np.arange(64) * 0.01
    with h5py.File(path, "w") as f:
        f["receivers/t"] = t
        f["receivers/u"] = np.sin(2 * np.pi * 10 * t)[:, None, None] * np.ones((1, 1, 3))
        f["receivers/points"] = np.zeros((1, 3))
    r = cli(["post", path] + args, check=False)
    assert r.returncode == 2 and r.stderr.strip() == f"petsc-ssi post: error: {msg}", (r.stdout, r.stderr)


# ------------------------------------------------------------ a t_end that would step for ever

@pytest.mark.parametrize("n", [1, 2])
def test_a_run_of_too_many_steps_is_refused_before_any_work(tmp_path, n):
    """-ssi_t_end 1e6 on a small case started stepping for ever (2e8 steps); now refused in one line
    naming the count, before the mesh; a FEM run too."""
    r = cli(BEM + ["-ssi_output", str(tmp_path / "b.h5"), "-ssi_t_end", "1e6"], nranks=n, check=False, timeout=60)
    assert one_line_error(r) == ("petsc-ssi: error: -ssi_t_end 1e+06 with -ssi_dt 0.005 is 2e+08 time steps, more "
                                 "than -ssi_max_steps 1000000; check t_end and dt, or raise -ssi_max_steps to run them")
    assert "[ssi]" not in r.stdout
    if n > 1:
        return
    r = cli(FEM + ["-ssi_t_end", "1", "-ssi_max_steps", "100"], check=False, timeout=60)
    assert "is 200 time steps, more than -ssi_max_steps 100" in one_line_error(r)


def test_the_steps_and_the_predicted_time_are_told_before_the_loop(tmp_path):
    """Before the assembly: the number of steps (ceil(t_end / dt), here 0.1 / 0.005 = 20) and the cost
    model's predicted time of the loop."""
    import re
    r = cli(BEM + ["-ssi_output", str(tmp_path / "b.h5"), "-ssi_t_end", "0.1", "-ssi_monitor"])
    m = re.search(r"\[ssi\] time loop: (\d+) steps of 0.005 s to t = 0.1 s; predicted ([0-9.e-]+) ?s \(the soil's BEM: "
                  r"about ([0-9.e-]+) s per step", r.stdout)
    assert m and int(m.group(1)) == 20, r.stdout
    assert float(m.group(2)) > 0 and float(m.group(3)) > 0
    assert r.stdout.index(m.group(0)) < r.stdout.index("assembl"), r.stdout
    r = cli(FEM)
    assert "[ssi] time loop: 2 steps of 0.005 s to t = 0.01 s\n" in r.stdout, r.stdout


# ------------------------------------------------------------ no output file; a structure command without a structure

@pytest.mark.parametrize("n", [1, 2])
def test_no_output_file_is_refused_where_the_results_live_in_it(n):
    """-ssi_output '' on a BEM or coupled run assembled, then ended in an HDF5 error and a traceback;
    now refused in one line before any work. (A FEM run takes '' as 'no output'.)"""
    for args, what in ((BEM, "a BEM"), (COUPLED, "a coupled"))[n - 1:]:
        r = cli(args + ["-ssi_output", ""], nranks=n, check=False, timeout=60)
        assert one_line_error(r) == (f"petsc-ssi: error: -ssi_output '': {what} run keeps its results in its output "
                                     "file; give a file name (only a FEM run, -ssi_problem fem, runs without one)")
        assert "[ssi]" not in r.stdout, r.stdout


@pytest.mark.parametrize("n", [1, 2])
def test_static_and_modes_need_a_structure(tmp_path, n):
    """`petsc-ssi static` with a soil-only options set meshed the default 1 m box and failed on a
    receiver (or solved the box); now one line saying a structure is needed."""
    for cmd in ("static", "modes")[:3 - n]:
        r = cli([cmd] + BEM + ["-ssi_output", str(tmp_path / "s.h5"), "-ssi_receivers", "3,0,0"], nranks=n,
                check=False, timeout=60)
        assert one_line_error(r).startswith(f"petsc-ssi: error: petsc-ssi {cmd} needs a structure, and these options "
                                            "describe none (no -ssi_fem_* option, -ssi_problem bem)"), r.stdout


# ------------------------------------------------------------ post --plot of a structure's output

def _write_receivers(path, attrs, points, u, extra=()):
    import h5py
    import numpy as np
    with h5py.File(path, "w") as f:
        f.attrs.update(attrs)
        f["receivers/t"] = np.arange(u.shape[0]) * 0.01
        f["receivers/points"] = np.asarray(points, float)
        f["receivers/u"] = u
        for name in extra:
            f["receivers/" + name] = 2 * u
    return str(path)


def _captured_plot(monkeypatch, fn):
    """Run ``fn()`` with petsc_ssi.plot's figures kept: the list of figures it drew."""
    import petsc_ssi.plot as plot
    figs = []
    real = plot._mpl

    def mpl():
        plt = real()

        class Wrap:
            def __getattr__(self, name):
                return getattr(plt, name)

            def subplots(self, *a, **k):
                fig, axs = plt.subplots(*a, **k)
                figs.append(fig)
                return fig, axs

            def close(self, fig):
                pass
        return Wrap()
    monkeypatch.setattr(plot, "_mpl", mpl)
    fn()
    return figs


def test_post_plot_of_a_structure_draws_its_own_quantity_against_time(tmp_path, monkeypatch):
    """A roof receiver at x = y = 0 swaying in x: the plot was the Lamb form (r taken as 1 m, the
    'radial' component 0: a flat line). Now t [s] and the stored series in its unit, the curve the
    file's own numbers; --quantity velocity draws the velocity in m/s. A BEM run loaded on a patch
    with receivers off the axis keeps the Lamb form."""
    import numpy as np
    from petsc_ssi.plot import receiver_plot
    t = np.arange(50) * 0.01
    u = np.zeros((50, 1, 3))
    u[:, 0, 0] = 1e-3 * np.sin(2 * np.pi * 2 * t)
    path = _write_receivers(tmp_path / "s.h5", {"problem": "fem"}, [[0, 0, 9]], u, extra=("velocity",))
    for series, label, factor in (("receivers/u", "displacement [m]", 1), ("receivers/velocity", "velocity [m/s]", 2)):
        figs = _captured_plot(monkeypatch, lambda: receiver_plot(path, png=str(tmp_path / "p.png"), series=series))
        ax = figs[0].axes[0]
        assert ax.get_xlabel() == "t [s]" and ax.get_ylabel() == label, (ax.get_xlabel(), ax.get_ylabel())
        x, y = ax.lines[0].get_data()
        assert np.array_equal(x, t) and np.array_equal(y, factor * u[:, 0, 0])      # the sway, not a flat line
    # the Lamb form stays for a loaded patch with receivers off the axis ...
    lamb = {"problem": "bem", "load_p0": 1.0, "load_patch": "1,1", "cp": 548.0, "cs": 316.0, "rho": 2000.0}
    p2 = _write_receivers(tmp_path / "b.h5", lamb, [[3, 0, 0]], u)
    figs = _captured_plot(monkeypatch, lambda: receiver_plot(p2, png=str(tmp_path / "q.png"), reference=False))
    assert figs[0].axes[0].get_xlabel() == r"$\tau = c_s t / r$"
    # ... but not with a receiver on it (r = 0)
    p3 = _write_receivers(tmp_path / "c.h5", lamb, [[3, 0, 0], [0, 0, 0]], np.concatenate([u, u], 1))
    figs = _captured_plot(monkeypatch, lambda: receiver_plot(p3, png=str(tmp_path / "r.png")))
    assert figs[0].axes[0].get_xlabel() in ("", "t [s]") and figs[0].axes[-1].get_xlabel() == "t [s]"
    # through the command line: a PNG, status 0; a quantity the file lacks: one line
    r = cli(["post", path, "--plot", str(tmp_path / "v.png"), "--quantity", "velocity"])
    assert (tmp_path / "v.png").stat().st_size > 0
    r = cli(["post", p2, "--plot", str(tmp_path / "w.png"), "--quantity", "velocity"], check=False)
    assert r.returncode == 2 and r.stderr.startswith("petsc-ssi post: error: ") and "Traceback" not in r.stderr


def test_post_receivers_csv_writes_the_quantity_asked_to_the_file_named(tmp_path):
    """--receivers --csv wrote displacements whatever --quantity/--series said, always on standard
    output: velocities, accelerations and rotations could not be exported. Now the series asked,
    to the file named after --csv (standard output without one), its columns named by quantity;
    the values are the file's to 1e-9 (9 significant digits written)."""
    import csv
    import io
    import h5py
    import numpy as np
    t = np.arange(5) * 0.01
    rng = np.random.default_rng(3)
    data = {q: rng.standard_normal((5, 2, 3)) for q in ("u", "velocity", "acceleration", "rotation")}
    path = str(tmp_path / "s.h5")
    with h5py.File(path, "w") as f:
        f.attrs["problem"] = "fem"
        f["receivers/t"] = t
        f["receivers/points"] = np.array([[0, 0, 9.0], [1, 0, 0]])
        f["receivers/has_rotation"] = np.array([1, 0])
        for q, v in data.items():
            f["receivers/" + q] = v
    for q, p in (("velocity", "v"), ("acceleration", "a"), ("rotation", "r")):
        out = tmp_path / f"{q}.csv"
        cli(["post", path, "--receivers", "--quantity", q, "--csv", str(out)])
        rows = list(csv.DictReader(open(out)))
        assert list(rows[0]) == ["receiver", "x", "y", "z", "t", p + "x", p + "y", p + "z"]
        assert len(rows) == 2 * 5
        got = np.array([[float(r[p + c]) for c in "xyz"] for r in rows[:5]])
        assert np.abs(got - data[q][:, 0]).max() <= 1e-8 * np.abs(data[q]).max()
        if q == "rotation":                     # receiver 1 has no rotation: empty cells, not zeros
            assert rows[5][p + "x"] == "" and rows[9][p + "z"] == ""
        else:
            assert np.isclose(float(rows[9][p + "z"]), data[q][4, 1, 2], rtol=1e-8)
    r = cli(["post", path, "--receivers", "--series", "receivers/acceleration", "--csv"])
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    assert np.isclose(float(rows[0]["ax"]), data["acceleration"][0, 0, 0], rtol=1e-8)
    r = cli(["post", path, "--receivers", "--csv"])
    assert r.stdout.splitlines()[0] == "receiver,x,y,z,t,ux,uy,uz"


# ------------------------------------------------------------ PETSc refuses a solver option

@pytest.mark.parametrize("n", [1, 2])
def test_a_solver_option_petsc_refuses_is_one_line(tmp_path, n):
    """-ssi_bem_mat_mumps_icntl_7 1 (MUMPS's user-given ordering, which PETSc's MUMPS interface refuses)
    stopped the run at the step matrix's factorisation with a Python traceback, PETSc's own message only
    in the stack printed at exit (lost under MPI_Abort). Now one line from each rank that met it, with where and PETSc's
    message, no traceback, a non-zero exit (MPI_Abort on more ranks: PETSc may raise on some ranks only)."""
    r = cli(BEM + ["-ssi_output", str(tmp_path / "b.h5"), "-ssi_bem_mat_mumps_icntl_7", "1"], nranks=n, check=False,
            timeout=120)
    # (each rank prints its line; under MPI_Abort mpirun may drop a rank's last output, so at least one; the
    # lines are read from each "petsc-ssi: error: " on, should mpirun's relay run two ranks' lines together)
    errs = ["petsc-ssi: error: " + part.splitlines()[0].rstrip() for part in r.stderr.split("petsc-ssi: error: ")[1:]]
    assert r.returncode != 0 and 1 <= len(errs) <= n and len(set(errs)) == 1, r.stdout[-3000:] + r.stderr[-3000:]
    assert "Traceback" not in r.stderr, r.stderr
    assert errs[0] == ("petsc-ssi: error: PETSc stopped with error code 63 in petsc_ssi/bem/march.py:"
                       f"{errs[0].split('march.py:')[1].split(' ')[0]} (_factorise) at MatSetFromOptions_MUMPS(): "
                       "Argument out of range; Valid values are 0=AMD, 2=AMF, 3=Scotch, 4=PORD, 5=Metis, 6=QAMD, and "
                       "7=auto (-ssi_debug for the traceback)"), errs[0]
    if n == 1:                  # -ssi_debug: the traceback as before
        r = cli(BEM + ["-ssi_output", str(tmp_path / "b.h5"), "-ssi_bem_mat_mumps_icntl_7", "1", "-ssi_debug"],
                check=False, timeout=120)
        assert r.returncode != 0 and "Traceback" in r.stderr and "petsc-ssi: error:" not in r.stderr
