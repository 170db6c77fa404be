"""Output: HDF5 (PETSc viewer) + XDMF + JSON record, and `petsc-ssi post`."""
import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np

from helpers import cli, read_h5, ROOT
import pytest

pytestmark = pytest.mark.run


def test_hdf5_xdmf_json_and_post_csv(tmp_path):
    out = tmp_path / "run.h5"
    cli(["-options_file", "runs/pekeris/small.opts", "-ssi_mesh_size", "6,6", "-ssi_t_end", "0.003",
         "-ssi_output_stride", "2", "-ssi_output", str(out), "-ssi_plot",
         "-ssi_receivers", "2,0,0;3,1,0"])
    d = read_h5(out)
    assert {"coordinates", "topology", "time", "displacement_000000", "displacement_000001", "displacement_000002",
            "traction_000000", "receivers"} <= set(d["keys"])
    assert d["u"].shape == (4, 2, 3)
    np.testing.assert_allclose(d["t"], 7.5e-4 * np.arange(1, 5), rtol=1e-12)
    import h5py
    with h5py.File(out) as f:
        ncoord = f["coordinates"].shape
        assert f["topology"].shape[1] == 9 and ncoord[1] == 3
        assert np.all(f["topology"][:] < ncoord[0])
        np.testing.assert_allclose(f["time"][:], [0.0, 1.5e-3, 3.0e-3])     # t = 0 (at rest), steps 2 and 4
        assert not np.any(f["displacement_000000"][:]) and not np.any(f["traction_000000"][:])
        # the applied traction appears in the traction field: -p0 in z under the load
        assert np.isclose(f["traction_000001"][:, 2].min(), -1000.0)
    xmf = ET.parse(str(out).replace(".h5", ".xmf")).getroot()
    grids = xmf.findall(".//Grid[@GridType='Uniform']")
    assert len(grids) == 3 and grids[0].find("Topology").get("TopologyType") == "Quadrilateral_9"
    rec = json.load(open(str(out).replace(".h5", ".json")))
    for key in ("petsc", "petsc4py", "mpi4py", "mpi", "ranks", "options", "git", "hdf5"):
        assert key in rec
    assert rec["options"]["dt"] == 7.5e-4 and rec["option_sources"]["dt"] == "user"
    assert os.path.getsize(str(out).replace(".h5", ".png")) > 10000
    p = subprocess.run([sys.executable, "-m", "petsc_ssi", "post", str(out), "--receivers", "--csv"],
                       capture_output=True, text=True, cwd=ROOT, check=True)
    lines = p.stdout.strip().splitlines()
    assert lines[0] == "receiver,x_m,y_m,z_m,t_s,ux_m,uy_m,uz_m"      # (each column's unit in its name)
    assert len(lines) == 1 + 2 * 4
    row = lines[-1].split(",")
    assert row[0] == "1" and float(row[1]) == 3.0 and float(row[2]) == 1.0 and np.isclose(float(row[7]), d["u"][-1, 1, 2], rtol=1e-8)
    # the amplitude spectrum's columns and peaks carry the series' unit too
    spec = str(tmp_path / "spec.csv")
    p = subprocess.run([sys.executable, "-m", "petsc_ssi", "post", str(out), "--spectrum", "--component", "z",
                        "--csv", spec], capture_output=True, text=True, cwd=ROOT, check=True)
    assert "component,rank,f_hz,amplitude_m" in p.stdout.splitlines()
    body = [ln for ln in open(spec).read().splitlines() if not ln.startswith("#")]
    assert body[0] == "f_hz,u_z_m" and "# unit: the amplitudes in m" in open(spec).read()


def test_help_lists_every_option():
    p = subprocess.run([sys.executable, "-m", "petsc_ssi", "help"], capture_output=True, text=True,
                       cwd=ROOT, check=True)
    from petsc_ssi import options
    from petsc_ssi.app import kinds, estimate, impedance  # noqa: F401  (every option, as the CLI declares them)
    for name, opt in options.options().items():
        assert f"-ssi_{name} <{opt.default}>" in p.stdout
