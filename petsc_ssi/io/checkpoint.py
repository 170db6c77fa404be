"""Checkpoint and restart: everything the next step needs, in one HDF5 file.

A checkpoint of a run after step n holds

  Vecs (PETSc HDF5 viewer, global datasets: any rank count reads them back)
      the soil's history ring (u^m, p^m for the steps the history sum still reads), the
      structure's integrator state (u, v and, per integrator, a or the last impulse)
  serial data (rank 0, h5py, group ``serial``)
      the recorded series (times, |u|, soil and structure receivers, interface series), the
      output's snapshot list, the contact state, integrator scalars
  attributes
      ``step``, ``n_steps``, ``problem``, ``ranks``, ``format``, the package version and ``key``:
      the options that define the run (``run_key``) as JSON, with a SHA-256 of every input file
      they name (meshes, load tables)

It is written to ``FILE.tmp`` and renamed over ``FILE`` only when complete, so a kill during the
write leaves the previous checkpoint. ``-ssi_checkpoint FILE`` names it (default
``<output stem>-checkpoint.h5``; ``%d`` in the name is replaced by the step, to keep every one);
``-ssi_checkpoint_every N`` (steps) and ``-ssi_checkpoint_interval S`` (wall seconds) say when;
SIGTERM, SIGINT and SIGUSR1 write one at the end of the current step, after the output, before
the run stops (``TransientProblem._stop``; under mpirun only if its kill leaves the time: README).
``-ssi_restart FILE`` resumes: the same options (refused otherwise, naming the option that
differs), any rank count; the output of the interrupted run is continued in place.

Bitwise: a restart at the rank count of the checkpoint repeats the uninterrupted run bit for bit
when its solves are deterministic (one rank, or -ssi_reproducible on more: MUMPS's parallel
factorisation may sum in another order from run to run, jobscripts/rerun_determinism.sh); on
another rank count it agrees to round-off.
"""
import hashlib
import json
import os

import numpy as np

from ..petsc import init, collective, collective_error, collective_io, ensure_space, SSIError

FORMAT = 1

# Options that steer how a run is carried out, watched or written, not what it computes: a restart
# may change them. Every other -ssi_ option defines the run and must be the same on restart.
RUN_CONTROL = frozenset((
    "output", "output_overwrite", "output_flush", "output_stride", "monitor", "monitor_every", "plot",
    "reproducible", "memory_limit", "guard", "guard_factor", "check_stability", "check_stability_steps",
    "warn_beta", "cache", "cache_share", "lag_storage", "lag_fill", "history_block", "history_sub", "partition", "fem_solver", "modes_n",
    "checkpoint", "checkpoint_every", "checkpoint_interval", "restart", "lags_save", "lags_load"))


def _file_digest(path):
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def run_key(cfg, exclude=RUN_CONTROL):
    """{option: value as text} of the options that define the run (estimate_* and the run-control
    ones left out), plus ``file:<option>`` the SHA-256 of an input file an option names."""
    key = {}
    for name, val in sorted(cfg.as_dict().items()):
        if name in exclude or name.startswith("estimate_"):
            continue
        key[name] = repr(val) if isinstance(val, float) else str(val)
        if isinstance(val, str) and val and os.path.isfile(val):
            key["file:" + name] = _file_digest(val)
    return key


def key_difference(saved, now):
    """The first option that differs between two keys, as a phrase, or None. An option the
    checkpoint's version did not have counts as its default there (an option added since)."""
    from ..options import _REGISTRY
    for name in sorted(set(saved) | set(now)):
        a, b = saved.get(name), now.get(name)
        if a is None and name in _REGISTRY and not name.startswith("file:"):
            d = _REGISTRY[name].default
            a = repr(d) if isinstance(d, float) else str(d)
        if a == b:
            continue
        if name.startswith("file:"):
            return f"the file of -ssi_{name[5:]} changed since the checkpoint (SHA-256 differs)"
        return f"-ssi_{name} is {b if b is not None else '(unset)'} here and was {a if a is not None else '(unset)'}"
    return None


def checkpoint_path(cfg, step=None):
    """The checkpoint file of a run (None: the run has neither -ssi_checkpoint nor an output);
    ``%d`` in the name becomes ``step``."""
    path = cfg.get("checkpoint") or ""
    if not path:
        if not cfg.get("output"):
            return None
        path = os.path.splitext(cfg.output)[0] + "-checkpoint.h5"
    if "%d" in path and step is not None:
        path = path.replace("%d", str(int(step)))
    return path


def _h5(path, mode):
    import h5py
    try:
        return h5py.File(path, mode, locking=False)
    except (TypeError, ValueError):
        return h5py.File(path, mode)


def read_header(path, comm):
    """Collective: the attributes of a checkpoint (rank 0 reads, every rank gets them); SSIError in
    one line if it is missing or not a complete checkpoint."""
    head = None
    with collective(comm, f"-ssi_restart {path}", "{what}: cannot read it ({error})"):
        if comm.getRank() == 0:
            if not os.path.isfile(path):
                raise SSIError(f"-ssi_restart {path}: no such file")
            with _h5(path, "r") as f:
                if int(f.attrs.get("format", -1)) != FORMAT or "key" not in f.attrs:
                    raise SSIError(f"-ssi_restart {path}: not a petsc-ssi checkpoint (format {FORMAT})")
                head = {k: (v.item() if hasattr(v, "item") else v) for k, v in f.attrs.items()}
                head["key"] = json.loads(str(head["key"]))
    return comm.tompi4py().bcast(head, root=0)


def check_restart(cfg, comm, kind):
    """Collective, before any heavy work: the header of -ssi_restart, checked against this run
    (problem kind, the options that define the run); SSIError naming what differs."""
    path = cfg.restart
    head = read_header(path, comm)
    err = None
    if head["problem"] != kind:
        err = f"-ssi_restart {path}: the checkpoint is of -ssi_problem {head['problem']}, this run is {kind}"
    else:
        diff = key_difference(head["key"], run_key(cfg))
        if diff:
            err = (f"-ssi_restart {path}: {diff}; a restart continues the same run, so the options that "
                   "define it must not change")
    if err is None and not 0 < int(head["step"]) < int(head["n_steps"]):
        err = f"-ssi_restart {path}: the checkpoint is after step {head['step']} of {head['n_steps']}: nothing to do"
    collective_error(err, comm)
    return head


def write(path, comm, step, n_steps, kind, key, vecs, serial):
    """Collective: a checkpoint at ``path``, atomically (``path``.tmp, then renamed). ``vecs``:
    {name: Vec}, written by the PETSc HDF5 viewer; ``serial``: {name: array} of rank 0."""
    PETSc = init()
    tmp = path + ".tmp"
    with collective(comm, f"checkpoint {path}", "{what}: {error}"):
        if comm.getRank() == 0:
            os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
            if os.path.lexists(tmp):
                os.remove(tmp)
    ensure_space(path, 8.0 * sum(v.getSize() for v in vecs.values()), comm, f"checkpoint after step {step}")
    viewer = PETSc.Viewer().createHDF5(tmp, mode="w", comm=comm)

    def write_vecs():
        for name, v in vecs.items():
            old = v.getName()
            v.setName(name)
            try:
                v.view(viewer)
            finally:
                v.setName(old)
    collective_io(write_vecs, f"writing the checkpoint {tmp}", comm)
    collective_io(viewer.destroy, f"closing the checkpoint {tmp}", comm)
    with collective(comm, f"checkpoint {path}", "{what}: {error}"):
        if comm.getRank() == 0:
            from .. import __version__
            with _h5(tmp, "a") as f:
                g = f.create_group("serial")
                for name, val in serial.items():
                    g.create_dataset(name, data=np.bytes_(val.encode()) if isinstance(val, str) else np.asarray(val))
                f.attrs.update({"format": FORMAT, "step": int(step), "n_steps": int(n_steps), "problem": kind,
                                "ranks": comm.getSize(), "petsc_ssi_version": __version__,
                                "key": json.dumps(key, sort_keys=True)})
            fd = os.open(tmp, os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)
            os.replace(tmp, path)


class Reader:
    """Collective: a checkpoint's serial data (read by rank 0, broadcast) and its Vecs (loaded into
    Vecs of this run's layout by the PETSc HDF5 viewer)."""

    def __init__(self, path, comm):
        PETSc = init()
        self.path, self.comm = path, comm
        data = None
        with collective(comm, f"-ssi_restart {path}", "{what}: cannot read its data ({error})"):
            if comm.getRank() == 0:
                with _h5(path, "r") as f:
                    data = {k: f["serial"][k][()] for k in f["serial"]}
                    names = sorted(k for k in f.keys() if k != "serial")
                data = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in data.items()}
                data = (data, names)
        self.serial, self.names = comm.tompi4py().bcast(data, root=0)
        self.names = frozenset(self.names)
        self.viewer = PETSc.Viewer().createHDF5(path, mode="r", comm=comm)

    def output_state(self, prefix):
        """The snapshot list of an Output saved under ``prefix`` (``Output.state``)."""
        if prefix + "_times" not in self.serial:      # the interrupted run wrote no output
            return None
        return {"times": self.serial[prefix + "_times"], "fields": self.serial[prefix + "_fields"]}

    def has(self, name):
        """Whether the checkpoint holds the Vec ``name``."""
        return name in self.names

    def load(self, name, vec):
        """Collective: the saved Vec ``name`` into ``vec`` (same global size)."""
        old = vec.getName()
        vec.setName(name)
        vec.load(self.viewer)
        vec.setName(old)
        return vec

    def close(self):
        self.viewer.destroy()
