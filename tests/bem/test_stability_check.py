"""Stability tools (issue 6): the growth-rate classification, the guard rule
on recorded histories, -ssi_check_stability on a deliberately unstable and a
stable configuration, its one-line input errors, and the guard over a sample
of the stable region of runs/stability (it must never stop those runs).

beta = c_s dt / l with l = h/2, the node spacing of 1 m nine-node elements."""
import numpy as np
import pytest

from helpers import run_bem, resolve_error
from petsc_ssi.bem import stability as st

pytestmark = pytest.mark.run

CS = 316.0
L_NODE = 0.5


def _dt(beta):
    return beta * L_NODE / CS


def test_growth_rate_recovers_exponential_rates():
    n = np.arange(1, 1201)
    for r in (-1e-3, 0.0, 3e-5, 5e-4, 1e-2):
        u = 2e-5 * np.exp(r * n)
        assert abs(st.growth_rate(u) - r) < 1e-9, r
    # transient in the first two thirds does not enter the fit
    u = np.where(n < 700, 1e-5 * (1 + np.sin(n)), 1e-5)
    assert abs(st.growth_rate(u)) < 1e-12
    assert st.classify(np.exp(5e-5 * n))[0] == "stable"
    assert st.classify(np.exp(5e-4 * n))[0] == "slowly growing"
    assert st.classify(np.exp(5e-3 * n))[0] == "unstable"
    assert st.classify(np.r_[np.ones(50), np.inf])[0] == "unstable"
    assert st.classify(np.ones(50), stopped=True)[0] == "unstable"


def test_guard_step_rule():
    u = np.ones(300)
    assert st.guard_step(u, 100.0) is None
    u[150:] = np.exp(0.1 * np.arange(150))          # 100 x the first-half max after ln(100)/0.1 = 46 steps
    assert st.guard_step(u, 100.0) == 150 + int(np.ceil(np.log(100) / 0.1)) + 1
    u = np.ones(300); u[5] = np.nan
    assert st.guard_step(u, 100.0) == 6             # a non-finite norm stops at once
    u = np.ones(300); u[10] = 1e9                  # a finite spike before GUARD_MIN_STEPS (20) is ignored
    assert st.guard_step(u, 100.0) is None


CHECK = dict(mesh_size="16,16", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000,
             symmetry="x=sym,y=sym", output_stride=0, warn_beta=0, check_stability=1)


def test_check_stability_reports_unstable_plain_scheme(tmp_path):
    out = tmp_path / "c.h5"
    r = run_bem(**CHECK, scheme="plain", dt=_dt(0.05), t_end=1.0, output=out)
    assert r["verdict"] == "unstable"
    c = r["checks"][0]
    assert abs(c["beta"] - 0.05) < 1e-9 and c["stopped"]
    assert c["steps"] < c["planned"] <= 3 * 341 + 3
    assert not list(tmp_path.iterdir())          # the surrogate's scratch output is removed


def test_check_stability_reports_stable_stabilized_scheme(tmp_path):
    r = run_bem(**CHECK, scheme="stabilized", dt=_dt(0.5), t_end=1.0, output=tmp_path / "c.h5")
    c = r["checks"][0]
    assert r["verdict"] == "stable" and not c["stopped"]
    assert c["steps"] == c["planned"] >= 400
    assert abs(c["rate"]) < st.RATE_SLOW


def test_check_stability_bad_input_is_one_line():
    for opts in ({"check_stability": "maybe"}, {"check_stability": 1, "check_stability_steps": 10}):
        msg = resolve_error(**opts)
        assert msg and "check_stability" in msg and "\n" not in msg, msg


# a sample of the region that runs/stability/stability_map.csv classifies stable
STABLE_SAMPLE = [("plain", 0.15), ("plain", 0.5), ("plain", 2.0),
                 ("stabilized", 0.1), ("stabilized", 0.8), ("stabilized", 2.0)]


@pytest.mark.parametrize("scheme,beta", STABLE_SAMPLE)
def test_guard_never_stops_stable_runs(tmp_path, scheme, beta):
    dt = _dt(beta)
    n = 1000
    r = run_bem(mesh_size="6,6", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000,
                symmetry="x=sym,y=sym", dt=dt, t_end=n * dt, output_stride=0, warn_beta=0, scheme=scheme,
                output=tmp_path / "g.h5")
    un = r["unorm"]
    assert len(un) == n                                 # the guard (default factor) did not stop it
    assert st.classify(un)[0] == "stable", st.growth_rate(un)
    assert st.guard_step(un, 10.0) is None              # not even a ten times tighter guard would
