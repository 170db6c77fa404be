"""Rayleigh damping in the coupled run (issue 43, item 1): both couplings take C = a0 M + a1 K (implicit:
the midpoint form, staggered: the Green scheme), say so in the log and record it in the structure's
output; the stiffness-proportional part damps the structure's ringing after the load."""
import h5py
import numpy as np
import pytest

from helpers import cli

pytestmark = pytest.mark.run

CASE = ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800",
        "-ssi_mesh_size", "2,2", "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5",
        "-ssi_fem_box_cells", "4,4,2", "-ssi_fem_box_size", "1,1,0.5", "-ssi_fem_load_group", "top",
        "-ssi_fem_load_p0", "1000", "-ssi_fem_load_history", "box", "-ssi_fem_load_t0", "0.0125",
        "-ssi_dt", "0.0125", "-ssi_t_end", "0.15", "-ssi_output_stride", "0",
        "-ssi_structure_receivers", "0,0,0.5", "-ssi_warn_beta", "0"]


@pytest.mark.parametrize("coupling", ["implicit", "staggered"])
def test_coupled_run_takes_rayleigh_damping(tmp_path, coupling):
    """The structure's top, relative to its base (the block's own deformation), rings less with a large
    a1 (its modes above 100 Hz: zeta = a1 omega/2 > 0.6 with a1 = 2e-3 s) than without; the soil's
    motion is barely touched; the output records a0, a1."""
    runs = {}
    for name, extra in (("none", []), ("k", ["-ssi_fem_rayleigh", "0,2e-3"])):
        out = tmp_path / f"{name}.h5"
        p = cli(CASE + ["-ssi_coupling", coupling, "-ssi_output", str(out)] + extra)
        with h5py.File(tmp_path / f"{name}_structure.h5", "r") as f:
            runs[name] = (f["receivers/u"][()], dict(f.attrs))
        if name == "k":
            assert "Rayleigh damping C = a0 M + a1 K, a0 = 0 1/s, a1 = 0.002 s" in p.stdout
    (u0, at0), (u1, at1) = runs["none"], runs["k"]
    assert at0["rayleigh_a1"] == 0.0 and at1["rayleigh_a1"] == 2e-3 and at1["alpha_m"] == 0.0
    assert np.all(np.isfinite(u1))
    d0, d1 = np.abs(u0).max(), np.abs(u1 - u0).max()
    assert 1e-3 * d0 < d1 < d0, (d0, d1)
