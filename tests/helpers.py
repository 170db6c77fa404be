"""Helpers for tests that run petsc_ssi in-process or under mpirun."""
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PY = sys.executable


def petsc():
    from petsc_ssi.petsc import init
    return init(["pytest"])


def run_bem(**opts):
    """Run a BEM case in this process with -ssi_<key> <value> options."""
    PETSc = petsc()
    from petsc_ssi import options
    import petsc_ssi.app.kinds  # noqa: F401  (every problem kind's options declared)
    from petsc_ssi.app.kinds import run_bem as _run
    db = PETSc.Options()
    opts = dict(opts)
    opts.setdefault("output_overwrite", 1)     # tests rerun cases into the same scratch file
    for k, v in opts.items():
        db.setValue("ssi_" + k, str(v))
    try:
        from petsc_ssi.app.kinds import resolve
        cfg = resolve("bem")
        return _run(cfg)
    finally:
        for k in opts:
            db.delValue("ssi_" + k)


def resolve_error(groups=("common", "bem"), **opts):
    """The SSIError message options.resolve + BEM set-up raise, or None."""
    PETSc = petsc()
    from petsc_ssi import options
    import petsc_ssi.app.kinds  # noqa: F401  (every problem kind's options declared)
    from petsc_ssi.petsc import SSIError
    from petsc_ssi.bem.halfspace import HalfSpace
    db = PETSc.Options()
    for k, v in opts.items():
        db.setValue("ssi_" + k, str(v))
    try:
        cfg = options.resolve(groups)
        prob = HalfSpace(cfg, PETSc.COMM_WORLD, log=lambda m: None)
        prob.check_memory(prob.lagset(prob.interp_plan()))
        return None
    except SSIError as exc:
        return str(exc)
    finally:
        for k in opts:
            db.delValue("ssi_" + k)


def run_script(*parts):
    """The module of a study script under runs/ (``run_script("runs", "trench", "trench.py")``): tests
    run its functions, as the README's numbers come from them."""
    import importlib.util
    path = os.path.join(ROOT, *parts)
    spec = importlib.util.spec_from_file_location(os.path.splitext(parts[-1])[0] + "_study", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def cli(args, nranks=1, timeout=900, check=True):
    """Run ``petsc-ssi`` (python -m petsc_ssi) in a subprocess, optionally under mpirun."""
    cmd = [PY, "-m", "petsc_ssi"] + list(args)
    if nranks > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(nranks)] + cmd
    env = dict(os.environ)
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=timeout, env=env)
    if check and p.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    return p


def read_h5(path):
    import h5py
    with h5py.File(path, "r") as f:
        d = {"t": f["receivers/t"][:], "u": f["receivers/u"][:], "points": f["receivers/points"][:]}
        snaps = sorted(k for k in f.keys() if k.startswith("displacement_"))
        if snaps:
            d["last"] = f[snaps[-1]][:]
        d["attrs"] = dict(f.attrs)
        d["keys"] = list(f.keys())
    return d


def relmax(a, b):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / max(np.abs(np.asarray(b)).max(), 1e-300))


def run_ssi(**opts):
    """Run a coupled FEM-BEM case in this process with -ssi_<key> <value> options."""
    PETSc = petsc()
    from petsc_ssi import options
    import petsc_ssi.app.kinds  # noqa: F401  (every problem kind's options declared)
    from petsc_ssi.app.kinds import run_ssi as _run
    db = PETSc.Options()
    opts = dict(opts)
    opts.setdefault("problem", "ssi")
    opts.setdefault("output_overwrite", 1)     # tests rerun cases into the same scratch file
    for k, v in opts.items():
        db.setValue("ssi_" + k, str(v))
    try:
        from petsc_ssi.app.kinds import resolve
        cfg = resolve("ssi")
        return _run(cfg)
    finally:
        for k in opts:
            db.delValue("ssi_" + k)


def signal_midway(args, log, after, send, nranks=1, timeout=240, mpirun_args=()):
    """Start ``petsc-ssi args`` (under mpirun for ``nranks`` > 1, with ``mpirun_args``) with a progress line every step,
    wait for the line of step ``after``, then ``send(p)`` (p: the Popen of python or of mpirun);
    returns (exit status, the log's text). The run must be long enough to be signalled midway."""
    import time
    cmd = [PY, "-m", "petsc_ssi"] + list(args) + ["-ssi_monitor", "-ssi_monitor_every", "1"]
    if nranks > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(nranks)] + list(mpirun_args) + cmd
    with open(log, "w") as fh:
        p = subprocess.Popen(cmd, cwd=ROOT, stdout=fh, stderr=subprocess.STDOUT,
                             env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    try:
        t0, seen = time.time(), False
        while time.time() - t0 < timeout and p.poll() is None:
            if os.path.exists(log) and f"step {after}/" in open(log).read():
                seen = True
                break
            time.sleep(0.2)
        assert seen, open(log).read()[-2000:]
        send(p)
        rc = p.wait(timeout=120)
    finally:
        if p.poll() is None:
            p.kill()
    return rc, open(log).read()


def kill_session(p, timeout=30):
    """SIGKILL to every process of the session ``p`` (a Popen started with start_new_session=True)
    leads, at once, then wait until none is left: what a lost node or a scheduler's kill does to a
    whole job. ``os.killpg(p.pid)`` is not that: mpirun puts each rank in a process group of its
    own, so it kills mpirun alone and leaves the ranks writing for a while."""
    import signal
    import time

    def members():
        out = []
        for d in os.listdir("/proc"):
            if d.isdigit():
                try:
                    with open(f"/proc/{d}/stat") as fh:
                        fields = fh.read().rsplit(")", 1)[1].split()
                except OSError:
                    continue
                if int(fields[3]) == p.pid and fields[0] != "Z":
                    out.append(int(d))
        return out
    for pid in members():
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    p.wait(timeout=timeout)
    t0 = time.time()
    while members():
        if time.time() - t0 > timeout:
            raise AssertionError(f"processes of session {p.pid} survive SIGKILL")
        time.sleep(0.01)


def write_surface_msh(path, order=2, xmin=-2.0, z=0.0):
    """A 4 m x 4 m gmsh surface of quadrilaterals (order 2: nine-node) at height z."""
    import gmsh
    gmsh.initialize(["gmsh", "-v", "0"], readConfigFiles=False)
    try:
        gmsh.model.add("t")
        s = gmsh.model.occ.addRectangle(xmin, -2, z, 4, 4)
        gmsh.model.occ.synchronize()
        gmsh.model.addPhysicalGroup(2, [s], name="surface")
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 1.0)
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(order)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


PV_HEAD = ("import sys, json\nfrom paraview.simple import XDMFReader\nfrom paraview import servermanager as sm\n"
           "from vtk.numpy_interface import dataset_adapter as dsa\nimport numpy as np\n"
           "r = XDMFReader(FileNames=[sys.argv[1]])\n")


def pv_or_skip():
    """pvpython's path; skips the test without it (apt-get install paraview): call it before the
    run the test reads, so a machine without ParaView does not pay for the run."""
    import shutil
    import pytest
    pv = shutil.which("pvpython")
    if pv is None:
        pytest.skip("ParaView (pvpython) is not installed: apt-get install paraview")
    return pv


def pvpython(body, xmf, tmp_path):
    """ParaView's XDMF reader on ``xmf``: ``body`` (after PV_HEAD, which opens it as ``r``) run by
    pvpython, offscreen; returns the last JSON line it printed, parsed. Skips the test without
    pvpython (apt-get install paraview)."""
    import json
    import subprocess
    pv = pv_or_skip()
    script = os.path.join(str(tmp_path), "pv_read.py")
    with open(script, "w") as fh:
        fh.write(PV_HEAD + body)
    p = subprocess.run([pv, "--force-offscreen-rendering", script, xmf], capture_output=True, text=True,
                       timeout=180, env=dict(os.environ, DISPLAY=""))
    assert p.returncode == 0, p.stdout + p.stderr
    return json.loads([ln for ln in p.stdout.splitlines() if ln[:1] in "{["][-1])


def sin4_pulse(path, T):
    """A record file 't a': a sin^4 acceleration pulse of length T then the reversed one, 1 m/s^2 (zero net
    velocity), 80 samples a pulse; returns its path as a string."""
    t = np.arange(0.0, 2 * T + 1e-9, T / 80)
    a = sum(sg * np.where((t >= k * T) & (t < (k + 1) * T), np.sin(np.pi * (t - k * T) / T) ** 4, 0.0)
            for k, sg in enumerate((1, -1)))
    np.savetxt(path, np.c_[t, a], header="units: m/s2")
    return str(path)


def ranks_json(code, n, tag, timeout=300):
    """Run python ``code`` under ``mpirun -n n`` and return the JSON its rank 0 printed after ``tag`` on one line
    (one line from rank 0: mpirun may run the ranks' lines together); asserts the run ended well and printed it."""
    import json
    import subprocess
    cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(n), PY, "-c", code]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=timeout,
                       env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith(tag)]
    assert p.returncode == 0 and len(lines) == 1, p.stdout + p.stderr
    return json.loads(lines[0][len(tag):])
