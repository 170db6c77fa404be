"""-ssi_huge_pages: transparent huge pages for large arrays are a memory setting only
(jobscripts/first_touch.py, first_touch_pair.py, paper_repeat.sh and huge_pages_bench.sh measure what
they cost): the switch takes effect, 'auto' gives the lag arrays small pages exactly where the
machine's balloon reports free pages to its host (read from a sysfs tree made here), a bad value is
refused, and a run gives the same bits with every setting."""
import json

import numpy as np
import pytest

from helpers import cli, read_h5

pytestmark = pytest.mark.mpi


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
        assert set_huge_pages("auto") is True    # 'auto' too (the lag arrays decide apart)
        with pytest.raises(SSIError, match="-ssi_huge_pages maybe: expected auto, off, on or numpy"):
            set_huge_pages("maybe")
    finally:
        set_huge_pages("on" if before else "off")


def _virtio(root, name, device, features):
    d = root / name
    d.mkdir(parents=True)
    (d / "device").write_text(device + "\n")
    (d / "features").write_text(features + "\n")


def test_auto_gives_the_lag_arrays_small_pages_only_where_a_balloon_reports_free_pages(tmp_path, monkeypatch):
    """sysmem.free_page_reporting reads bit 5 (VIRTIO_BALLOON_F_REPORTING) of a virtio balloon's
    (device 0x0005) negotiated features; another device with that bit, a balloon without it, a
    missing tree and unreadable entries do not count. petsc.lag_small_pages: 'auto' follows it,
    'off' is small, 'on' and 'numpy' are not."""
    from petsc_ssi import sysmem
    from petsc_ssi.petsc import lag_small_pages
    f = sysmem.free_page_reporting
    assert f(str(tmp_path / "none")) is False
    root = tmp_path / "devices"
    _virtio(root, "virtio0", "0x0001", "0000010" + "0" * 57)        # a network device with bit 5
    _virtio(root, "virtio1", "0x0005", "0110000" + "0" * 57)        # a balloon: stats, deflate, no reporting
    (root / "virtio2").mkdir()                                      # an entry without files
    assert f(str(root)) is False
    _virtio(root, "virtio3", "0x0005", "0110010" + "0" * 57)        # a balloon that reports free pages
    assert f(str(root)) is True
    for reporting in (True, False):
        monkeypatch.setattr(sysmem, "free_page_reporting", lambda: reporting)
        assert lag_small_pages("auto") is reporting
        assert lag_small_pages("off") is True
        assert lag_small_pages("on") is False and lag_small_pages("numpy") is False


RUN = ["-ssi_problem", "bem", "-ssi_mesh_size", "12,12", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1",
       "-ssi_load_group", "load", "-ssi_load_p0", "1000", "-ssi_dt", "0.0025", "-ssi_t_end", "0.05",
       "-ssi_receivers", "2,0,0", "-ssi_output_stride", "5", "-ssi_warn_beta", "0"]


def test_a_run_is_the_same_with_huge_pages_on_and_off(tmp_path):
    """625 soil nodes, 21 lags: lag block arrays of several MB, over numpy's 4 MB threshold."""
    out = {}
    for mode in ("off", "on", "auto"):
        path = str(tmp_path / f"{mode}.h5")
        cli(RUN + ["-ssi_output", path, "-ssi_huge_pages", mode])
        out[mode] = read_h5(path)
        with open(str(tmp_path / f"{mode}.json")) as fh:
            assert json.load(fh)["options"]["huge_pages"] == mode
    assert np.abs(out["off"]["u"]).max() > 0
    assert np.array_equal(out["off"]["u"], out["on"]["u"])
    assert np.array_equal(out["off"]["last"], out["on"]["last"])
    assert np.array_equal(out["auto"]["u"], out["on"]["u"])


def test_a_bad_value_is_refused_in_one_line_before_the_run(tmp_path):
    p = cli(RUN + ["-ssi_output", str(tmp_path / "x.h5"), "-ssi_huge_pages", "maybe"], nranks=2, check=False)
    assert p.returncode != 0
    lines = [ln for ln in (p.stdout + p.stderr).splitlines() if "huge_pages" in ln]
    assert len(lines) == 1 and "'maybe' is not one of auto|off|on|numpy" in lines[0], p.stdout + p.stderr
    assert "[ssi] BEM:" not in p.stdout and not (tmp_path / "x.h5").exists()
