"""The importable problems (petsc_ssi/problem.py): a script that steps a problem itself gets what
`run()` gives, can act between steps, and is told when it calls the stages out of order.

Each case is small (seconds). The comparison is exact: the same algebra in the same order."""
import numpy as np
import pytest

from helpers import petsc

pytestmark = pytest.mark.run

SSI = dict(problem="ssi", cp=42, cs=20, rho=1800, mesh_size="2,2", mesh_h=0.5, mesh_patch="0.5,0.5",
           fem_box_cells="4,4,1", fem_box_size="1,1,0.25", fem_box_origin="-0.5,-0.5,0", fem_E=300e9, fem_rho=200,
           fem_load_group="top", fem_load_p0=1000, fem_load_history="box", fem_load_t0=0.05,
           dt=0.0125, t_end=0.15, output_stride=0, warn_beta=0, receivers="1,0,0")
FEM = dict(problem="fem", fem_box_cells="2,2,2", fem_fixed="base", fem_load_group="top", fem_load_p0=1000,
           fem_load_history="box", fem_load_t0=0.01, dt=2e-3, t_end=0.02, output_stride=0,
           receivers="0,0,0.5")
BEM = dict(problem="bem", mesh_size="4,4", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000,
           dt=0.005, t_end=0.03, output_stride=0, receivers="2,0,0")


class opts:
    """The options set in the database for the block (and removed after)."""

    def __init__(self, **kw):
        self.kw = kw

    def __enter__(self):
        self.db = petsc().Options()
        for k, v in self.kw.items():
            self.db.setValue("ssi_" + k, str(v))

    def __exit__(self, *exc):
        for k in self.kw:
            self.db.delValue("ssi_" + k)


@pytest.mark.parametrize("case", ["bem", "fem", "ssi"])
def test_stepping_by_hand_equals_run(case, tmp_path):
    """from_options + setup/start/step/finish gives the receivers of run(), bit for bit; the state
    between steps is the problem's own (its norm is the one the recorder keeps)."""
    from petsc_ssi.app.kinds import from_options
    from petsc_ssi.petsc import init
    kw = {"bem": BEM, "fem": FEM, "ssi": SSI}[case]
    with opts(**kw, output=tmp_path / "a.h5"):
        a = from_options().run()
    with opts(**kw, output=tmp_path / "b.h5"):
        p = from_options()
        assert p.kind == case and p.n_steps > 3
        p.setup()
        p.start()
        norms = []
        for n in range(1, p.n_steps + 1):
            state = p.step(n)
            assert isinstance(state[0], init().Vec)
            norms.append(state[0].norm())
        b = p.finish()
    if case == "fem":
        assert np.array_equal(a["u"], b["u"]) and np.abs(a["u"]).max() > 0
    else:
        assert np.array_equal(a["u"], b["u"]) and np.abs(a["u"]).max() > 0
        assert np.allclose(norms, b["unorm"], rtol=0, atol=0)
    if case == "ssi":
        it = b["interface"]
        assert np.array_equal(it["uf"], a["interface"]["uf"])
        # equilibrium at every step, read from the states the script saw
        assert np.abs(it["force_fe"] + it["force_be"]).max() < 1e-10 * np.abs(it["force_be"]).max()


def test_acting_between_steps_changes_the_run(tmp_path):
    """A script may change the load between steps (here: the FEM load doubled after step 3 by
    scaling the spatial load Vec): the receiver equals the plain run's up to step 3 and differs
    by more than 0.1% from step 5 on."""
    from petsc_ssi.app.kinds import from_options
    with opts(**{**FEM, "output": tmp_path / "a.h5", "fem_load_history": "heaviside", "output_overwrite": 1}):
        a = from_options().run()
        p = from_options()
        p.setup()
        p.start()
        for n in range(1, p.n_steps + 1):
            if n == 4:
                p.F.scale(2.0)
            p.step(n)
        b = p.finish()
    ua, ub = a["u"][:, 0, 2], b["u"][:, 0, 2]
    assert np.array_equal(ua[:4], ub[:4])
    assert np.all(np.abs(ub[5:] - ua[5:]) > 1e-3 * np.abs(ua[5:]))


def test_stages_out_of_order_are_refused(tmp_path):
    from petsc_ssi.app.kinds import from_options
    from petsc_ssi.petsc import SSIError
    with opts(**FEM, output=tmp_path / "a.h5"):
        p = from_options()
        with pytest.raises(SSIError, match="step 1 before start"):
            p.step(1)
        with pytest.raises(SSIError, match=r"start\(\) out of order, the problem is 'created'"):
            p.start()
        p.setup()
        p.start()
        p.step(1)
        with pytest.raises(SSIError, match="step 3 out of order"):
            p.step(3)
        for n in range(2, p.n_steps + 1):
            p.step(n)
        with pytest.raises(SSIError, match="out of order"):
            p.step(p.n_steps + 1)
        p.finish()
