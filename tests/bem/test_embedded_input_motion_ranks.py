"""An embedded massless footing (``tests/bem/test_embedded_input_motion.py``) at -n 2 equals -n 1: its
condition's free-field share (``MasslessFooting.free_field_resultant``) is formed on every rank from the
whole region, the scattered share is a collective reduction, and the two must give each rank the same q."""
import h5py
import numpy as np
import pytest

from helpers import cli
from test_history_block import same

pytestmark = pytest.mark.mpi


def record(path, T=0.008):
    t = np.arange(0.0, T + 1e-12, T / 80)
    np.savetxt(path, np.c_[t, np.sin(np.pi * t / T) ** 4], header="units: m/s2")
    return str(path)


# slow tier: two runs, one at -n 2 (7 s); the -n 1 run's physics stays in the default tier
# (test_embedded_input_motion.py)
@pytest.mark.slow
def test_two_ranks_equal_one(tmp_path):
    """D/B = 1 on 1 m elements, vertical S: the footing's motion, the free field's share and every recorded
    field at -n 2 equal -n 1's to 1e-12 of their scale."""
    args = ["-ssi_problem", "bem", "-ssi_mesh", "pit", "-ssi_mesh_params", "a=1,b=1,d=1", "-ssi_mesh_size", "8,8",
            "-ssi_mesh_h", "1", "-ssi_disp_group", "pit", "-ssi_disp_rigid", "massless", "-ssi_disp_ref", "0,0,-1",
            "-ssi_seismic", "vertical", "-ssi_seismic_record_x", record(tmp_path / "r.txt"), "-ssi_seismic_units",
            "m/s2", "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none", "-ssi_dt", "9.4e-4", "-ssi_t_end",
            "0.03", "-ssi_scheme", "plain", "-ssi_output_stride", "4", "-ssi_warn_beta", "0"]
    a, b = str(tmp_path / "a.h5"), str(tmp_path / "b.h5")
    cli(args + ["-ssi_output", a])
    cli(args + ["-ssi_output", b], nranks=2)
    same(a, b, 1e-12)
    with h5py.File(a) as fa, h5py.File(b) as fb:
        for k in ("translation", "rotation", "free_field_resultant"):
            x, y = fa["input_motion"][k][:], fb["input_motion"][k][:]
            assert np.abs(x).max() > 0 and np.abs(x - y).max() <= 1e-12 * np.abs(x).max(), k
