"""The README's "Output files" table is what a run writes (issue 30, item 5): a small coupled run
(the soil file with its interface group, the structure's `_structure.h5`) is walked with h5py and
its table (petsc_ssi/app/output_table.py) must equal the README's; every dataset carries a
`unit` attribute (before: none did but the groups written as (array, unit) tuples); the timing
conventions the table states hold in the files (soil receivers from t = dt, structure receivers
from t = 0, a snapshot at t = 0 (at rest: zero fields), the last step missed when not a multiple of the stride, no
acceleration field in the structure's XDMF)."""
import os

import h5py
import numpy as np

from helpers import ROOT, cli
import pytest

pytestmark = pytest.mark.run

SSI = ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_size", "2,2",
       "-ssi_mesh_h", "0.5", "-ssi_mesh_patch", "0.5,0.5", "-ssi_fem_box_cells", "4,4,1", "-ssi_fem_box_size",
       "1,1,0.25", "-ssi_fem_box_origin", "-0.5,-0.5,0", "-ssi_fem_E", "300e9", "-ssi_fem_rho", "200",
       "-ssi_dt", "0.0125", "-ssi_t_end", "0.1375", "-ssi_fem_load_group", "top", "-ssi_fem_load_p0", "1000",
       "-ssi_contact", "unilateral", "-ssi_receivers", "1,0,0;0.75,0.25,0",
       "-ssi_structure_receivers", "0,0,0.25;0.5,0,0.25", "-ssi_output_stride", "2", "-ssi_warn_beta", "0"]


def test_readme_output_table_is_a_real_runs(tmp_path):
    from petsc_ssi.app.output_table import table, BEGIN, END
    out = tmp_path / "FILE.h5"
    cli(SSI + ["-ssi_output", str(out)])
    soil, struct = str(out), str(tmp_path / "FILE_structure.h5")
    made = table([(soil, "FILE.h5"), (struct, "FILE_structure.h5")])
    text = open(os.path.join(ROOT, "README.md")).read()
    i, j = text.index(BEGIN) + len(BEGIN), text.index(END)
    assert text[i:j].strip() == made.strip(), "python -m petsc_ssi.app.output_table FILE.h5 FILE_structure.h5"
    dt, n = 0.0125, 11                                  # 11 steps, stride 2
    for path in (soil, struct):
        with h5py.File(path) as f:
            missing = []
            f.visititems(lambda k, o: missing.append(k) if isinstance(o, h5py.Dataset) and "unit" not in o.attrs
                         else None)
            assert not missing, (path, missing)
            assert np.allclose(f["time"][:], dt * np.array([0, 2, 4, 6, 8, 10]))    # t = 0, step 11 missed
            assert not np.any(f["displacement_000000"][:]) and np.any(f["displacement_000001"][:])    # at rest
    with h5py.File(soil) as f:
        assert np.allclose(f["receivers/t"][:], dt * np.arange(1, n + 1)) and f["receivers/u"].attrs["unit"] == "m"
        assert f["interface/p"].attrs["unit"] == "N/m^2" and f["interface/force_fe"].attrs["unit"] == "N"
        assert f["traction_000000"].attrs["unit"] == "N/m^2"
    with h5py.File(struct) as f:
        assert np.allclose(f["receivers/t"][:], dt * np.arange(0, n + 1))
        assert f["receivers/acceleration"].attrs["unit"] == "m/s^2"
    xmf = open(str(tmp_path / "FILE_structure.xmf")).read()
    assert 'Name="displacement"' in xmf and "acceleration" not in xmf
