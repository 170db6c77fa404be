"""Where a toeplitz run's resident memory goes (issue 41's quarter case): a petsc_ssi run in this process
with this process's resident memory (VmRSS) and its peak (VmHWM, /proc/self/status) printed before and
after the BEM assemblies, the march's lag Mats, each side's toeplitz kernel build and its state maps, and at
the end ("#mem" lines, MiB). Under mpirun every rank prints its own lines.

    PYTHONPATH=. .venv/bin/python jobscripts/toeplitz_memory_phases.py -options_file runs/pekeris/paper.opts \\
        -ssi_lag_store toeplitz -ssi_output /tmp/q.h5 -ssi_output_overwrite
    (mpirun -n 2 ... the same, for the two ranks' split)

Warm the numba cache first (python -m petsc_ssi.app.warmup): a first run's peak is the compiler's.
"""
import functools
import os
import runpy
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def rss(tag):
    d = {}
    with open("/proc/self/status") as fh:
        for ln in fh:
            if ln.startswith(("VmRSS", "VmHWM")):
                k, v = ln.split(":")
                d[k] = int(v.split()[0]) // 1024
    print(f"#mem {tag}: RSS {d['VmRSS']} MiB, HWM {d['VmHWM']} MiB", flush=True)


def wrap(obj, name, label=None):
    f = getattr(obj, name)

    @functools.wraps(f)
    def g(*a, **k):
        tag = label or name
        if name == "build":
            tag += f" ({a[0].side} side)"
        rss("before " + tag)
        r = f(*a, **k)
        rss("after " + tag)
        return r
    setattr(obj, name, g)


def main():
    import petsc_ssi.bem.build as B
    import petsc_ssi.bem.lagset as LS
    import petsc_ssi.bem.march as M
    import petsc_ssi.bem.toeplitz as T
    wrap(T.ToeplitzHistory, "build", "toeplitz kernels")
    wrap(T.ToeplitzHistory, "_setup_state_maps", "state maps")
    wrap(B, "_toeplitz_marcher", "the toeplitz march's set-up")
    wrap(M.Marcher, "set_lags", "lag Mats")
    for n in dir(LS):
        c = getattr(LS, n)
        if isinstance(c, type) and "assemble" in vars(c):
            wrap(c, "assemble", f"{n}.assemble")
    sys.argv = ["petsc_ssi"] + sys.argv[1:]
    try:
        runpy.run_module("petsc_ssi", run_name="__main__")
    except SystemExit:
        pass
    rss("end")


if __name__ == "__main__":
    main()
