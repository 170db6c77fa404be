"""The progress line warns when the steps run far above the run's own prediction (issue 43: 'an
estimate you can trust'; issue 44: '-n 2 slower than -n 1 on shared cores with no word'):
``monitor.slow_warning`` names the cause it can see (ranks above the cores, a load average above
them, else the model's constants) and what to try; ``Progress.expect`` warns once, on rank 0, from
the -ssi_monitor line. No timing of the machine: the measured times are given."""
import pytest

from petsc_ssi import monitor

pytestmark = pytest.mark.unit
monitor.compile_seconds()   # numba imported (its event clock bound) before a test replaces time.perf_counter


def test_no_warning_within_the_factor_or_too_early():
    assert monitor.slow_warning(2.9 * 10, 10.0, 50, 1, load=0.1, cores=2) is None       # under SLOW x
    assert monitor.slow_warning(1.5, 0.01, 50, 1, load=9.0, cores=2) is None            # start-up noise
    assert monitor.slow_warning(100.0, 1.0, 3, 1, load=9.0, cores=2) is None            # too few steps


@pytest.mark.parametrize("ranks, load, words", [
    (4, 0.5, ["4 ranks share 2 cores (oversubscribed)", "mpirun -n"]),
    (2, 10.0, ["load average 10.0 on 2 cores", "-n 1 may then be the faster"]),
    (1, 0.2, ["not visibly loaded", "jobscripts/calibrate.py", "-ssi_estimate_constants"])])
def test_warning_names_the_cause_and_what_to_try(ranks, load, words):
    msg = monitor.slow_warning(40.0, 10.0, 100, ranks, load=load, cores=2)
    assert msg is not None and "4.0 times slower" in msg and "\n" not in msg
    for w in words:
        assert w in msg, msg


def test_progress_warns_once_against_its_model(monkeypatch, capfd):
    """A Progress whose model predicts 1 ms a step, measured at 10 s a step (a clock that advances
    10 s per call): the first due report warns, later ones do not repeat it."""
    clock = iter(range(0, 10_000, 10))
    monkeypatch.setattr(monitor.time, "perf_counter", lambda: float(next(clock)))
    p = monitor.Progress("time loop", 40, every=10)
    p.expect(lambda k: 1e-3 * k, ranks_here=1)
    for k in range(1, 41):
        p.update(k)
    out = capfd.readouterr().out
    assert out.count("times slower than the run's prediction") == 1
    assert "for 10 steps" in out


def test_the_eta_follows_the_model_at_the_measured_pace(monkeypatch, capfd):
    """With a model the progress line's eta is the model's remaining time scaled by the measured pace: a
    history sum whose step k costs k (the lags in use grow), measured at 10 s for each unit of the model, has
    10 x (sum 21..40 of k) = 6100 s to go after step 20, where a straight line from the steps done (2100 s for
    20) says 2100 s; the pace is that of the steps since the last report (a one-time cost before them left out);
    without a model the straight line stays. A toeplitz run's warning names its own fit (``fit``)."""
    import re
    model = lambda k: 0.5 * k * (k + 1)                     # step k costs k
    for with_model in (True, False):
        t = {"now": 0.0}
        monkeypatch.setattr(monitor.time, "perf_counter", lambda: t["now"])
        p = monitor.Progress("time loop", 40, every=20)
        if with_model:
            p.expect(model, ranks_here=1)
        for k in range(1, 41):
            t["now"] = 10.0 * model(k)
            p.update(k)
        etas = re.findall(r"step 20/40 .* eta (\S+)", capfd.readouterr().out)
        assert etas == (["1h41m"] if with_model else ["35m00s"]), etas         # 6100 s; 2100 s
    # a one-time cost in the first steps (1000 s before step 1): the eta after the second report is the pace of
    # the steps since the first (10 s a unit), not diluted by it: 10 x (820 - 465) = 3550 s after step 30
    t = {"now": 0.0}
    p = monitor.Progress("time loop", 40, every=10)
    p.expect(model, ranks_here=1)
    for k in range(1, 41):
        t["now"] = 1000.0 + 10.0 * model(k)
        p.update(k)
    etas = re.findall(r"step 30/40 .* eta (\S+)", capfd.readouterr().out)
    assert etas == ["59m10s"], etas
    msg = monitor.slow_warning(40.0, 10.0, 100, 1, load=0.2, cores=2, fit="jobscripts/toeplitz_fit.py")
    assert "jobscripts/toeplitz_fit.py" in msg and "calibrate.py" not in msg


def test_the_warning_comes_without_monitor_too(monkeypatch, capfd):
    """Issue 44: `-n 2` ran 3-10 times slower than `-n 1` on shared cores with no word when -ssi_monitor was
    off: the progress line stays off, the warning (once) does not."""
    clock = iter(range(0, 10_000, 10))
    monkeypatch.setattr(monitor.time, "perf_counter", lambda: float(next(clock)))
    p = monitor.Progress("time loop", 40, enabled=False, every=10)
    p.expect(lambda k: 1e-3 * k, ranks_here=1)
    for k in range(1, 41):
        p.update(k)
    out = capfd.readouterr().out
    assert out.count("times slower than the run's prediction") == 1 and "time loop: step" not in out
    q = monitor.Progress("time loop", 40, enabled=False, every=10)           # no model: nothing at all
    for k in range(1, 41):
        q.update(k)
    assert capfd.readouterr().out == ""


def _new_kernel(seed, loops=1):
    """A numba kernel no run has compiled (its source is new: the cache cannot hold it), of ``loops`` loops: its
    compile time grows with them (eight took a few times one's in a scratch timing on a machine where the
    suite took 10 min; one loop's compile fell to 0.0496 s there, under the test's 0.05 s floor, in the CI of
    61596ac)."""
    import numba
    body = "".join(f"    for i in range(x.size):\n        s += x[i] * {seed!r} + {j}.0 * x[i] ** {j % 3 + 1}\n"
                   for j in range(loops))
    ns = {}
    exec(f"def k(x):\n    s = 0.0\n{body}    return s", ns)
    return numba.njit(ns["k"])


def test_compiling_in_the_loop_is_not_slowness(monkeypatch, capfd):
    """A loop whose first item compiles a numba kernel (the first run of a version) and whose other items
    cost nothing: its model's 1 ms an item is met once the compile is left out (no warning), while the same
    loop with a sleep as long as that compile instead warns (the check sees time, not only compiles)."""
    import numpy as np
    monkeypatch.setattr(monitor, "SLOW_MIN_S", 0.0)
    x = np.ones(4)
    _new_kernel(0.5)(x)                 # numba itself started (a run's assembly does it before the loop)

    def loop(first_item):
        p = monitor.Progress("time loop", 20, enabled=False, every=1)
        p.expect(lambda k: 1e-3 * k, ranks_here=1)
        for k in range(1, 21):
            if k == 1:
                first_item()
            p.update(k)
        return capfd.readouterr().out

    kernel = _new_kernel(np.random.rand(), loops=8)     # a compile well above the 0.05 s floor and the model's 3 x 20 ms
    t0, c0 = monitor.time.perf_counter(), monitor.compile_seconds()
    out = loop(lambda: kernel(x))
    spent = monitor.compile_seconds() - c0
    assert spent > 0.05 and spent <= monitor.time.perf_counter() - t0, spent     # a compile, measured
    assert "times slower" not in out, out
    out = loop(lambda: monitor.time.sleep(spent))
    assert out.count("times slower than the run's prediction") == 1, out
