"""Checkpoint and restart: everything the next step needs, in one HDF5 file.

A checkpoint of a run after step n holds

  Vecs (PETSc HDF5 viewer, global datasets: any rank count reads them back)
      the soil's history ring (u^m, p^m for the steps the history sum still reads), the
      structure's integrator state (u, v and, per integrator, a or the last impulse)
  serial data (rank 0, h5py, group ``serial``)
      the recorded series (times, |u|, soil and structure receivers, interface series), the
      output's snapshot list, the contact state, integrator scalars
  attributes
      ``step``, ``n_steps``, ``problem``, ``ranks``, ``format``, the package version, ``key``:
      the options that define the run (``run_key``) as JSON, with a SHA-256 of every input file
      they name (meshes, load tables), and ``run_id``: the id the run wrote into its output too
      (a restart continues only an output of the same run); ``attrs_sha256``: the SHA-256 of
      these attributes and of every dataset's CRC32 list (``attrs_digest``), so an edited
      attribute is refused like damaged data
  on every dataset, attribute ``crc32``
      the CRC32 of each 8 MiB piece of its data (``io.integrity``: the ranks sum the pieces in
      turn, no gather); a restart verifies them before any heavy work and refuses a damaged file

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

FORMAT = 3          # 3: with the SHA-256 of the attributes; 2: run_id and the CRC32 of every dataset's data (1, 2: refused)
ATTRS = ("format", "step", "n_steps", "problem", "ranks", "petsc_ssi_version", "key", "run_id")


def attrs_digest(attrs, crcs):
    """SHA-256 of the attributes a restart trusts (``ATTRS``: the step it resumes after, the run's
    options, its id, ...) and of every dataset's CRC32 list: an attribute edited by hand or damaged
    is refused like a damaged dataset."""
    def text(v):
        v = v.item() if hasattr(v, "item") else v
        return v.decode() if isinstance(v, bytes) else str(v)
    blob = json.dumps({"attrs": {k: text(attrs.get(k, "")) for k in ATTRS},
                       "crc32": {k: [int(c) for c in v] for k, v in sorted(crcs.items())}}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()

# Options that steer how a run is carried out, watched or written, not what it computes: a restart
# may change them. Every other -ssi_ option defines the run and must be the same on restart.
RUN_CONTROL = frozenset((
    "output", "output_overwrite", "output_flush", "output_merge", "output_stride", "monitor", "monitor_every", "plot",
    "reproducible", "memory_limit", "guard", "guard_factor", "check_stability", "check_stability_steps",
    "warn_beta", "warn_edge", "cache", "cache_share", "lag_storage", "lag_fill", "history_block", "history_sub", "partition", "fem_solver", "modes_n",
    "checkpoint", "checkpoint_every", "checkpoint_interval", "restart", "lags_save", "lags_load",
    "huge_pages", "disk_check", "debug",
    # how the interface columns are solved (region or full: equal to round-off, as the solvers' options)
    "interface_columns", "interface_columns_margin",
    # the step matrix's LU in block low-rank form (its factors checked to 1e-12 on a test right-hand side)
    "step_blr"))


def _file_digest(path):
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def run_key(cfg, exclude=RUN_CONTROL, grid=None):
    """{option: value as text} of the options that define the run (estimate_* and the run-control
    ones left out), plus ``file:<option>`` the SHA-256 of an input file an option names. A run under
    a record without -ssi_t_end lasts the record: its t_end is ``DERIVED``, and ``grid`` (the run's
    time grid, when known) gives the end it derived under 'derived:t_end'."""
    key = {}
    values = cfg.as_dict()
    for name, val in sorted(values.items()):
        if name in exclude or name.startswith("estimate_"):
            continue
        key[name] = repr(val) if isinstance(val, float) else str(val)
        if isinstance(val, str) and val and os.path.isfile(val):
            key["file:" + name] = _file_digest(val)
    seismic = str(values.get("seismic", "none") or "none") != "none"
    if seismic and hasattr(cfg, "user_set") and "t_end" in key and not cfg.user_set("t_end"):
        # the run lasts the record: t_end is derived (the record, the start and dt are in the key),
        # the same on restart, where it is set only after this check (before: 0.04 here, 15.005 saved)
        key["derived:t_end"] = key.pop("t_end") if grid is None else repr(float(grid.t_end))
        key["t_end"] = DERIVED
    if "seismic_format" in key:
        key["seismic_format"] = _record_format(values)
    return key


DERIVED = "(not given: the record's length)"


def _record_format(cfg):          # cfg: the options' values (a dict)
    """-ssi_seismic_format as the record is read: 'auto' resolved to what it finds (peer, table or obspy),
    so a restart that names the format auto found is the same run (before: refused as a change)."""
    fmt = str(cfg.get("seismic_format", "auto") or "auto")
    path = next((cfg.get(k) for k in ("seismic_record", "seismic_record_x", "seismic_record_y", "seismic_record_z")
                 if cfg.get(k) and os.path.isfile(cfg.get(k))), None)
    if path is None or str(cfg.get("seismic", "none")) == "none":
        return fmt
    from ..seismic.records import detect_format
    try:
        with open(path, "rb") as fh:
            kind = detect_format(path, fh.read(1 << 16), fmt)
    except OSError:
        return fmt
    if kind in ("peer", "table"):
        return kind
    if fmt.lower() not in ("auto", "obspy"):
        return fmt.upper()
    try:                # the format ObsPy finds (MSEED, SAC, ...): -ssi_seismic_format mseed names the same
        import obspy
        return str(obspy.read(path, headonly=True)[0].stats._format).upper()
    except Exception:   # (no ObsPy, or a file it cannot read: the run's reader says why, in one line)
        return "obspy"


def key_difference(saved, now):
    """The first option that differs between two keys, as a phrase, or None. An option the
    checkpoint's version did not have counts as its default there (an option added since). An
    option naming an input file compares by the file's SHA-256, not its path."""
    from ..options import options
    registry = options()
    for name in sorted(set(saved) | set(now)):
        if name.startswith("derived:"):
            continue                             # a value the run derives, compared through ``name``
        a, b = saved.get(name), now.get(name)
        if DERIVED in (a, b) and a != b:         # derived on one side, given on the other: the saved value
            da = saved.get("derived:" + name, a)
            try:
                if a == DERIVED and float(b) == float(da):
                    continue                     # given as the value the interrupted run derived
            except (TypeError, ValueError):
                pass
            return (f"-ssi_{name} is {b} here and was {a if a != DERIVED else f'{da} {DERIVED}'}"
                    + (f"; leave -ssi_{name} out, as the interrupted run did" if a == DERIVED else
                       f"; give -ssi_{name} {a}, as the interrupted run did"))
        if a is None and name in registry and not name.startswith("file:"):
            d = registry[name].default
            a = repr(d) if isinstance(d, float) else str(d)
        if a == b:
            continue
        if name == "seismic_format" and a == "obspy" and b is not None and b.isupper():
            continue            # a checkpoint written before the ObsPy format was resolved: the same reader
        fa, fb = saved.get("file:" + name), now.get("file:" + name)
        if fa is not None and fa == fb:
            continue            # the same input file at another path (moved, copied): the same run
        if fa is not None and fb is not None:
            name = "file:" + name
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
            import h5py
            with _h5(path, "r") as f:
                fmt = f.attrs.get("format", -1)
                fmt = int(fmt) if np.ndim(fmt) == 0 and np.issubdtype(np.asarray(fmt).dtype, np.number) else -1
                if fmt in (1, 2):
                    raise SSIError(f"-ssi_restart {path}: a checkpoint of an older petsc-ssi without checksums "
                                   f"of its {'content' if fmt == 1 else 'attributes'} (format {fmt}); run again "
                                   "from the start")
                if fmt != FORMAT or "key" not in f.attrs:
                    raise SSIError(f"-ssi_restart {path}: not a petsc-ssi checkpoint (format {FORMAT})")
                crc = {}
                f.visititems(lambda name, obj: crc.__setitem__(name, [int(c) for c in obj.attrs["crc32"]])
                             if isinstance(obj, h5py.Dataset) and "crc32" in obj.attrs else None)
                saved = f.attrs.get("attrs_sha256", "")
                saved = saved.decode() if isinstance(saved, bytes) else str(saved)
                if saved != attrs_digest(f.attrs, crc):
                    raise SSIError(f"-ssi_restart {path}: its attributes (step, options, run id, checksums) differ "
                                   "from their SHA-256 (attrs_sha256): a damaged or edited checkpoint; restart from "
                                   "an earlier one or run again from the start")
                head = {k: (v.item() if hasattr(v, "item") else v) for k, v in f.attrs.items()}
                head = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in head.items()}
                try:
                    head["key"] = json.loads(str(head["key"]))
                    int(head["step"]), int(head["n_steps"])
                except (ValueError, TypeError) as exc:
                    raise SSIError(f"-ssi_restart {path}: unreadable attributes ({exc})") from None
                head["crc32"] = crc
    return comm.tompi4py().bcast(head, root=0)


def output_run_id(path, comm):
    """Collective: the ``run_id`` attribute of an existing output ('' without one), None when the
    file does not exist; rank 0 reads, every rank gets it."""
    rid = None
    with collective(comm, f"-ssi_output {path}", "{what}: cannot read it to check that it belongs to the "
                                                 "checkpoint ({error})"):
        if comm.getRank() == 0 and os.path.lexists(path):
            with _h5(path, "r") as f:
                v = f.attrs.get("run_id", "")
                rid = v.decode() if isinstance(v, bytes) else str(v)
    return comm.tompi4py().bcast(rid, root=0)


def check_restart(cfg, comm, kind, outputs=()):
    """Collective, before any heavy work: the header of -ssi_restart, checked against this run
    (problem kind, the options that define the run), its content against its checksums, and each
    existing file of ``outputs`` (the run's HDF5 outputs, which a restart continues) against its
    run id; SSIError naming what differs."""
    from .integrity import check_datasets
    path = cfg.restart
    head = read_header(path, comm)
    bad = check_datasets(path, comm, head.pop("crc32"))
    if bad:
        raise SSIError(f"-ssi_restart {path}: {bad}: a damaged checkpoint; restart from an earlier one or "
                       "run again from the start")
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
    for out in outputs:
        rid = output_run_id(out, comm)
        if rid is not None and rid != head.get("run_id"):
            raise SSIError(f"-ssi_output {out}: exists and is not the output of the run that wrote -ssi_restart "
                           f"{path} (run id {rid or '(none)'} there, {head.get('run_id')} in the checkpoint); a "
                           "restart continues its own run's output: give that one, or a name that does not exist")
        if rid is not None:                      # its parts, before the assembly (before: refused after it)
            from .output import missing_part
            gone = None
            with collective(comm, f"-ssi_output {out}", "{what}: cannot read it ({error})"):
                if comm.getRank() == 0:
                    gone = missing_part(out)
            gone = comm.tompi4py().bcast(gone, root=0)
            if gone:
                raise SSIError(f"-ssi_output {gone}; restore the part, or restart into a new -ssi_output name")
    return head


def not_ours(path, comm, run_id, overwrite=False):
    """Collective: a phrase if ``path`` exists and is not a checkpoint of the run ``run_id`` (another
    run's, or another file), which a checkpoint write would replace (unless ``overwrite``), else None."""
    why = None
    if comm.getRank() == 0 and not overwrite and os.path.lexists(path):
        rid = None
        try:
            with _h5(path, "r") as f:
                v = f.attrs.get("run_id", "")
                rid = v.decode() if isinstance(v, bytes) else str(v)
        except Exception:  # noqa: BLE001 -- not an HDF5 file: not ours
            pass
        if not run_id or rid != run_id:
            why = f"{path} exists and is not this run's checkpoint (add -ssi_output_overwrite to replace it)"
    return comm.tompi4py().bcast(why, root=0)


def write(path, comm, step, n_steps, kind, key, vecs, serial, run_id=""):
    """Collective: a checkpoint at ``path``, atomically (``path``.tmp, then renamed). ``vecs``:
    {name: Vec}, written by the PETSc HDF5 viewer; ``serial``: {name: array} of rank 0; every
    dataset gets the CRC32s of its data (``io.integrity.dataset_crcs``)."""
    from .integrity import dataset_crcs
    PETSc = init()
    tmp = path + ".tmp"
    with collective(comm, f"checkpoint {path}", "{what}: {error}"):
        if comm.getRank() == 0:
            os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
            if os.path.lexists(tmp):
                os.remove(tmp)
    ensure_space(path, 8.0 * sum(v.getSize() for v in vecs.values()), comm, f"checkpoint after step {step}")
    viewer = PETSc.Viewer().createHDF5(tmp, mode="w", comm=comm)

    from .output import view_vecs
    collective_io(lambda: view_vecs(viewer, vecs), f"writing the checkpoint {tmp}", comm)
    collective_io(viewer.destroy, f"closing the checkpoint {tmp}", comm)
    with collective(comm, f"checkpoint {path}", "{what}: {error}"):
        if comm.getRank() == 0:
            with _h5(tmp, "a") as f:
                g = f.create_group("serial")
                for name, val in serial.items():
                    g.create_dataset(name, data=np.bytes_(val.encode()) if isinstance(val, str) else np.asarray(val))
    crcs = dataset_crcs(tmp, comm)
    with collective(comm, f"checkpoint {path}", "{what}: {error}"):
        if comm.getRank() == 0:
            from .. import __version__
            with _h5(tmp, "a") as f:
                for name, c in crcs.items():
                    f[name].attrs["crc32"] = np.asarray(c, np.uint32)
                f.attrs.update({"format": FORMAT, "step": int(step), "n_steps": int(n_steps), "problem": kind,
                                "ranks": comm.getSize(), "petsc_ssi_version": __version__,
                                "key": json.dumps(key, sort_keys=True), "run_id": run_id})
                f.attrs["attrs_sha256"] = attrs_digest(f.attrs, crcs)
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
