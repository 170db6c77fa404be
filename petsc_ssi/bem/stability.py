"""Stability of the BEM time marching (issue 6).

* ``growth_rate`` / ``classify``: the late-time growth of the solution norm
  |u^n| (least-squares slope of ln|u^n| against the step number over the last
  third of a run) and the classification used by runs/stability and by
  ``-ssi_check_stability``:

    stable          rate <  RATE_SLOW      (< 10 % growth per 1000 steps)
    slowly growing  RATE_SLOW <= rate < RATE_UNSTABLE
    unstable        rate >= RATE_UNSTABLE  (> x7.4 per 1000 steps), a
                    non-finite norm, or a run stopped by the guard.

  A loaded half-space radiates energy away: under a Heaviside load |u| tends
  to the static value, under a pulse it decays, so any sustained growth is a
  numerical instability. Rates are per step (the marching is a recurrence in
  the step), not per second.
* ``guard_reference`` / ``guard_trips`` / ``guard_step``: the rule of the
  run-time guard (``-ssi_guard``): stop when |u^n| is not finite, or, after
  GUARD_MIN_STEPS steps, exceeds ``factor`` times the largest |u| of the first
  half of the run so far. ``guard_step`` applies the same rule to a whole
  recorded history (the study script uses it to show where the default guard
  would have stopped each run).
* ``surrogate`` / ``check_stability``: ``-ssi_check_stability``: the same
  material, time step, scheme and interpolation settings on a small quarter
  model with the element size of the real mesh (hence the same beta), a few
  hundred steps (at least 3 times the causal lag count of the surrogate, since
  the instabilities found in runs/stability set in only after the last
  causal lag has entered the recurrence), and a one-line verdict.
"""
import math
import os

import numpy as np

from ..petsc import SSIError, printf

from .stability_map import MAP_STABLE_FROM, MAP_BETA_MAX, beta_warning  # noqa: F401  (re-exported)

RATE_SLOW = 1e-4
RATE_UNSTABLE = 2e-3
FIT_FRACTION = 1.0 / 3.0
GUARD_MIN_STEPS = 20
CLASSES = ("stable", "slowly growing", "unstable")


def growth_rate(unorm, frac=FIT_FRACTION):
    """Least-squares slope of ln|u^n| per step over the last ``frac`` of the
    history (at least 5 steps); +inf if any norm is not finite."""
    u = np.asarray(unorm, dtype=float)
    if u.size == 0:
        raise SSIError("growth_rate: empty norm history")
    if not np.all(np.isfinite(u)):
        return float("inf")
    m = max(int(round(frac * u.size)), min(5, u.size))
    y = np.log(np.maximum(u[-m:], 1e-300))
    if m < 2:
        return 0.0
    s = np.arange(m, dtype=float)
    s -= s.mean()
    return float(np.dot(s, y - y.mean()) / np.dot(s, s))


def classify(unorm, stopped=False):
    """(class, rate): see the module header for the thresholds."""
    rate = growth_rate(unorm)
    if stopped or not np.isfinite(rate) or rate >= RATE_UNSTABLE:
        return "unstable", rate
    if rate >= RATE_SLOW:
        return "slowly growing", rate
    return "stable", rate


def thresholds_text():
    return (f"late growth rate r = d ln|u| / d step fitted over the last {FIT_FRACTION:.2g} of the run: "
            f"stable r < {RATE_SLOW:g}, slowly growing {RATE_SLOW:g} <= r < {RATE_UNSTABLE:g}, "
            f"unstable r >= {RATE_UNSTABLE:g} or blow-up")


def guard_reference(prefix_max, n):
    """The guard's reference at step n (1-based): the largest |u| of steps 1..n//2."""
    return prefix_max[n // 2 - 1] if n >= 2 else 0.0


def guard_trips(nrm, ref, n, factor):
    """True when the guard stops the run at step n."""
    if not np.isfinite(nrm):
        return True
    return n >= GUARD_MIN_STEPS and nrm > factor * max(ref, 1e-300)


def guard_step(unorm, factor):
    """The first step (1-based) at which the guard rule with ``factor`` stops
    the recorded history ``unorm``, or None (vectorised form of guard_trips)."""
    u = np.asarray(unorm, dtype=float)
    if u.size == 0:
        return None
    fin = np.isfinite(u)
    pm = np.maximum.accumulate(np.where(fin, u, np.inf))
    n = np.arange(1, u.size + 1)
    ref = np.where(n >= 2, pm[np.maximum(n // 2 - 1, 0)], 0.0)
    trip = ~fin | ((n >= GUARD_MIN_STEPS) & (u > factor * np.maximum(ref, 1e-300)))
    hit = np.flatnonzero(trip)
    return int(hit[0]) + 1 if hit.size else None


# ------------------------------------------------------------ -ssi_check_stability
SURROGATE_ELEMENTS = 3      # elements per side of the surrogate quarter model


def surrogate(cfg, prob, h):
    """Options of the coarse surrogate of ``cfg`` with element size ``h``:
    a quarter model (two symmetry planes) of SURROGATE_ELEMENTS x
    SURROGATE_ELEMENTS elements, one loaded element (Heaviside, 1 kPa), the
    same material, dt, scheme and interpolation (an automatic T_L and k are
    taken from the real problem's plan), no output fields, no receivers."""
    from ..options import Config
    vals = dict(cfg.as_dict())
    size = 2 * SURROGATE_ELEMENTS * h
    vals.update(mesh="grid", mesh_size=f"{size:.12g},{size:.12g}", mesh_h=h, mesh_patch=f"{h:.12g},{h:.12g}",
                symmetry="x=sym,y=sym", load_group="load", load_area="", load_p0=1000.0, load_history="heaviside",
                disp_group="", receivers="", output_stride=0, plot=False, warn_beta=False,
                check_stability=False, guard=True, guard_factor=cfg.guard_factor)
    if cfg.interp == "auto":
        plan = prob.interp_plan()
        vals.update(interp=plan.method if plan.active else "none", interp_tl=plan.TL or 0.0, interp_k=plan.k)
    r_max = math.sqrt(2.0) * size
    lags = int(math.floor(r_max / (cfg.cs * cfg.dt))) + 2
    steps = max(cfg.check_stability_steps, 3 * lags)
    vals.update(t_end=steps * cfg.dt)
    src = dict(cfg.sources())
    for k in ("t_end", "interp", "interp_tl", "interp_k"):
        src[k] = "check_stability"
    return Config(vals, src), steps, lags


def check_stability(cfg, comm, run):
    """Collective: run the surrogate(s) of ``cfg`` with ``run(cfg2)`` (the BEM
    run without output) and print one verdict line per surrogate. The mesh's
    largest element gives the smallest beta = c_s dt / l (the side where the
    plain scheme fails); a non-uniform mesh (smallest element < 0.75 x the
    largest) is checked at its smallest element too. Returns a dict."""
    from .halfspace import HalfSpace
    prob = HalfSpace(cfg, comm, log=lambda m: None)
    sizes = prob.mesh.element_sizes()
    hs = [2.0 * float(sizes.max())]
    if sizes.min() < 0.75 * sizes.max():
        hs.append(2.0 * float(sizes.min()))
    out = {"checks": []}
    worst = 0
    for h in hs:
        c2, steps, lags = surrogate(cfg, prob, h)
        c2.set("output", _scratch(cfg.output, comm))
        stopped, msg = False, ""
        try:
            res = run(c2)
            un = res["unorm"]
        except SSIError as exc:
            if not hasattr(exc, "unorm"):
                raise
            stopped, msg, un = True, str(exc), exc.unorm
        finally:
            _cleanup(c2.output, comm)
        cls, rate = classify(un, stopped)
        worst = max(worst, CLASSES.index(cls))
        beta = cfg.cs * cfg.dt / (h / 2)
        line = (f"[ssi] stability check: {cls.upper()}: surrogate quarter model of {SURROGATE_ELEMENTS}x"
                f"{SURROGATE_ELEMENTS} elements of {h:.4g} m (beta = c_s dt / l = {beta:.3g}, l = h/2 the "
                f"node spacing), scheme {cfg.scheme}, interp {c2.interp}, {len(un)}/{steps} steps "
                f"({lags} causal lags): late growth rate {rate:.3g} per step")
        if stopped:
            line += f"; stopped by the guard at step {len(un)}"
        printf(line)
        if msg:
            printf("[ssi] stability check: " + msg.split("; likely cause: ")[-1])
        out["checks"].append({"h": h, "beta": beta, "class": cls, "rate": rate, "steps": len(un),
                              "planned": steps, "stopped": stopped, "unorm": np.asarray(un)})
    out["verdict"] = CLASSES[worst]
    printf(f"[ssi] stability check verdict: {out['verdict']} ({thresholds_text()})")
    return out


def _scratch(path, comm):
    """Scratch output of the surrogate beside the real output (removed afterwards)."""
    return os.path.splitext(path)[0] + ".stability-check.h5"


def _cleanup(path, comm):
    comm.tompi4py().Barrier()
    if comm.getRank() == 0:
        from ..io.output import remove_output
        try:
            remove_output(path)
        except OSError:
            pass


def guard(cfg, prob, march, unorm, n):
    """Stop a clearly diverging run (same decision on every rank: the norm is
    a global reduction). Diverging: a non-finite norm, or after 20 steps a
    norm above guard_factor times the largest norm of the first half of the
    run so far. A loaded, damped (radiating) half-space cannot do that."""
    nrm = unorm[-1]
    pm = march.norm_prefix_max                             # running max of |u|: O(1) per step
    pm.append(max(pm[-1], nrm) if pm else nrm)
    ref = guard_reference(pm, n)
    if not guard_trips(nrm, ref, n, cfg.guard_factor):
        return
    rate = (np.log(nrm / ref) / (n - n // 2)) if (np.isfinite(nrm) and ref > 0) else float("inf")
    causes = []
    if march.scheme == "plain":
        causes.append(f"the plain scheme (eq. 6) is unstable for small beta = c_s dt / l (here {prob.beta[0]:.3g}; "
                      "runs/stability/README.md maps where): use -ssi_scheme stabilized")
    beta = beta_warning(march.scheme, prob.beta[0], prob.beta[1] * prob.mat.cs / prob.mat.cp)
    if beta:
        causes.append(beta.split(": the marching")[0] + ": change -ssi_dt or the mesh")
    plan = getattr(march, "plan", None)
    if plan is not None:
        causes.append(f"lag interpolation from T_L = {plan.TL:.4g} s: a threshold below the Rayleigh "
                      "arrival (tau_L < 1.09) is inaccurate; raise -ssi_interp_tl")
    if not causes:
        causes.append("unknown (check the mesh and dt; -ssi_guard 0 disables this check)")
    exc = SSIError(f"the solution is diverging at step {n} (t = {n * prob.dt:.4g} s): |u| = {nrm:.3e}, "
                   f"{nrm / ref if ref > 0 else float('inf'):.3g} x the largest norm of the first half, growth "
                   f"rate {rate:.3g} per step; likely cause: {'; '.join(causes)}")
    exc.unorm = np.array(unorm)      # the history so far (-ssi_check_stability, runs/stability)
    raise exc


class DivergenceGuard:
    """An observer of the recorder (``io.recorder`` protocol): after each step is recorded, stop
    a clearly diverging run (``guard``) with the |u| history of ``norms`` (``NormHistory``).

    Under a seismic input (the half-space's ``seismic``) only a non-finite norm stops the run: the
    growth rule compares |u| with the first half of the run, but the scattered field grows from
    zero as the wave arrives (a wave starting late, or an oblique one, trips it in a stable run)."""

    def __init__(self, cfg, prob, march, norms):
        self.cfg, self.prob, self.march, self.norms = cfg, prob, march, norms
        self.growth = getattr(prob, "seismic", None) is None

    def observe(self, n, t, step):
        if self.growth:
            guard(self.cfg, self.prob, self.march, self.norms.values, n)
            return
        nrm = self.norms.values[-1]
        if not np.isfinite(nrm):
            raise SSIError(f"the solution is not finite at step {n} (t = {t:.4g} s): |u| = {nrm}; likely cause: "
                           f"beta_s = c_s dt / l from {self.prob.beta[0]:.2f} (the stability map's stable range "
                           f"for -ssi_scheme {self.cfg.scheme}: from {MAP_STABLE_FROM.get(self.cfg.scheme, 0):g} to "
                           f"{MAP_BETA_MAX:g}) or the scheme")
