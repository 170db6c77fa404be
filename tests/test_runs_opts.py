"""Every options file under runs/ runs at a reduced size, so the examples
cannot drift from the code (Firedrake's demo guard). Each run must finish
and produce an output with finite receiver values (an impedance case, whose file names the
`petsc-ssi impedance` command: a finite impedance table)."""
import glob
import os
import re

import numpy as np
import pytest

from helpers import ROOT, cli, read_h5

pytestmark = pytest.mark.run

OPTS = sorted(glob.glob(os.path.join(ROOT, "runs", "**", "*.opts"), recursive=True))
# the slow tier (make test-slow): each over a minute; a smaller sibling of each stays in make test
SLOW = {
    # the full building's files: the half building's and the CI building stay
    "runs/building/ssi-common.opts", "runs/building/ssi-half-common.opts",
    "runs/building/ssi-full-bonded-ny4.opts", "runs/building/ssi-full-bonded-released.opts",
    "runs/building/ssi-full-unilateral.opts", "runs/building/ssi-full-bonded.opts",
    # the disk's and the rectangle's impedances: the square's stays
    "runs/impedance/disk.opts", "runs/impedance/rectangle.opts",
    # the antisymmetric foundation cases: anti-unilateral and the symmetric ones stay; the symmetric bonded
    # case: the symmetric unilateral and bonded-staggered ones stay
    "runs/foundation/anti-bonded.opts", "runs/foundation/anti-unilateral-cohesive.opts",
    "runs/foundation/sym-bonded.opts",
    # the half building bonded: the half building unilateral (the same mesh and soil) stays
    "runs/building/ssi-half-bonded.opts",
    # the paper's building under a record: the half building's file (same mesh) and the seismic building stay
    "runs/seismic/paper-building.opts",
    # the building on a basement (the pit's BEM assembly, half a minute): runs/basement/surface.opts stays
    "runs/basement/basement.opts",
    # the 28.8 m building on a large site under an oblique wave (5439 interface columns even on the reduced grid):
    # runs/seismic/building-oblique.opts (an oblique SV wave) and the uniform-grid building tests
    # (tests/coupling/test_region_columns.py) stay
    "runs/seismic/site-oblique.opts",
}
# a grid generator's reduced size where 8 m x 8 m cannot hold the structure (one cell beyond the slab each side)
REDUCED_SIZE = {"runs/seismic/site-oblique.opts": "31.2,24"}
PARAMS = [pytest.param(p, id=os.path.relpath(p, ROOT),
                       marks=[pytest.mark.slow] if os.path.relpath(p, ROOT) in SLOW else [])
          for p in OPTS]


def _value(text, name, default=None):
    m = re.search(rf"^-ssi_{name}\s+(\S+)", text, re.M)
    return m.group(1) if m else default


def _read(path):
    """The file's text with nested -options_file lines expanded (outer lines first)."""
    text = open(path).read()
    for m in re.finditer(r"^-options_file\s+(\S+)", text, re.M):
        text += "\n" + _read(os.path.join(ROOT, m.group(1)))
    return text


@pytest.mark.parametrize("path", PARAMS)
def test_options_file_runs_reduced(path, tmp_path):
    text = _read(path)
    problem = _value(text, "problem", "bem")
    dt = float(_value(text, "dt", "7.5e-4"))
    out = tmp_path / "run.h5"
    args = ["-options_file", os.path.relpath(path, ROOT), "-ssi_t_end", repr(3 * dt),
            "-ssi_output", str(out)]
    if problem in ("bem", "ssi") and _value(text, "mesh", "grid") == "grid":
        args += ["-ssi_mesh_size", REDUCED_SIZE.get(os.path.relpath(path, ROOT), "8,8")]
        if _value(text, "receivers"):
            args += ["-ssi_receivers", "2,0,0"]
    if _value(text, "seismic") and not _value(text, "seismic_record"):   # the record comes on the command line
        obspy = pytest.importorskip("obspy")
        args += ["-ssi_seismic_record", os.path.join(os.path.dirname(obspy.__file__), "io", "nied", "tests", "data",
                                                     "test.knet")]
    if "petsc-ssi impedance" in text:          # an impedance case: the command, one mode, a few steps
        cli(["impedance"] + args + ["-ssi_t_end", repr(20 * dt), "-ssi_impedance_modes", "vertical",
                                    "-ssi_output_overwrite"])
        import csv
        rows = list(csv.DictReader(open(str(tmp_path / "run-impedance.csv"))))
        k = np.array([float(r["K_re"]) for r in rows])
        assert len(rows) > 10 and np.all(np.isfinite(k)) and abs(float(rows[0]["K0"])) > 0
        return
    cli(args)
    d = read_h5(out)
    assert d["u"].shape[0] in (3, 4) and np.all(np.isfinite(d["u"]))
    if _value(text, "seismic", "none") not in ("none", "vertical"):
        # an oblique wave reaches the receivers later than these few steps (the automatic start keeps
        # the free field zero at every soil node up to t = 0): the input itself must be there
        import h5py
        with h5py.File(out, "r") as f:
            assert np.abs(f["seismic/acceleration"][()]).max() > 0
        return
    assert np.abs(d["u"]).max() > 0
