"""The beta warning comes from the stability map (issue 30, item 3): its thresholds are what
runs/stability/stability_map.csv found, the project's own cases (the demo's building, the half
building, the paper's foundation) do not trigger it, and edge diffraction is one
line naming the earliest arrival and every receiver it reaches."""
import csv
import os

import pytest

from helpers import ROOT, cli

pytestmark = pytest.mark.run


def test_thresholds_are_the_maps():
    from petsc_ssi.bem.stability import MAP_STABLE_FROM, MAP_BETA_MAX
    rows = list(csv.DictReader(open(os.path.join(ROOT, "runs", "stability", "stability_map.csv"))))
    rows = [r for r in rows if r["part"] == "map"]
    for scheme, expect in MAP_STABLE_FROM.items():
        worst = 0.0
        for h in sorted({r["h"] for r in rows if r["scheme"] == scheme}):
            runs = sorted((float(r["beta"]), r["class"]) for r in rows if r["scheme"] == scheme and r["h"] == h)
            bad = [b for b, c in runs if c != "stable"]
            stable_from = min(b for b, c in runs if not bad or b > max(bad))   # every run from here on stable
            worst = max(worst, stable_from)
        assert worst == expect, (scheme, worst)
    top = max(float(r["beta"]) for r in rows)
    assert top == MAP_BETA_MAX and all(r["class"] == "stable" for r in rows if float(r["beta"]) == top)


def test_beta_warning_follows_the_scheme():
    from petsc_ssi.bem.stability import beta_warning
    assert beta_warning("stabilized", 0.1, 1.9) is None and beta_warning("plain", 0.2, 2.0) is None
    msg = beta_warning("plain", 0.1, 1.0)
    assert "below 0.15, from which every plain run" in msg and "-ssi_scheme stabilized from 0.07" in msg
    assert "above 2" in beta_warning("stabilized", 0.5, 2.5) and "\n" not in msg


@pytest.mark.parametrize("opts", ["runs/building/demo.opts", "runs/building/ssi-half-bonded.opts",
                                  "runs/foundation/sym-bonded.opts"])
def test_shipped_cases_do_not_warn_about_beta(opts):
    """Before: 'beta ... outside [0.3, 1.3]: the time marching may be inaccurate or unstable' on the
    demo's building (c_s dt / l from 0.366 to 2.0: inside the map's stable range)."""
    p = cli(["estimate", "-options_file", opts])
    assert "beta" not in "\n".join(ln for ln in p.stdout.splitlines() if "warning" in ln), p.stdout[-3000:]


def test_diffraction_is_one_line(tmp_path):
    """The demo's building stops at the memory check (after the set-up's warnings): one line with
    the earliest arrival and every receiver and the structure; before, one line each. The earliest:
    receiver 1 at x = 6 m, path from the load's far side (x = 8 + 0.5 m) to the edge x = 12 m and
    back, 3.5 + 6 m at c_p = 208 m/s."""
    t = (3.5 + 6.0) / 208.0
    p = cli(["-options_file", "runs/building/demo.opts", "-ssi_memory_limit", "0.001",
             "-ssi_output", str(tmp_path / "d.h5")], check=False)
    lines = [ln for ln in p.stdout.splitlines() if "diffracted" in ln]
    assert p.returncode == 2 and len(lines) == 1, p.stdout[-3000:]
    assert f"the earliest at t = {t:.4g} s" in lines[0] and f"receiver 1 (6, 0, 0) (t = {t:.4g} s)" in lines[0]
    assert all(f"receiver {k}" in lines[0] for k in range(3)) and "the structure" in lines[0]
