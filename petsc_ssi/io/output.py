"""Output: fields through the PETSc HDF5 viewer, an XDMF file for ParaView,
and a JSON provenance record beside them.

Layout of ``FILE.h5`` (flat dataset names, so the same file is written by
petsc4py 3.18, whose HDF5 viewer has no group/timestepping calls, and newer):

  coordinates            (N, 3)  node coordinates           [PETSc Vec, bs 3]
  <field>_<k:06d>        (N, 3)  nodal field at snapshot k  [PETSc Vec, bs 3]
  topology               (E, n)  cell connectivity (0-based)        [rank 0]
  time                   (K,)    time of snapshot k                 [rank 0]
  receivers/...          receiver series (see ``write_receivers``)  [rank 0]
  (writers)              more data of ``Output.writers`` (e.g. fem/forces.py's member forces:
                         distributed Vecs through the viewer before it closes, then rank 0's
                         h5py work, which may name cell fields: XDMF Center="Cell" attributes)
  attrs: cell_type, fields, n_snapshots, petsc_ssi_version, run_status, run_id (shared with
         the run's checkpoints: a restart continues only the output of its own run)

Distributed fields are written collectively by the PETSc viewer; the small
serial data (topology, time, receiver series) by rank 0 with h5py after the
viewer is closed. While the run goes on, the viewer's datasets live in parts
(``<stem>.parts/``, new HDF5 files closed at each flush and never written again)
and ``FILE.h5``, written anew and renamed at each flush, links to them; the final
close puts every dataset into ``FILE.h5`` and removes the parts (``Output``).
Rank-0-only file work never leaves the other ranks waiting:
an error there is caught, passed to every rank (``petsc.collective_error``)
and raised everywhere as the same one-line SSIError. ``FILE.xmf`` (XDMF 3, temporal collection) is written on
rank 0 so ParaView opens the result; ``FILE.json`` holds the resolved options,
library versions, git revision and number of ranks (PyLith's habit).
"""
import json
import os
import platform
import re
import subprocess
import time as _time

import numpy as np

from ..petsc import init, collective, collective_error, collective_io, ensure_space, SSIError

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
    "interface/uf_check": "m", "interface/uff": "m", "interface/p": "N/m^2", "interface/pff": "N/m^2",
    "interface/gap": "m",
    "interface/pN": "N/m^2", "interface/closed": "1", "interface/n_open": "1", "interface/iterations": "1",
    "interface/changes": "1", "interface/force_fe": "N", "interface/force_be": "N", "interface/moment_fe": "N m",
    "interface/moment_be": "N m", "interface/bem_residual": "1", "interface/force_map_error": "N",
    "interface/nodal_steps": "1", "interface/t_nodal": "s",
    "resultants/t": "s", "resultants/force": "N", "resultants/moment": "N m (about resultants/x_ref)",
    "resultants/h": "1 (the prescribed motion's factor at t)", "resultants/u0": "m", "resultants/theta0": "rad",
    "resultants/x_ref": "m",
}


def output_files(path):
    """The files a run with -ssi_output ``path`` writes: the HDF5 file and its sidecars."""
    stem = os.path.splitext(path)[0]
    return [path] + [stem + s for s in SIDECARS]


def file_keys(path):
    """What the file ``path`` is, to compare two names of files (never by ``os.path.abspath``, which
    sees two names of one file through a symbolic link, a linked directory or a hard link as two
    files): its real path (links and '..' resolved) and, when it exists, its device and inode."""
    keys = {("path", os.path.realpath(path))}
    try:
        st = os.stat(path)
        keys.add(("inode", st.st_dev, st.st_ino))
    except OSError:
        pass
    return keys


def missing_part(path):
    """Rank 0's phrase for the first dataset of the output ``path`` that links (HDF5 external link) to
    a part that is not there (a running or stopped run's output whose parts directory lost a file), or
    None (also when ``path`` does not exist or holds its datasets itself)."""
    import h5py
    if not os.path.isfile(path):
        return None
    d = os.path.dirname(os.path.abspath(path))
    with _h5(path, "r") as f:
        for name in f:
            ln = f.get(name, getlink=True)
            if isinstance(ln, h5py.ExternalLink) and not os.path.isfile(os.path.join(d, ln.filename)):
                return (f"{path} links its dataset {name} to {ln.filename}, which is missing: the file and its "
                        "parts directory go together")
    return None


def same_file(a, b):
    """Whether the names ``a`` and ``b`` are one file (``file_keys``)."""
    return bool(file_keys(a) & file_keys(b))


def remove_output(path):
    """Rank 0: a scratch run's output gone: FILE.h5, its sidecars and its parts directory."""
    import shutil
    for f in output_files(path):
        if os.path.isfile(f):
            os.remove(f)
    if os.path.isdir(parts_dir(path)):
        shutil.rmtree(parts_dir(path), ignore_errors=True)


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
        d_parts = parts_dir(p)
        if err is None and os.path.lexists(d_parts):
            if not os.path.isdir(d_parts) or os.path.islink(d_parts):
                err = f"{what} {p}: {d_parts} (where the run keeps its parts) exists and is not a directory"
            elif not overwrite:
                err = (f"{what} {p}: {d_parts} exists (the parts of an earlier run); add -ssi_output_overwrite "
                       f"to replace it, or choose another {what}")
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


def new_group(parent, name):
    """A new HDF5 group without modification times (h5py's create_group cannot say so)."""
    import h5py
    gcpl = h5py.h5p.create(h5py.h5p.GROUP_CREATE)
    gcpl.set_obj_track_times(False)
    return h5py.Group(h5py.h5g.create(parent.id, name.encode(), gcpl=gcpl))


def view_vecs(viewer, vecs):
    """Collective: Vecs {dataset name: Vec} through a PETSc HDF5 viewer, each under that name (the
    Vec's own name kept)."""
    for name, vec in vecs.items():
        old = vec.getName()
        vec.setName(name)
        try:
            vec.view(viewer)
        finally:
            vec.setName(old)


def parts_dir(path):
    """The directory of a running output's parts: ``<stem>.parts`` beside ``FILE.h5``."""
    return os.path.splitext(path)[0] + ".parts"


MERGE_EVERY = 16         # a flush merges the last 16 parts of one level into one part of the next
_FROZEN = 99             # the level of a part a restart adopted (never merged again)


def _part_number(rel):
    """The number of a part's file name (p000012.h5, m1-000017.h5, r000005.h5), or -1."""
    m = re.search(r"(\d+)\.h5$", os.path.basename(rel))
    return int(m.group(1)) if m else -1


def _snapshot_number(name):
    """k of a snapshot's dataset name '<field>_<k:06d>' (also the member forces'), or -1."""
    m = re.search(r"_(\d{6})$", name)
    return int(m.group(1)) if m else -1


def _fsync(path):
    """``path``'s bytes (a file or a directory) on the disk before what follows (a rename)."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:                              # a file system without fsync on directories
        pass
    finally:
        os.close(fd)


def _new_file(path):
    """A new HDF5 file (truncated) whose objects carry no modification times: the same data give
    the same bytes (PETSc's viewer has no switch for this; h5py's create_group has none either)."""
    import h5py
    fcpl = h5py.h5p.create(h5py.h5p.FILE_CREATE)
    fcpl.set_obj_track_times(False)
    return h5py.File(h5py.h5f.create(path.encode(), h5py.h5f.ACC_TRUNC, fcpl=fcpl))


def _copy_dataset(src, dst, name, slab=1 << 26):
    """Rank 0: dataset ``src`` (any file) as ``dst[name]``, its data and attributes, no times; read
    and written in slabs of rows of about ``slab`` bytes (a snapshot of a large mesh is not held
    whole on rank 0)."""
    if src.ndim == 0 or src.size * src.dtype.itemsize <= slab:
        d = dst.create_dataset(name, data=src[()], track_times=False)
    else:
        d = dst.create_dataset(name, shape=src.shape, dtype=src.dtype, track_times=False)
        rows = max(1, int(slab // max(1, src[0:1].nbytes)))
        for i in range(0, src.shape[0], rows):
            d[i:i + rows] = src[i:i + rows]
    for k, v in src.attrs.items():
        d.attrs[k] = v
    return d


def _tmp_gone(tmp):
    """Rank 0: a temporary file of a failed write removed (its retry writes another)."""
    try:
        os.remove(tmp)
    except OSError:
        pass


def _h5(path, mode):
    """h5py.File without HDF5's file locking where the library allows (a reader may hold it)."""
    import h5py
    try:
        return h5py.File(path, mode, locking=False)
    except (TypeError, ValueError):            # h5py < 3.5, or an HDF5 without the locking switch
        return h5py.File(path, mode)


class Output:
    """Collective writer of one run's fields and series.

    Nothing that a flush made readable is ever written to again, so a kill at any moment (SIGKILL,
    a lost node) leaves the last flush whole (issue 30; HDF5 updates its metadata in place, and a
    kill inside such an update tore the file): the distributed datasets go through the PETSc
    viewer into *parts*, new HDF5 files in ``<stem>.parts/``, one per flush interval that wrote
    any; a flush closes the current part and rank 0 then writes ``FILE.h5`` anew beside it (the
    series, the attributes and an HDF5 external link per dataset of the parts) and renames it over
    the old one. A reader opens ``FILE.h5`` as usual (h5py and ParaView follow the links). Every
    ``MERGE_EVERY`` parts of one level are copied into one part of the next (so a long run keeps
    few files), and the final close writes ``FILE.h5`` with every dataset in it and removes the
    parts."""

    def __init__(self, path, comm, resume=None, run_id=""):
        """``run_id``: the run's id (``TransientProblem.run_id``), the attribute ``run_id`` of the
        file, which a restart compares with its checkpoint's. ``resume``: the snapshot list of an interrupted run ({'times', 'fields'}, a checkpoint's):
        its file is continued (its datasets kept, where they are; later snapshots replace those the
        interrupted run wrote after its checkpoint); a missing file is started anew, with a warning."""
        PETSc = init()
        self.PETSc = PETSc
        self.path = path
        self.comm = comm
        self.rank = comm.getRank()
        self.run_id = run_id or ""
        self.dir = os.path.dirname(os.path.abspath(path))
        self.parts = parts_dir(path)
        self._rank0(lambda: os.makedirs(self.dir, exist_ok=True), f"cannot create the output directory {self.dir}")
        self.times = []
        self.fields = []
        self.links = {}          # dataset name -> its part (path relative to the output's directory)
        self.part_list = []      # [[part, level]] in the order written
        self.seq = 0             # the next part's number
        self.final = False       # the file being written is the final one (every dataset in it)
        self.viewer = None       # the open part's viewer, or None
        self._written = []       # the datasets of the open part
        self.closed = False      # the final close is done (a flush after it does nothing)
        # -ssi_output_merge 0: the final FILE.h5 keeps linking its parts (no copy at the end)
        self.merge = PETSc.Options().getBool("ssi_output_merge", True)
        fresh = True
        if resume is not None:
            exists = comm.tompi4py().bcast(os.path.isfile(path) if self.rank == 0 else None, root=0)
            if exists:
                fresh = False
                self.times = [float(t) for t in resume["times"]]
                self.fields = [f for f in resume["fields"].split(",") if f]
                self._adopt()
            elif len(resume["times"]):
                from ..petsc import warn
                warn(f"{path} (the output of the interrupted run) is missing: a new one is written, without the "
                     f"{len(resume['times'])} field snapshots before the restart (the receiver series are whole)", comm)
        if fresh:
            self._rank0(self._stale, f"cannot remove the old sidecars and parts of {path}")
        self.cells = None
        self.cell_type = None
        self.n_nodes = 0
        # writers of more data (e.g. fem.forces.ForceRecorder): write_collective(out) before the
        # part closes, write_serial(h5 file) on rank 0 -> XDMF cell attributes [(name, dataset, unit)]
        self.writers = []
        self.cell_attributes = []

    def _stale(self):
        """Rank 0: an older run's file, sidecars and parts must not describe this run's."""
        remove_output(self.path)

    def _adopt(self):
        """Collective: the datasets of the interrupted run's file (a restart), on every rank: its
        external links stay where they point; a file that holds its datasets itself (a finished or
        stopped run's, or one written by a version before the parts) becomes a part, hard-linked
        (copied where the file system has no hard links) into the parts directory."""
        def work():
            import shutil
            import h5py
            links, parts = {}, []
            with _h5(self.path, "r") as f:
                own = []
                for name in f:
                    ln = f.get(name, getlink=True)
                    if isinstance(ln, h5py.ExternalLink):
                        if not os.path.isfile(os.path.join(self.dir, ln.filename)):
                            raise SSIError(f"{self.path} links its dataset {name} to {ln.filename}, which is "
                                           f"missing: the file and its parts directory go together")
                        links[name] = ln.filename
                        if ln.filename not in parts:
                            parts.append(ln.filename)
                    elif isinstance(f.get(name), h5py.Dataset) and name not in ("topology", "time") \
                            and not name.startswith("cell_peak_"):
                        own.append(name)
            # snapshots the interrupted run wrote after its checkpoint: not this run's (later ones replace them)
            stale = [n for n in list(links) + own if _snapshot_number(n) >= len(self.times)]
            for n in stale:
                links.pop(n, None)
            own = [n for n in own if n not in stale]
            parts = [p for p in parts if p in links.values()]
            present = os.listdir(self.parts) if os.path.isdir(self.parts) else []
            seq = 1 + max([_part_number(p) for p in parts + present] + [-1])   # no name used before
            if own:
                os.makedirs(self.parts, exist_ok=True)
                rel = os.path.join(os.path.basename(self.parts), f"r{seq:06d}.h5")
                dst = os.path.join(self.dir, rel)
                try:
                    os.link(self.path, dst)
                except OSError:
                    shutil.copyfile(self.path, dst)
                parts.append(rel)
                links.update({name: rel for name in own})
                seq += 1
            return links, parts, seq
        box = []
        self._rank0(lambda: box.append(work()), f"reading {self.path} to continue it")
        links, parts, seq = self.comm.tompi4py().bcast(box[0] if box else None, root=0)
        self.links, self.seq = links, seq
        self.part_list = [[p, _FROZEN] for p in parts]

    def state(self):
        """The snapshot list, for a checkpoint: {'times', 'fields'}."""
        return {"times": np.asarray(self.times, float), "fields": ",".join(self.fields)}

    def source_of(self, name):
        """The file that holds dataset ``name`` as seen from FILE.h5 (an HDF5 virtual dataset's
        source): '.' in the final file, else its part."""
        return "." if self.final else self.links.get(name, ".")

    def _part(self):
        """Collective: the open part's viewer (a new part opened when none is)."""
        if self.viewer is None:
            rel = os.path.join(os.path.basename(self.parts), f"p{self.seq:06d}.h5")
            self.seq += 1
            self._rank0(lambda: os.makedirs(self.parts, exist_ok=True), f"cannot create {self.parts}")
            self._open = rel
            self._written = []
            self.viewer = self.PETSc.Viewer().createHDF5(os.path.join(self.dir, rel), mode="w", comm=self.comm)
        return self.viewer

    def _view(self, vecs, what):
        """Collective: Vecs {dataset name: Vec} into the open part (a Vec of block size c gives an
        (n / c, c) dataset)."""
        viewer = self._part()
        collective_io(lambda: view_vecs(viewer, vecs), what, self.comm)
        self._written += [n for n in vecs if n not in self._written]

    def write_mesh(self, coords_vec, cells, cell_type):
        """``coords_vec``: PETSc Vec (bs 3) of node coordinates in the field
        layout; ``cells``: (E, n) int array, needed on rank 0 only; or, with
        ``cell_type`` 'mixed', a list [(xdmf type name, (E, n) cells)] of blocks
        (written as one XDMF Mixed topology)."""
        self._view({"coordinates": coords_vec}, f"writing {self.path}")
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
        self._view({f"{name}_{k:06d}": vec for name, vec in fields.items()},
                   f"writing {self.path} (snapshot {k}, t = {t:.6g} s)")
        for name in fields:
            if name not in self.fields:
                self.fields.append(name)
        self.times.append(float(t))

    def write_vecs(self, vecs, what):
        """Collective: distributed Vecs {dataset name: Vec} through the viewer (a Vec of block
        size c gives an (n / c, c) dataset; a dataset of that name written before is replaced)."""
        ensure_space(self.path, 8.0 * sum(v.getSize() for v in vecs.values()), self.comm, what)
        self._view(vecs, f"writing {self.path} ({what})")

    def close(self, receivers=None, attrs=None, record=None, groups=None, status="completed", final=True):
        """Collective: close the open part, then rank 0 writes FILE.h5 (the serial data, the
        links or, ``final``, every dataset) and the XDMF and JSON files. ``receivers``: dict with 'points'
        (R,3), 'nodes' (R,) optional, 't' (K,), 'u' (K,R,3), on rank 0.
        ``groups``: {group: {name: array, (array, unit) or (array, unit, {attribute: value})}}
        more serial data (rank 0). ``status``: how the run
        ended (the file's attribute ``run_status`` and the record's)."""
        if self.closed:
            return
        for w in self.writers:
            w.write_collective(self)
        self._seal()
        closing, room = final, True
        if final and self.links and not self.merge:
            final = False                       # -ssi_output_merge 0: FILE.h5 keeps linking its parts
        elif final and self.links and not self._room_to_copy():
            final = room = False                # FILE.h5 keeps linking its parts
        # merges only in a running flush: not at a stop (the kill that follows a signal leaves little
        # time) nor when the disk has no room
        merged = self._merge() if not final and room and status == "running" else []
        self.final = final
        try:
            self._rank0(lambda: self._write_serial(receivers, attrs, record, groups, status, final),
                        f"writing {self.path}")
        finally:
            self.final = False
        if merged or final:
            self._rank0(lambda: self._remove(merged, final), f"removing the merged parts of {self.path}")
        self.closed = closing

    def flush(self, receivers=None, attrs=None, record=None, groups=None, status="running"):
        """Collective: make the file readable as it stands (a run killed or stopped later keeps
        it): the open part closed, rank 0 writes time, topology, receivers, groups, the attributes
        with ``run_status``, links to the parts and the sidecars; the next write opens a new part."""
        self.close(receivers, attrs, record, groups, status, final=False)

    def _room_for(self, parts):
        """Collective: (whether the output's file system has room for a copy of ``parts``: their
        bytes, 10 % and 1 MB more, while they still exist), the same on every rank."""
        import shutil
        need, free = 0.0, 0.0
        if self.rank == 0:
            for rel in set(parts):
                f = os.path.join(self.dir, rel)
                need += os.path.getsize(f) if os.path.isfile(f) else 0.0
            need = 1.1 * need + 1e6
            free = float(shutil.disk_usage(self.dir).free)
        self._need = self.comm.tompi4py().bcast((need, free), root=0)
        return self._need[0] <= self._need[1]

    def _room_to_copy(self):
        """Collective: whether the output's file system has room for the final copy of the parts
        into FILE.h5; else a warning: FILE.h5 stays linked to its parts."""
        if self._room_for(self.links.values()):
            return True
        need, free = self._need
        from ..petsc import warn
        warn(f"{self.path}: {free / 1e6:.3g} MB free, too little to copy its parts ({need / 1e6:.3g} MB) into it: it "
             f"links to them in {self.parts} (keep the two together)", self.comm)
        return False

    def _seal(self):
        """Collective: the open part closed, finished by rank 0 (the units of its datasets, its
        bytes on the disk) before FILE.h5 names it."""
        if self.viewer is None:
            return
        viewer, self.viewer = self.viewer, None
        collective_io(viewer.destroy, f"closing {self.path}'s part {self._open}", self.comm)
        rel, names = self._open, list(self._written)

        def finish():
            full = os.path.join(self.dir, rel)
            with _h5(full, "a") as f:
                for name in names:
                    unit = self._unit(name)
                    if unit is not None:
                        f[name].attrs["unit"] = unit
            _fsync(full)
            _fsync(self.parts)
        try:
            self._rank0(finish, f"writing {rel}")
        finally:                                  # the viewer wrote it whole: named even without its units
            self.links.update({name: rel for name in names})
            self.part_list.append([rel, 0])

    def _merge(self):
        """Collective: while the last MERGE_EVERY parts have one level, rank 0 copies them (later
        datasets over earlier ones) into one new part of the next level, which their links then
        name. Returns the parts replaced (removed once FILE.h5 no longer names them)."""
        gone = []
        while len(self.part_list) >= MERGE_EVERY:
            last = self.part_list[-MERGE_EVERY:]
            level = last[0][1]
            if level == _FROZEN or any(p[1] != level for p in last):
                break
            olds = [p[0] for p in last]
            if not self._room_for(olds):
                break                             # merging can wait: the parts stay as they are
            rel = os.path.join(os.path.basename(self.parts), f"m{level + 1}-{self.seq:06d}.h5")
            self.seq += 1
            names = [(n, r) for n, r in self.links.items() if r in olds]

            def work():
                full = os.path.join(self.dir, rel)
                tmp = full + ".tmp"
                try:
                    with _new_file(tmp) as dst:
                        self._copy_parts(dst, names)
                    _fsync(tmp)
                    os.replace(tmp, full)
                    _fsync(self.parts)
                except BaseException:
                    _tmp_gone(tmp)
                    raise
            self._rank0(work, f"merging {len(olds)} parts of {self.path}")
            self.links.update({n: rel for n, _ in names})
            self.part_list[-MERGE_EVERY:] = [[rel, level + 1]]
            gone += olds
        return gone

    def _copy_parts(self, dst, items):
        """Rank 0: the datasets [(name, part)] copied from their parts into the open file ``dst``,
        in name order (the same data give the same bytes, restarted or not)."""
        srcs = {}
        try:
            for name, rel in sorted(items):
                if rel not in srcs:
                    srcs[rel] = _h5(os.path.join(self.dir, rel), "r")
                _copy_dataset(srcs[rel][name], dst, name)
        finally:
            for f in srcs.values():
                f.close()

    def _remove(self, merged, final):
        """Rank 0: parts FILE.h5 no longer names (after it was replaced); all of them when final."""
        import shutil
        if final:
            if os.path.isdir(self.parts):
                shutil.rmtree(self.parts)
            return
        for rel in merged:
            f = os.path.join(self.dir, rel)
            if os.path.isfile(f):
                os.remove(f)

    def _rank0(self, work, what):
        """Collective: ``work()`` on rank 0; an exception there is raised on every rank as a
        one-line SSIError (the allgather of collective_error is also the barrier)."""
        with collective(self.comm, what, "{what}: {error}"):
            if self.rank == 0:
                work()

    def _write_serial(self, receivers, attrs, record, groups=None, status="completed", final=True):
        """Rank 0: FILE.h5 written anew beside the old one and renamed over it (a kill leaves one or
        the other whole): links to the parts' datasets (or, final, the datasets themselves),
        topology, time, attributes and receivers; XDMF; JSON."""
        tmp = self.path + ".part.tmp"
        try:
            self._write_file(tmp, receivers, attrs, groups, status, final)
            _fsync(tmp)
            os.replace(tmp, self.path)
        except BaseException:
            _tmp_gone(tmp)
            raise
        _fsync(self.dir)
        self._write_xdmf()
        if record is not None:
            record = dict(record, run_status=status)
            tmp = os.path.splitext(self.path)[0] + ".json.tmp"
            with open(tmp, "w") as fh:
                json.dump(record, fh, indent=1, sort_keys=True, default=str)
            os.replace(tmp, os.path.splitext(self.path)[0] + ".json")

    def _write_file(self, tmp, receivers, attrs, groups, status, final):
        """Rank 0: the new FILE.h5 as ``tmp`` (the datasets in name order: a restarted run's file is
        the same bytes as an uninterrupted one's)."""
        import h5py
        with _new_file(tmp) as f:
            if final:
                self._copy_parts(f, self.links.items())
            else:
                for name, rel in sorted(self.links.items()):
                    f[name] = h5py.ExternalLink(rel, "/" + name)
            if self.cells is not None:
                f.create_dataset("topology", data=self.cells, track_times=False)
            f.create_dataset("time", data=np.asarray(self.times), track_times=False)
            for gname, data in ((("receivers", receivers),) if receivers is not None else ()) + \
                    tuple((groups or {}).items()):
                g = new_group(f, gname)
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
            self.cell_attributes = []
            for w in self.writers:
                self.cell_attributes += w.write_serial(f)

    def _field_units(self, f, time_is=None):
        """Rank 0: ``unit`` attributes of FILE.h5's own time and topology (the parts' datasets got
        theirs when their part was closed: ``_unit``)."""
        for name, unit in (("topology", "1"), ("time", "1 (" + time_is + ")" if time_is else "s")):
            if name in f:
                f[name].attrs["unit"] = unit

    def _unit(self, name):
        """The ``unit`` attribute of a dataset the viewer wrote: coordinates, a snapshot's field
        (UNITS; '' for a field without one), else None (the writer's own datasets)."""
        if name == "coordinates":
            return "m"
        field = name.rsplit("_", 1)[0]
        return UNITS.get(field, "") if field in self.fields else None

    def _write_xdmf(self):
        if self.cells is None:
            return
        from xml.sax.saxutils import escape
        base = escape(os.path.basename(self.path))      # '&', '<', '>' in a file name: valid XML

        def where(name):
            """A viewer dataset's file and path: its part while the run goes on (ParaView's XDMF
            reader does not follow HDF5's external links), FILE.h5 once final."""
            rel = self.source_of(name)
            return f"{base if rel == '.' else escape(rel)}:/{name}"
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
                         f'Precision="8" Format="HDF">{where("coordinates")}</DataItem></Geometry>')
            for name, dset, unit in self.cell_attributes:
                lines.append(f'<Attribute Name="{escape(name)}" AttributeType="Scalar" Center="Cell">'
                             f'<DataItem Dimensions="{ne}" NumberType="Float" Precision="8" Format="HDF">'
                             f'{base}:/{escape(dset)}</DataItem></Attribute>')
            if k is not None:
                for name in self.fields:
                    lines.append(f'<Attribute Name="{name}" AttributeType="Vector" Center="Node">'
                                 f'<DataItem Dimensions="{nn} 3" NumberType="Float" Precision="8" '
                                 f'Format="HDF">'
                                 f'{where(f"{name}_{k:06d}")}</DataItem></Attribute>')
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


def provenance(cfg, comm, extra=None, grid=None):
    """The run record: resolved options, library versions, git revision, ranks; with ``grid`` (the
    run's ``timegrid.TimeGrid``) its step, end and steps under 'time_grid' (a run under a record
    without -ssi_t_end lasts the record: the options keep what the user gave)."""
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
    if grid is not None:
        rec["time_grid"] = {"dt_s": grid.dt, "t_end_s": grid.time(grid.n_steps), "n_steps": grid.n_steps}
    if extra:
        rec.update(extra)
    return rec
