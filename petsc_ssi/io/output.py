"""Output: fields through the PETSc HDF5 viewer, an XDMF file for ParaView,
and a JSON provenance record beside them.

Layout of ``FILE.h5`` (flat dataset names, so the same file is written by
petsc4py 3.18, whose HDF5 viewer has no group/timestepping calls, and newer):

  coordinates            (N, 3)  node coordinates           [PETSc Vec, bs 3]
  <field>_<k:06d>        (N, 3)  nodal field at snapshot k  [PETSc Vec, bs 3]
  topology               (E, n)  cell connectivity (0-based)        [rank 0]
  time                   (K,)    time of snapshot k                 [rank 0]
  receivers/...          receiver series (see ``write_receivers``)  [rank 0]
  (writers)              more data of ``Output.writers`` (e.g. io/forces.py's member forces:
                         distributed Vecs through the viewer before it closes, then rank 0's
                         h5py work, which may name cell fields: XDMF Center="Cell" attributes)
  attrs: cell_type, fields, n_snapshots, petsc_ssi_version, run_status, run_id (shared with
         the run's checkpoints: a restart continues only the output of its own run)

Distributed fields are written collectively by the PETSc viewer; the small
serial data (topology, time, receiver series) by rank 0 with h5py after the
viewer is closed. Rank-0-only file work never leaves the other ranks waiting:
an error there is caught, passed to every rank (``petsc.collective_error``)
and raised everywhere as the same one-line SSIError. ``FILE.xmf`` (XDMF 3, temporal collection) is written on
rank 0 so ParaView opens the result; ``FILE.json`` holds the resolved options,
library versions, git revision and number of ranks (PyLith's habit).
"""
import json
import os
import platform
import subprocess
import time as _time

import numpy as np

from ..petsc import init, collective, collective_error, collective_io, ensure_space

XDMF_CELL = {"quad9": ("Quadrilateral_9", 9), "quad4": ("Quadrilateral", 4),
             "hex8": ("Hexahedron", 8), "line2": ("Polyline", 2), "tri3": ("Triangle", 3)}
# XDMF "Mixed" topology: per cell its type id (a Polyline also its node count), then its nodes
XDMF_MIXED_ID = {"Polyline": 2, "Triangle": 4, "Quadrilateral": 5, "Hexahedron": 9, "Quadrilateral_9": 0x23}


def mixed_topology(blocks):
    """Flat XDMF Mixed topology of [(xdmf type name, cells (E, n))]: per cell
    [type id, (n for a Polyline), nodes...]; and the cell count."""
    parts, ne = [], 0
    for name, cells in blocks:
        cells = np.asarray(cells, np.int64)
        if cells.size == 0:
            continue
        head = [np.full((cells.shape[0], 1), XDMF_MIXED_ID[name], np.int64)]
        if name == "Polyline":
            head.append(np.full((cells.shape[0], 1), cells.shape[1], np.int64))
        parts.append(np.hstack(head + [cells]).ravel())
        ne += cells.shape[0]
    return (np.concatenate(parts) if parts else np.zeros(0, np.int64)), ne


SIDECARS = (".xmf", ".json")

# The ``unit`` attribute of the datasets whose names are fixed ("1": a count, index, flag or a
# relative number): the snapshots' fields (``<field>_NNNNNN``), the receivers' group (soil and
# structure) and the coupled run's interface group. A group written as (array, unit) tuples gives
# its own; README "Output files" lists them all.
UNITS = {
    "displacement": "m", "traction": "N/m^2", "velocity": "m/s", "rotation": "rad", "acceleration": "m/s^2",
    "mode_shape": "1 (the mode vector scaled to max |entry| = 1)",
    "mode_shape_rotation": "1 (rotations of the same scaled vector)",
    "receivers/points": "m", "receivers/t": "s", "receivers/u": "m", "receivers/velocity": "m/s",
    "receivers/acceleration": "m/s^2", "receivers/rotation": "rad", "receivers/nodes": "1",
    "receivers/node_points": "m", "receivers/snap_distance": "m", "receivers/has_rotation": "1",
    "receivers/ground_acceleration": "m/s^2", "receivers/absolute_acceleration": "m/s^2",
    "interface/t": "s", "interface/x": "m", "interface/normal": "1", "interface/uf": "m", "interface/ub": "m",
    "interface/uf_check": "m", "interface/uff": "m", "interface/p": "N/m^2", "interface/gap": "m",
    "interface/pN": "N/m^2", "interface/closed": "1", "interface/n_open": "1", "interface/iterations": "1",
    "interface/changes": "1", "interface/force_fe": "N", "interface/force_be": "N", "interface/moment_fe": "N m",
    "interface/moment_be": "N m", "interface/bem_residual": "1", "interface/force_map_error": "N",
    "interface/nodal_steps": "1", "interface/t_nodal": "s",
}


def output_files(path):
    """The files a run with -ssi_output ``path`` writes: the HDF5 file and its sidecars."""
    stem = os.path.splitext(path)[0]
    return [path] + [stem + s for s in SIDECARS]


def command_output(path, command, argv=None):
    """The output of ``petsc-ssi modes`` or ``static``: -ssi_output as given on the command line;
    from an options file (or the default) ``<stem>-<command>.h5``, so the command run with a
    transient case's options never replaces that run's result (kept when the stem already ends
    with the command's name: out/block-modes.h5)."""
    import sys
    argv = sys.argv[1:] if argv is None else argv
    if not path or "-ssi_output" in argv:
        return path
    stem, ext = os.path.splitext(path)
    if stem.lower().endswith(command):
        return path
    return f"{stem}-{command}{ext or '.h5'}"


def replace_error(f, label, what="-ssi_output", overwrite=False):
    """The one-line reason the output file ``f`` (named in messages as ``label``) may not be
    written, or None: a directory, not a regular file, or an earlier result without overwrite."""
    if os.path.isdir(f):
        return f"{label}: {f} is a directory"
    if os.path.lexists(f) and not os.path.isfile(f):
        return f"{label}: {f} exists and is not a regular file"
    if os.path.lexists(f) and not overwrite:
        return (f"{label}: {f} exists (a previous result); add -ssi_output_overwrite to replace it, "
                f"or choose another {what}")
    return None


def check_output(path, comm, overwrite=False, what="-ssi_output", also=()):
    """Collective, before any heavy work: SSIError (one line, every rank) unless ``path`` (and the
    outputs ``also``, e.g. the structure's file of a coupled run) can be written: not a sidecar
    name, not a directory or special file, its directory creatable and writable by every rank,
    and no existing result replaced unless ``overwrite`` (-ssi_output_overwrite)."""
    paths = [path] + list(also)
    err = None
    ext = os.path.splitext(path)[1].lower()
    if ext in SIDECARS:
        err = (f"{what} {path}: '{ext}' is the name of a sidecar the run writes beside its HDF5 file; "
               "give the .h5 name")
    d = os.path.dirname(os.path.abspath(path))
    if err is None and comm.getRank() == 0:
        try:
            os.makedirs(d, exist_ok=True)
        except OSError as exc:
            err = f"{what} {path}: cannot create the directory {d} ({exc.strerror or exc})"
    collective_error(err, comm)
    for p in paths:
        for f in output_files(p):
            err = replace_error(f, f"{what} {p}", what, overwrite)
            if err:
                break
        if err:
            break
    if err is None and not os.access(d, os.W_OK | os.X_OK):
        err = f"{what} {path}: the directory {d} is not writable (rank {comm.getRank()})"
    if err is None:
        probe = os.path.join(d, f".petsc-ssi-probe-{os.getpid()}-{comm.getRank()}")
        try:
            with open(probe, "wb") as fh:
                fh.write(b"\0" * 4096)
                fh.flush()
                os.fsync(fh.fileno())
        except OSError as exc:
            err = f"{what} {path}: cannot write in {d} ({exc.strerror or exc})"
        finally:
            try:
                os.remove(probe)
            except OSError:
                pass
    collective_error(err, comm)


STAGE = "_flush_staging"       # the group a flush writes its series to before they replace the old ones


def _group(parent, name):
    """A new HDF5 group without modification times (h5py's create_group cannot say so)."""
    import h5py
    gcpl = h5py.h5p.create(h5py.h5p.GROUP_CREATE)
    gcpl.set_obj_track_times(False)
    return h5py.Group(h5py.h5g.create(parent.id, name.encode(), gcpl=gcpl))


def compactable(path, slack=2.0, margin=8e6):
    """Rank 0: whether the file holds much more than its datasets (more than ``slack`` times their
    bytes plus ``margin``): each flush during a run replaces the series (receivers, interface,
    demands) and HDF5 does not reuse the space of deleted datasets, so a long run's file would grow
    with the number of flushes times the series' size (262 MB for 29 MB of data, 6000 steps and a
    flush every 10 s). Files with virtual datasets (io/forces.py) are left as they are: a copy
    would store their data twice."""
    import h5py
    live, virtual = [0], [False]
    with _h5(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                if obj.is_virtual:
                    virtual[0] = True
                else:
                    live[0] += obj.id.get_storage_size()
        f.visititems(visit)
    return not virtual[0] and os.path.getsize(path) > slack * live[0] + margin


def rewrite_without_times(path):
    """Rank 0: ``path`` copied object by object into a file whose objects carry no modification
    times, then renamed over it, so identical data give identical bytes. (PETSc's HDF5 viewer
    creates its datasets with HDF5's default, which records the times; it has no switch.)"""
    import h5py
    tmp = path + ".notimes.tmp"
    fcpl = h5py.h5p.create(h5py.h5p.FILE_CREATE)
    fcpl.set_obj_track_times(False)
    with _h5(path, "r") as src, h5py.File(h5py.h5f.create(tmp.encode(), h5py.h5f.ACC_TRUNC, fcpl=fcpl)) as dst:
        def copy(s, d):
            for k, v in s.attrs.items():
                d.attrs[k] = v
            for name in s:
                obj = s[name]
                if isinstance(obj, h5py.Group):
                    copy(obj, _group(d, name))
                else:
                    ds = d.create_dataset(name, data=obj[()], track_times=False, chunks=obj.chunks,
                                          maxshape=obj.maxshape if obj.chunks else None)   # as PETSc made it:
                    # a restart appends through PETSc's viewer, which extends chunked datasets
                    for k, v in obj.attrs.items():
                        ds.attrs[k] = v
        copy(src, dst)
    os.replace(tmp, path)


def _h5(path, mode):
    """h5py.File without HDF5's file locking where the library allows (a reader may hold it)."""
    import h5py
    try:
        return h5py.File(path, mode, locking=False)
    except (TypeError, ValueError):            # h5py < 3.5, or an HDF5 without the locking switch
        return h5py.File(path, mode)


class Output:
    """Collective writer of one run's fields and series."""

    def __init__(self, path, comm, resume=None, run_id=""):
        """``run_id``: the run's id (``TransientProblem.run_id``), the attribute ``run_id`` of the
        file, which a restart compares with its checkpoint's. ``resume``: the snapshot list of an interrupted run ({'times', 'fields'}, a checkpoint's):
        its file is continued (opened to append; later snapshots overwrite those the interrupted run
        wrote after its checkpoint); a missing file is started anew, with a warning."""
        PETSc = init()
        self.PETSc = PETSc
        self.path = path
        self.comm = comm
        self.rank = comm.getRank()
        self.run_id = run_id or ""
        d = os.path.dirname(os.path.abspath(path))

        def stale():
            for f in output_files(path)[1:]:          # an older run's sidecars must not describe this file
                if os.path.isfile(f):
                    os.remove(f)
        self._rank0(lambda: os.makedirs(d, exist_ok=True), f"cannot create the output directory {d}")
        self.times = []
        self.fields = []
        mode = "w"
        if resume is not None:
            exists = comm.tompi4py().bcast(os.path.isfile(path) if self.rank == 0 else None, root=0)
            if exists:
                mode = "a"
                self.times = [float(t) for t in resume["times"]]
                self.fields = [f for f in resume["fields"].split(",") if f]
            elif len(resume["times"]):
                from ..petsc import warn
                warn(f"{path} (the output of the interrupted run) is missing: a new one is written, without the "
                     f"{len(resume['times'])} field snapshots before the restart (the receiver series are whole)", comm)
        if mode == "w":
            self._rank0(stale, f"cannot remove the old sidecars of {path}")
        self.viewer = PETSc.Viewer().createHDF5(path, mode=mode, comm=comm)
        self.cells = None
        self.cell_type = None
        self.n_nodes = 0
        # -ssi_reproducible: the finished file is rewritten without HDF5 modification times
        self.deterministic = PETSc.Options().getBool("ssi_reproducible", False)
        # writers of more data (e.g. io.forces.ForceRecorder): write_collective(out) before the
        # viewer closes, write_serial(h5 file) on rank 0 -> XDMF cell attributes [(name, dataset, unit)]
        self.writers = []
        self.cell_attributes = []

    def state(self):
        """The snapshot list, for a checkpoint: {'times', 'fields'}."""
        return {"times": np.asarray(self.times, float), "fields": ",".join(self.fields)}

    def write_mesh(self, coords_vec, cells, cell_type):
        """``coords_vec``: PETSc Vec (bs 3) of node coordinates in the field
        layout; ``cells``: (E, n) int array, needed on rank 0 only; or, with
        ``cell_type`` 'mixed', a list [(xdmf type name, (E, n) cells)] of blocks
        (written as one XDMF Mixed topology)."""
        coords_vec.setName("coordinates")
        collective_io(lambda: coords_vec.view(self.viewer), f"writing {self.path}", self.comm)
        self.n_nodes = coords_vec.getSize() // 3
        self.n_cells = 0
        if cell_type == "mixed":
            self.cells, self.n_cells = (None, 0) if cells is None else mixed_topology(cells)
        else:
            self.cells = None if cells is None else np.asarray(cells, dtype=np.int64)
            self.n_cells = 0 if cells is None else self.cells.shape[0]
        self.cell_type = cell_type

    def write_fields(self, t, fields):
        """Collective: one snapshot of nodal fields ``{name: Vec(bs 3)}``."""
        k = len(self.times)
        ensure_space(self.path, 8.0 * sum(v.getSize() for v in fields.values()),
                     self.comm, f"snapshot {k} (t = {t:.6g} s)")

        def write():
            for name, vec in fields.items():
                old = vec.getName()
                vec.setName(f"{name}_{k:06d}")
                try:
                    vec.view(self.viewer)
                finally:
                    vec.setName(old)
        collective_io(write, f"writing {self.path} (snapshot {k}, t = {t:.6g} s)", self.comm)
        for name in fields:
            if name not in self.fields:
                self.fields.append(name)
        self.times.append(float(t))

    def write_vecs(self, vecs, what):
        """Collective: distributed Vecs {dataset name: Vec} through the viewer (a Vec of block
        size c gives an (n / c, c) dataset; an existing dataset of that name is overwritten)."""
        ensure_space(self.path, 8.0 * sum(v.getSize() for v in vecs.values()), self.comm, what)

        def write():
            for name, vec in vecs.items():
                old = vec.getName()
                vec.setName(name)
                try:
                    vec.view(self.viewer)
                finally:
                    vec.setName(old)
        collective_io(write, f"writing {self.path} ({what})", self.comm)

    def close(self, receivers=None, attrs=None, record=None, groups=None, status="completed", final=True):
        """Collective: close the viewer, then rank 0 adds the serial data and
        writes the XDMF and JSON files. ``receivers``: dict with 'points'
        (R,3), 'nodes' (R,) optional, 't' (K,), 'u' (K,R,3), on rank 0.
        ``groups``: {group: {name: array, (array, unit) or (array, unit, {attribute: value})}}
        more serial data (rank 0). ``status``: how the run
        ended (the file's attribute ``run_status`` and the record's)."""
        for w in self.writers:
            w.write_collective(self)
        viewer, self.viewer = self.viewer, None
        collective_io(viewer.destroy, f"closing {self.path}", self.comm)
        self._rank0(lambda: self._write_serial(receivers, attrs, record, groups, status, final), f"writing {self.path}")

    def flush(self, receivers=None, attrs=None, record=None, groups=None, status="running"):
        """Collective: make the file readable as it stands (a run killed or stopped later keeps
        it): the viewer is closed, rank 0 (re)writes time, topology, receivers, groups, the
        attributes with ``run_status`` and the sidecars, and the viewer reopens to append."""
        if self.viewer is None:
            return
        try:
            self.close(receivers, attrs, record, groups, status, final=False)
        except BaseException:                      # a failed flush (a reader holding the file) keeps writing
            self._reopen()
            raise
        self._reopen()

    def _reopen(self):
        if self.viewer is None:
            self.viewer = self.PETSc.Viewer().createHDF5(self.path, mode="a", comm=self.comm)

    def _rank0(self, work, what):
        """Collective: ``work()`` on rank 0; an exception there is raised on every rank as a
        one-line SSIError (the allgather of collective_error is also the barrier)."""
        with collective(self.comm, what, "{what}: {error}"):
            if self.rank == 0:
                work()

    def _write_serial(self, receivers, attrs, record, groups=None, status="completed", final=True):
        """Rank 0: topology, time, attributes and receivers into the HDF5 file (replacing what an
        earlier flush wrote); XDMF; JSON."""
        with _h5(self.path, "a") as f:             # no lock: a reader may hold the file open mid-run
            # Staged, so that a kill (SIGKILL, a lost node) in the middle leaves the last flush's data
            # readable: the new series go to the group STAGE, HDF5 writes them out (H5Fflush), and
            # only then replace the old ones (moves), flushed again. Deleting first and writing
            # after left a window where the file pointed past its end (issue 30: 'addr overflow'
            # on receivers/u after a SIGKILL at -n 2).
            names = ("topology", "time", "receivers") + tuple(groups or ())
            if STAGE in f:
                del f[STAGE]
            st = _group(f, STAGE)
            if self.cells is not None:
                st.create_dataset("topology", data=self.cells, track_times=False)
            st.create_dataset("time", data=np.asarray(self.times), track_times=False)
            for gname, data in ((("receivers", receivers),) if receivers is not None else ()) + \
                    tuple((groups or {}).items()):
                g = _group(st, gname)
                for k, v in data.items():
                    unit, extra = UNITS.get(f"{gname}/{k}"), {}
                    if isinstance(v, tuple) and len(v) == 2 and isinstance(v[1], str):
                        v, unit = v                     # (array, unit): the unit as an attribute
                    elif isinstance(v, tuple) and len(v) == 3 and isinstance(v[1], str):
                        v, unit, extra = v              # (array, unit, {attribute: value})
                    d = g.create_dataset(k, data=np.asarray(v), track_times=False)
                    if unit is not None:
                        d.attrs["unit"] = unit
                    for ak, av in extra.items():
                        d.attrs[ak] = av
            f.flush()
            for name in names:
                if name in f:
                    del f[name]
                if name in st:
                    f.move(f"{STAGE}/{name}", name)
            del f[STAGE]
            f.attrs["run_status"] = status
            f.attrs["run_id"] = self.run_id
            f.attrs["cell_type"] = self.cell_type or ""
            f.attrs["fields"] = ",".join(self.fields)
            f.attrs["n_snapshots"] = len(self.times)
            from .. import __version__
            f.attrs["petsc_ssi_version"] = __version__
            for k, v in (attrs or {}).items():
                f.attrs[k] = v
            self._field_units(f, (attrs or {}).get("time_is"))
            f.flush()
            self.cell_attributes = []
            for w in self.writers:
                self.cell_attributes += w.write_serial(f)
        if final and (self.deterministic or compactable(self.path)):
            rewrite_without_times(self.path)        # also gives back the space earlier flushes freed
        self._write_xdmf()
        if record is not None:
            record = dict(record, run_status=status)
            tmp = os.path.splitext(self.path)[0] + ".json.tmp"
            with open(tmp, "w") as fh:
                json.dump(record, fh, indent=1, sort_keys=True, default=str)
            os.replace(tmp, os.path.splitext(self.path)[0] + ".json")

    def _field_units(self, f, time_is=None):
        """Rank 0: ``unit`` attributes of the datasets the PETSc viewer wrote (coordinates and the
        snapshots' fields, UNITS), of time and topology; snapshots already done are skipped."""
        for name, unit in (("coordinates", "m"), ("topology", "1"),
                           ("time", "1 (" + time_is + ")" if time_is else "s")):
            if name in f and f[name].attrs.get("unit") != unit:
                f[name].attrs["unit"] = unit
        done = getattr(self, "_units_done", 0)
        for k in range(done, len(self.times)):
            for name in self.fields:
                d = f.get(f"{name}_{k:06d}")
                if d is not None:
                    d.attrs["unit"] = UNITS.get(name, "")
        self._units_done = len(self.times)

    def _write_xdmf(self):
        if self.cells is None:
            return
        from xml.sax.saxutils import escape
        base = escape(os.path.basename(self.path))      # '&', '<', '>' in a file name: valid XML
        ne = self.n_cells
        nn = self.n_nodes
        if self.cell_type == "mixed":
            topo = (f'<Topology TopologyType="Mixed" NumberOfElements="{ne}">'
                    f'<DataItem Dimensions="{self.cells.size}" NumberType="Int" Precision="8" '
                    f'Format="HDF">{base}:/topology</DataItem></Topology>')
        else:
            ctype, npc = XDMF_CELL[self.cell_type]
            topo = (f'<Topology TopologyType="{ctype}" NumberOfElements="{ne}">'
                    f'<DataItem Dimensions="{ne} {npc}" NumberType="Int" Precision="8" '
                    f'Format="HDF">{base}:/topology</DataItem></Topology>')
        lines = ['<?xml version="1.0" ?>', '<Xdmf Version="3.0">', "<Domain>",
                 '<Grid Name="TimeSeries" GridType="Collection" CollectionType="Temporal">']
        steps = range(len(self.times)) if self.times else [None]
        for k in steps:
            lines.append('<Grid Name="mesh" GridType="Uniform">')
            if k is not None:
                lines.append(f'<Time Value="{self.times[k]:.9g}"/>')
            lines.append(topo)
            lines.append(f'<Geometry GeometryType="XYZ"><DataItem Dimensions="{nn} 3" NumberType="Float" '
                         f'Precision="8" Format="HDF">{base}:/coordinates</DataItem></Geometry>')
            for name, dset, unit in self.cell_attributes:
                lines.append(f'<Attribute Name="{escape(name)}" AttributeType="Scalar" Center="Cell">'
                             f'<DataItem Dimensions="{ne}" NumberType="Float" Precision="8" Format="HDF">'
                             f'{base}:/{escape(dset)}</DataItem></Attribute>')
            if k is not None:
                for name in self.fields:
                    lines.append(f'<Attribute Name="{name}" AttributeType="Vector" Center="Node">'
                                 f'<DataItem Dimensions="{nn} 3" NumberType="Float" Precision="8" '
                                 f'Format="HDF">'
                                 f'{base}:/{name}_{k:06d}</DataItem></Attribute>')
            lines.append("</Grid>")
        lines += ["</Grid>", "</Domain>", "</Xdmf>"]
        tmp = os.path.splitext(self.path)[0] + ".xmf.tmp"
        with open(tmp, "w") as fh:
            fh.write("\n".join(lines) + "\n")
        os.replace(tmp, os.path.splitext(self.path)[0] + ".xmf")


_GIT = []


def _git_revision():
    """``git describe --always --dirty`` of the package (once per process)."""
    if not _GIT:
        try:
            here = os.path.dirname(os.path.abspath(__file__))
            _GIT.append(subprocess.run(["git", "-C", here, "describe", "--always", "--dirty"],
                                       capture_output=True, text=True, timeout=5).stdout.strip())
        except Exception:  # noqa: BLE001 -- not a git checkout, no git
            _GIT.append("")
    return _GIT[0]


def provenance(cfg, comm, extra=None):
    """The run record: resolved options, library versions, git revision, ranks."""
    PETSc = init()
    import petsc4py
    import mpi4py
    from mpi4py import MPI
    rec = {"options": cfg.as_dict() if cfg is not None else {},
           "option_sources": cfg.sources() if cfg is not None else {},
           "petsc": ".".join(map(str, PETSc.Sys.getVersion())),
           "petsc4py": petsc4py.__version__, "mpi4py": mpi4py.__version__,
           "mpi": MPI.Get_library_version().splitlines()[0].strip(),
           "ranks": comm.getSize(), "python": platform.python_version(),
           "date": _time.strftime("%Y-%m-%dT%H:%M:%S"), "host": platform.node()}
    try:
        import h5py
        rec["hdf5"] = h5py.version.hdf5_version
    except ImportError:
        pass
    try:
        import gmsh
        rec["gmsh"] = gmsh.__version__
    except Exception:  # gmsh is optional for runs on structured meshes
        pass
    rec["git"] = _git_revision()
    if extra:
        rec.update(extra)
    return rec
