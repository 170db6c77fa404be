"""-ssi_huge_pages: numpy's transparent-huge-page advice for large arrays is a memory setting only
(jobscripts/first_touch.py and huge_pages_bench.sh measure what it costs): the switch takes effect,
a bad value is refused, and a run gives the same bits with it on and off."""
import json

import numpy as np
import pytest

from helpers import cli, read_h5


def test_the_switch_takes_effect_and_refuses_bad_values():
    from petsc_ssi.petsc import set_huge_pages, SSIError
    before = set_huge_pages("numpy")            # numpy's state now, unchanged
    if before is None:
        pytest.skip("this numpy has no huge-page switch")
    try:
        assert set_huge_pages("off") is False
        assert set_huge_pages("numpy") is False  # 'numpy' leaves the state as it is
        assert set_huge_pages("on") is True
        assert set_huge_pages("numpy") is True
        with pytest.raises(SSIError, match="-ssi_huge_pages maybe: expected off, on or numpy"):
            set_huge_pages("maybe")
    finally:
        set_huge_pages("on" if before else "off")


RUN = ["-ssi_problem", "bem", "-ssi_mesh_size", "12,12", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
       "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.0025", "-ssi_t_end", "0.05",
       "-ssi_receivers", "2,0,0", "-ssi_output_stride", "5", "-ssi_warn_beta", "0"]


def test_a_run_is_the_same_with_huge_pages_on_and_off(tmp_path):
    """625 soil nodes, 21 lags: lag block arrays of several MB, over numpy's 4 MB threshold."""
    out = {}
    for mode in ("off", "on"):
        path = str(tmp_path / f"{mode}.h5")
        cli(RUN + ["-ssi_output", path, "-ssi_huge_pages", mode])
        out[mode] = read_h5(path)
        with open(str(tmp_path / f"{mode}.json")) as fh:
            assert json.load(fh)["options"]["huge_pages"] == mode
    assert np.abs(out["off"]["u"]).max() > 0
    assert np.array_equal(out["off"]["u"], out["on"]["u"])
    assert np.array_equal(out["off"]["last"], out["on"]["last"])


def test_a_bad_value_is_refused_in_one_line_before_the_run(tmp_path):
    p = cli(RUN + ["-ssi_output", str(tmp_path / "x.h5"), "-ssi_huge_pages", "maybe"], nranks=2, check=False)
    assert p.returncode != 0
    lines = [ln for ln in (p.stdout + p.stderr).splitlines() if "huge_pages" in ln]
    assert len(lines) == 1 and "'maybe' is not one of off|on|numpy" in lines[0], p.stdout + p.stderr
    assert "[ssi] BEM:" not in p.stdout and not (tmp_path / "x.h5").exists()
