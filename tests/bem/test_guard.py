"""Run-time stability guard (issue 6): at beta = c_s dt / l = 0.05 the plain
scheme (eq. 6) diverges and the guard stops it within a bounded number of
steps, naming the cause; the stabilised scheme (eq. 7) on the same case runs
all 700 steps and stays bounded (the guard never stops it)."""
import numpy as np
import pytest

from helpers import run_bem
from petsc_ssi.petsc import SSIError
from petsc_ssi.bem.stability import guard_step

pytestmark = pytest.mark.run

BETA = 0.05
DT = BETA * 0.5 / 316.0
CASE = dict(mesh_size="6,6", mesh_h=1.0, mesh_patch="1,1", load_group="load", load_p0=1000,
            symmetry="x=sym,y=sym", dt=DT, t_end=700 * DT, receivers="0,0,0", output_stride=0,
            warn_beta=0)


def test_guard_stops_diverging_plain_scheme(tmp_path):
    with pytest.raises(SSIError) as exc:
        run_bem(**CASE, scheme="plain", output=tmp_path / "p.h5")
    msg = str(exc.value)
    assert "diverging at step" in msg and "plain scheme" in msg and "\n" not in msg
    step = int(msg.split("diverging at step ")[1].split()[0])
    assert 20 < step <= 450, step
    # the history travels with the error, and the recorded-history form of the rule agrees
    assert len(exc.value.unorm) == step
    assert guard_step(exc.value.unorm, 100.0) == step


def test_guard_lets_stabilized_scheme_run(tmp_path):
    r = run_bem(**CASE, scheme="stabilized", output=tmp_path / "s.h5")
    un = r["unorm"]
    assert len(un) == 700
    assert un[-100:].max() <= 1.05 * un[200:400].max()
