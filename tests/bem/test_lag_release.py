"""A finished run frees its soil's lag matrices (``TransientProblem.release_lags``): their python Mats and
contexts hold each other through PETSc, out of the collector's reach, so a script that ran problem after
problem in one process (a parameter study, ``petsc-ssi impedance``'s modes, these tests' workers) kept every
run's lags until exit."""
import gc
import weakref

import pytest

pytestmark = pytest.mark.run


@pytest.mark.parametrize("store", ["dense", "toeplitz"])
def test_a_finished_run_frees_its_lag_matrices(tmp_path, store, monkeypatch):
    from helpers import run_bem
    from petsc_ssi.bem import march as M
    seen = []
    release = M.Marcher.release

    def watched(self):
        for Ms in (self.H, self.G, self.HI, self.GI):
            for A in Ms:
                if A is not None and A.getType() == "python":
                    seen.append(weakref.ref(A.getPythonContext()))
        release(self)
    monkeypatch.setattr(M.Marcher, "release", watched)
    res = run_bem(problem="bem", cp=200, cs=100, rho=1800, mesh_size="4,4", mesh_h=1, mesh_patch="1,1",
                  load_group="load", load_p0=1000, dt=0.0025, t_end=0.03, receivers="1,0,0", warn_beta=0,
                  lag_store=store, lag_storage="sparse", output=str(tmp_path / "r.h5"))
    assert abs(res["u"]).max() > 0
    gc.collect()
    assert seen, "the run did not release its lags (or held no python Mats)"
    alive = [r for r in seen if r() is not None]
    assert not alive, f"{len(alive)} of {len(seen)} lag Mat contexts outlive the run"
