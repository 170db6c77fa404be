"""Observers own their output groups (issue 40, item 2; ``io.recorder``): each observer says the groups
it writes (``groups(steps, times)``) and the recorder hands a problem the groups of one of its outputs
(``Recorder.groups(out)``): the observer's own ``out``, or the one given to ``add``/``add_recorder``;
the interface series' go to the soil's output; a group None (a rank without it) is left out; the
step clock writes 'timing' only when asked. The whole runs' outputs are the refactor cases'
(jobscripts/refactor_cases.sh, bit for bit) and the problems' tests."""
from types import SimpleNamespace

import numpy as np
import pytest

from petsc_ssi.io.recorder import Recorder, InterfaceSeries, StepClock

pytestmark = pytest.mark.unit


class _Grid:
    n_steps = 3

    def writes(self, n):
        return False


class _Observer:
    """An observer with an output of its own (``out``) or none, that counts its steps."""

    def __init__(self, name, out=None, none=False):
        self.name, self.none, self.seen = name, none, []
        if out is not None:
            self.out = out

    def observe(self, n, t, step):
        self.seen.append(n)

    def groups(self, steps, times):
        if self.none:
            return {self.name: None}
        return {self.name: {"t": (np.asarray(times, float), "s"), "n": np.asarray(steps)}}


def _recorder(**kw):
    cfg = SimpleNamespace(monitor=False, monitor_every=0)
    return Recorder(cfg, None, "test loop", _Grid(), **kw)


def test_each_output_gets_the_groups_of_its_observers():
    soil_out, structure_out = object(), object()
    soil = _Observer("receivers", out=soil_out)
    structure = _Observer("structure_receivers", out=structure_out)
    rec = _recorder(soil=soil, structure=structure, interface_keys=("force",))
    extra = rec.add(_Observer("demands"), out=structure_out)          # no ``out`` of its own
    rec.add_recorder(_Observer("resultants", out=soil_out, none=True))   # a rank without the group
    clock = rec.add(StepClock(), out=soil_out)                         # timing not asked for
    loose = rec.add(_Observer("nowhere"))                              # no output: in no file
    for n in (1, 2, 3):
        rec.step(n, 0.1 * n, interface={"force": float(n)})
    g = rec.groups(soil_out)
    assert set(g) == {"receivers", "interface"}
    assert np.array_equal(g["receivers"]["n"], [1, 2, 3])
    assert np.array_equal(g["receivers"]["t"][0], [0.1, 0.2, 0.30000000000000004])
    assert np.array_equal(g["interface"]["force"], [1.0, 2.0, 3.0])
    assert np.array_equal(g["interface"]["t"], rec.times)
    s = rec.groups(structure_out)
    assert set(s) == {"structure_receivers", "demands"}
    assert extra.seen == loose.seen == [1, 2, 3] and clock.group is False
    assert rec.output_of(loose) is None and rec.output_of(extra) is structure_out


def test_the_step_clock_writes_its_times_when_asked():
    out = object()
    rec = _recorder()
    clock = rec.add(StepClock(group=True), out=out)
    clock.start()
    for n in (1, 2):
        rec.step(n, float(n))
    g = rec.groups(out)
    wall, unit = g["timing"]["step_wall"]
    assert unit == "s" and wall.shape == (2,) and np.all(wall >= 0)


def test_a_subclass_lays_out_the_interface_group():
    class Laid(InterfaceSeries):
        def groups(self, steps, times):
            a = self.arrays()
            return {"interface": {"u": a["u"].reshape(len(a["nodal_steps"]), -1, 3), "t": np.asarray(times)}}

    out = object()
    series = Laid(("u",), nodal=("u",), stride=2)
    rec = _recorder(soil=_Observer("receivers", out=out), interface=series)
    assert rec.interface is series
    for n in (1, 2, 3, 4):
        rec.step(n, float(n), interface={"u": np.full(6, float(n))})
    g = rec.groups(out)["interface"]
    assert g["u"].shape == (2, 2, 3) and np.array_equal(g["u"][:, 0, 0], [2.0, 4.0])     # steps 2 and 4
