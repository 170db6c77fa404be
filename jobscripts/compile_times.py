#!/usr/bin/env python3
"""Where numba's compile time goes, on an empty cache: the warm-up's first two runs (the block-sparse lag store's
tiny BEM case, then the same on the toeplitz store) in a fresh NUMBA_CACHE_DIR, one process, with numba's own
compile events counted (``numba:compile``: each kernel's seconds less its callees', the versions compiled).

    python jobscripts/compile_times.py [-top N]
    PYTHONPATH=<another checkout> python jobscripts/compile_times.py   # the same runs on other code

Prints per run its seconds and the kernel versions it compiled, then the N kernels (default 15) whose own compile
took longest and every kernel compiled in more than one version (with its versions' signatures). The runs are
petsc_ssi.app.warmup's first two (the same options), so the numbers compare across versions of the sources.

    python jobscripts/compile_times.py --since-warmup

instead lists the kernel versions this checkout's cache received after its warm-up finished (the ``.nbc`` files newer
than the warm-up's mark): what a run or a test compiled that the warm-up does not.
"""
import collections
import contextlib
import io
import os
import sys
import tempfile
import time


def since_warmup():
    import petsc_ssi
    d = os.environ["NUMBA_CACHE_DIR"]
    mark = os.path.join(d, f"warmup-done-{petsc_ssi.checkout_key()}")
    if not os.path.exists(mark):
        print(f"no warm-up mark for this checkout in {d}")
        return 1
    t0 = os.stat(mark).st_mtime
    new = sorted((os.stat(os.path.join(r, f)).st_mtime, os.path.relpath(os.path.join(r, f), d))
                 for r, _, fs in os.walk(d) for f in fs if f.endswith(".nbc") and os.stat(os.path.join(r, f)).st_mtime > t0)
    print(f"{len(new)} kernel version(s) compiled into {d} after the warm-up of this checkout "
          f"({time.strftime('%H:%M:%S', time.localtime(t0))}):")
    for t, p in new:
        print(f"  {time.strftime('%H:%M:%S', time.localtime(t))}  {p}")
    return 0


def main(argv):
    if "--since-warmup" in argv:
        return since_warmup()             # (its import of petsc_ssi points NUMBA_CACHE_DIR at this checkout's cache)
    top = int(argv[argv.index("-top") + 1]) if "-top" in argv else 15
    cache = tempfile.mkdtemp(prefix="numba-cold-")
    os.environ["NUMBA_CACHE_DIR"] = cache          # before petsc_ssi: an empty cache
    os.environ["PETSC_SSI_WARMUP"] = "1"
    from numba.core import event
    stack, own, versions = [], collections.defaultdict(float), collections.defaultdict(list)

    class Listener(event.Listener):
        def on_start(self, ev):
            stack.append([ev.data["dispatcher"].py_func.__qualname__, time.perf_counter(), 0.0])

        def on_end(self, ev):
            name, t0, inner = stack.pop()
            dt = time.perf_counter() - t0
            own[name] += dt - inner
            versions[name].append(str(ev.data.get("args", "")))
            if stack:
                stack[-1][2] += dt

    event.register("numba:compile", Listener())
    import petsc_ssi
    print(f"petsc_ssi from {os.path.dirname(petsc_ssi.__file__)}, an empty cache {cache}", flush=True)
    from petsc_ssi.petsc import init
    PETSc = init([sys.argv[0]])
    from petsc_ssi import options
    from petsc_ssi.app.kinds import run_bem
    try:
        from petsc_ssi.app.warmup import RUN_OPTS
    except ImportError:                   # (an older checkout: its warm-up's first run had these options)
        RUN_OPTS = {"problem": "bem", "mesh_size": "4,4", "mesh_h": 1.0, "mesh_patch": "1,1", "load_group": "load",
                    "load_p0": 1000, "dt": 0.005, "t_end": 0.02, "output_stride": 0, "warn_beta": 0,
                    "output_overwrite": 1, "lag_storage": "sparse", "history_block": 2}
    db = PETSc.Options()
    with tempfile.TemporaryDirectory() as tmp:
        opts = dict(RUN_OPTS, output=os.path.join(tmp, "w.h5"))
        for k, v in opts.items():
            db.setValue("ssi_" + k, str(v))
        for label, store in (("block-sparse lag store", None), ("toeplitz lag store", "toeplitz")):
            if store:
                db.setValue("ssi_lag_store", store)
            n0, t0 = sum(map(len, versions.values())), time.perf_counter()
            with contextlib.redirect_stdout(io.StringIO()):
                run_bem(options.resolve(("common", "bem")))
            print(f"run on the {label}: {time.perf_counter() - t0:.1f} s, "
                  f"{sum(map(len, versions.values())) - n0} kernel versions compiled")
    print(f"compile time, each kernel's own (its callees' taken out), in all: {sum(own.values()):.1f} s; the longest:")
    for name, s in sorted(own.items(), key=lambda kv: -kv[1])[:top]:
        print(f"  {s:6.2f} s  {name} ({len(versions[name])} version(s))")
    twice = {k: v for k, v in versions.items() if len(v) > 1}
    print(f"kernels compiled in more than one version: {len(twice)}")
    for name, sigs in sorted(twice.items()):
        print(f"  {name}: {len(sigs)}")
        for s in sigs:
            print(f"      {s[:300]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
