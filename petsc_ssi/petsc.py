"""Start-up of petsc4py and small collective helpers.

``init()`` must be called before ``from petsc4py import PETSc`` anywhere, so
that command-line options reach the PETSc options database (petsc4py demos,
PyLith). Nothing here captures MPI state at import time.
"""
import contextlib
import importlib
import sys
import traceback

_INITIALISED = False


def _find_debian_petsc4py():
    """Debian's petsc4py lives under $PETSC_DIR/lib/python3/dist-packages and
    its .pth file finds it only when PETSC_DIR is set; without it, look for
    the installed real-scalar build ourselves (and set PETSC_DIR/SLEPC_DIR)."""
    import glob
    import os
    for d in sorted(glob.glob("/usr/lib/petscdir/petsc*/*-real"), reverse=True):
        sp = os.path.join(d, "lib", "python3", "dist-packages")
        if os.path.isdir(os.path.join(sp, "petsc4py")):
            os.environ.setdefault("PETSC_DIR", d)
            sys.path.append(sp)
            for s in sorted(glob.glob("/usr/lib/slepcdir/slepc*/*-real"), reverse=True):
                os.environ.setdefault("SLEPC_DIR", s)
                ssp = os.path.join(s, "lib", "python3", "dist-packages")
                if os.path.isdir(ssp):
                    sys.path.append(ssp)
                break
            return True
    return False


def _pin_mmap_threshold(nbytes=256 << 10):
    """glibc raises its mmap threshold after large blocks are freed, after
    which mid-size arrays (the per-lag triplet pieces of the BEM assembly) come
    from the heap and, once freed, are neither returned to the system nor
    reused for PETSc's matrices: the paper case then needed 20 GB where 8 GB of
    matrices were stored. A fixed threshold keeps blocks >= 256 KiB mapped, so
    freeing them really frees memory. No-op where mallopt is not available."""
    try:
        import ctypes
        libc = ctypes.CDLL("libc.so.6")
        M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
        libc.mallopt(M_MMAP_THRESHOLD, int(nbytes))
        libc.mallopt(M_TRIM_THRESHOLD, int(nbytes))
    except (OSError, AttributeError):
        pass


def set_huge_pages(mode):
    """numpy's transparent-huge-page advice for the arrays it allocates from now on (-ssi_huge_pages):
    'off', 'on', or 'numpy' and 'auto' (left as it is: numpy's default, on unless
    NUMPY_MADVISE_HUGEPAGE=0, where nothing in the process changed it; with 'auto' the BEM's lag
    arrays are given small pages where ``sysmem.free_page_reporting``: ``lag_small_pages``).
    numpy (1.18 on, Linux) asks the kernel with
    madvise(MADV_HUGEPAGE) to back every array of 4 MB and more by 2 MB pages (arrays numba allocates
    inside compiled code are not numpy's: the element cache's pools keep the kernel's default);
    where the kernel then compacts memory on the spot (transparent_hugepage/defrag
    'madvise'), or where a virtual machine hands free 2 MB blocks back to its host (free page
    reporting), first writes stall erratically (jobscripts/first_touch.py, jobscripts/README.md's
    first-touch section). Returns the advice in
    effect (True/False), or None where this numpy has no such switch (then nothing changes)."""
    if mode not in ("off", "on", "numpy", "auto"):
        raise SSIError(f"-ssi_huge_pages {mode}: expected auto, off, on or numpy")
    ma = None
    for name in ("numpy._core.multiarray", "numpy.core.multiarray"):
        try:
            ma = importlib.import_module(name)
        except ImportError:
            continue
        if hasattr(ma, "_set_madvise_hugepage") and hasattr(ma, "_get_madvise_hugepage"):
            break
        ma = None
    if ma is None:
        return None
    if mode in ("on", "off"):
        ma._set_madvise_hugepage(mode == "on")
    return bool(ma._get_madvise_hugepage())


def lag_small_pages(mode):
    """Whether the BEM's lag arrays are to be backed by small (4 kB) pages under -ssi_huge_pages
    ``mode``: with 'auto' (the default), where this machine's balloon hands free memory back to its
    host (``sysmem.free_page_reporting``), since there a huge page's first write costs two to four
    times a small page's and the assembly writes every stored block into fresh memory (the paper's
    Lamb case on the development VM: assembly 5.2-7.2 s in 14 runs against 9.3-10.2 s in 6, the
    history sum up to 0.3 s slower from the small pages' address translation: jobscripts/README.md's
    first-touch section); 'off' too. With 'on' and 'numpy' they follow numpy's advice."""
    if mode == "off":
        return True
    if mode != "auto":
        return False
    from .sysmem import free_page_reporting
    return free_page_reporting()


def release_memory():
    """Return freed heap memory to the system (glibc malloc_trim: ``sysmem.release_freed``). The BEM
    frees its triplets lag by lag while building the Mats; without trimming, glibc keeps the freed
    pages and the paper case peaked at 20 GB where the Mats needed 7 GB (measured: trimming cut RSS
    from 7.8 to 2.7 GB on a reduced case). Cheap, and a no-op where glibc is not there."""
    from .sysmem import release_freed
    release_freed()


def init(argv=None):
    """Initialise petsc4py with ``argv`` (default ``sys.argv``); idempotent."""
    global _INITIALISED
    if not _INITIALISED:
        _pin_mmap_threshold()
        try:
            import petsc4py
        except ImportError:
            if not _find_debian_petsc4py():
                raise SystemExit("petsc-ssi: error: petsc4py is not installed (run 'make deps', "
                                 "or set PETSC_DIR to a PETSc build with petsc4py)")
            import petsc4py
        petsc4py.init(sys.argv if argv is None else argv)
        _INITIALISED = True
    from petsc4py import PETSc
    return PETSc


def error_line(text):
    """``text`` and its newline to standard error in one write, the buffered standard output and error flushed
    first (the log's lines before it stay before it; two ranks' lines are never run together). Every
    ``petsc-ssi: error:`` line goes this way: the log stays on standard output, the reason a run stopped on
    standard error."""
    import os
    sys.stdout.flush()
    sys.stderr.flush()
    data = (text.rstrip("\n") + "\n").encode()
    try:
        os.write(sys.stderr.fileno(), data)
    except (OSError, ValueError, AttributeError):   # no file descriptor (an in-process capture): Python's stream
        sys.stderr.write(data.decode())
        sys.stderr.flush()


class SSIError(RuntimeError):
    """An input or set-up error, raised on every rank with the same message."""


class DiskFullError(SSIError):
    """The output's file system has no room for the next write (checked before it): the run stops
    cleanly, keeping what it wrote."""


def collective_io(fn, what, comm):
    """``fn()``: PETSc viewer calls, collective. A PETSc error there (the disk filled up during the
    write, a quota, a file system gone) leaves the viewer's file unflushable and may leave the other
    ranks waiting inside an HDF5 collective: the failing rank prints one line and ends the job
    (MPI_Abort on more than one rank, which also ends ranks stuck in the collective; exit status 2
    on one). ``ensure_space`` before large writes stops cleanly in the common case instead."""
    PETSc = init()
    try:
        fn()
    except PETSc.Error as exc:
        import os
        error_line(f"petsc-ssi: error: {what} failed (PETSc error {exc.ierr} in the viewer: disk full, "
                   f"a quota or the file system; the file may be unreadable)")
        if comm.getSize() > 1:
            comm.tompi4py().Abort(2)
        os._exit(2)


def ensure_space(path, nbytes, comm, what):
    """Collective: DiskFullError on every rank if the file system of ``path`` has less than
    ``nbytes`` (plus 10 % and 1 MB for HDF5 metadata) free for this user (rank 0's statvfs; a quota
    is not seen)."""
    import os
    short = None
    if comm.getRank() == 0:
        try:
            st = os.statvfs(os.path.dirname(os.path.abspath(path)))
            free = st.f_bavail * st.f_frsize
            need = 1.1 * nbytes + 1e6
            if free < need:
                short = (f"{what}: the file system of {path} has {free / 1e6:.3g} MB free, the write needs about "
                         f"{need / 1e6:.3g} MB; the run stops here")
        except OSError:
            pass
    short = comm.tompi4py().bcast(short, root=0)
    if short:
        raise DiskFullError(short)


def comm_world():
    PETSc = init()
    return PETSc.COMM_WORLD


def collective_error(message, comm=None):
    """Collective: raise SSIError on every rank if any rank passes a message.

    Each rank passes ``None`` (all well) or a one-line message. The message of
    the lowest failing rank is broadcast so that all ranks raise the same
    error and mpirun never hangs on a rank that stopped alone.
    """
    comm = comm or comm_world()
    mpi = comm.tompi4py()
    flags = mpi.allgather(message)
    for m in flags:
        if m is not None:
            raise SSIError(m)


def one_line(exc):
    """``Type: first line of the message`` of an exception (an OSError: its strerror)."""
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    lines = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {lines[0] if lines else ''}".rstrip(": ")


# Errors of the input or of the machine, not of the code: a file that cannot be read or is damaged
# (OSError, h5py's too; bytes that do not decode; a truncated file), a failed allocation. Their
# one line says it all: no traceback unless -ssi_debug (anything else is a bug: its traceback).
USER_ERRORS = (OSError, UnicodeError, EOFError, MemoryError)


def debug():
    """Whether -ssi_debug is set (tracebacks of file and memory errors too)."""
    if not _INITIALISED:
        return False
    from petsc4py import PETSc
    try:
        return bool(PETSc.Options().getBool("ssi_debug", False))
    except Exception:  # noqa: BLE001 -- a malformed value: not debugging
        return False


@contextlib.contextmanager
def collective(comm, what, template="{what} failed on rank {rank}: {error}"):
    """Collective: run the block on every rank (work for one rank only goes under an ``if`` inside
    it) and raise the same SSIError on every rank if it failed on any (``collective_error``: the lowest
    failing rank's message; the allgather is also the barrier). An SSIError passes its message
    unchanged; any other exception (a bug, an unreadable file, MemoryError) is told as
    ``template`` (``what``, the failing ``rank``, ``error`` = ``one_line(exc)``), and a bug's
    traceback is printed on that rank's stderr (a file or memory error's, ``USER_ERRORS``, only
    with -ssi_debug: its line says it all), so nothing is lost and mpirun never hangs:

        with collective(comm, "reading the mesh"):
            mesh = read(path)          # may fail on some ranks only
    """
    comm = comm or comm_world()
    err = None
    try:
        yield
    except SSIError as exc:
        err = str(exc)
    except Exception as exc:  # noqa: BLE001 -- reaches every rank, with the traceback on stderr
        if debug() or not isinstance(exc, USER_ERRORS):
            traceback.print_exc(file=sys.stderr)        # a bug: the traceback is what to report
            sys.stderr.flush()
        err = template.format(what=what, rank=comm.getRank(), error=one_line(exc))
    collective_error(err, comm)


def check(condition, message, comm=None):
    """Collective assert: ``condition`` may differ between ranks."""
    collective_error(None if condition else message, comm)


def rank(comm=None):
    return (comm or comm_world()).getRank()


def size(comm=None):
    return (comm or comm_world()).getSize()


def printf(msg, comm=None):
    """Print from rank 0 only (PETSc.Sys.Print), flushing at once."""
    PETSc = init()
    PETSc.Sys.Print(msg, comm=comm or PETSc.COMM_WORLD)
    sys.stdout.flush()


def warn(msg, comm=None):
    printf("petsc-ssi: warning: " + msg, comm)


_APPLIED_DEFAULTS = set()


def set_default_options(prefix, defaults, log=None):
    """Insert PETSc options ``prefix+key`` only where the user set nothing.

    Returns the list of defaults applied, so the run log can say which were
    (PyLith ``Options::set``).
    """
    PETSc = init()
    opts = PETSc.Options()
    applied = []
    for key, value in defaults.items():
        name = prefix + key
        if not opts.hasName(name):
            opts.setValue(name, value)
            applied.append(f"-{name} {value}")
            _APPLIED_DEFAULTS.add(name)
    if log is not None and applied:
        log(f"  defaults applied: {' '.join(applied)}")
    return applied


def check_reproducible_solver(prefix, comm, what):
    """Collective (every rank decides alike): with ``-ssi_reproducible`` on more than one rank, one
    line when the solver options of ``prefix`` keep MUMPS's parallel factorisation, which a
    user's explicit ``-<prefix>pc_factor_mat_solver_type mumps`` does (the defaults then leave it):
    its reruns are not bitwise. Measured on the coupled case of tests/coupling/test_coupled_cli.py at
    -n 2, two reruns each: with the structure's D on MUMPS 1931 to 1944 values of the structure's
    file differed (1e-13 relative, from the second step on), whatever MUMPS's sequential analysis
    (-mat_mumps_icntl_28 1), ordering (_icntl_7 0 or 5), _icntl_13 1 or _icntl_14 100; with D on
    SuperLU_dist, or on MUMPS redundantly (whole on every rank), and the soil on either, none (the
    likely cause, not traced inside MUMPS: its parallel factorisation is scheduled dynamically and
    sums contribution blocks in the order the messages arrive). Returns whether it warned."""
    PETSc = init()
    db = PETSc.Options()
    if comm.getSize() == 1 or not db.getBool("ssi_reproducible", False):
        return False
    pc = (db.getString(prefix + "pc_type", "") or "").lower()
    pkg = (db.getString(prefix + "pc_factor_mat_solver_type", "") or "").lower()
    if pc in ("lu", "cholesky") and pkg == "mumps":
        warn(f"-ssi_reproducible: -{prefix}pc_factor_mat_solver_type mumps keeps MUMPS for {what}, whose parallel "
             "factorisation is not bitwise repeatable (reruns differ at round-off); leave it unset for SuperLU_dist, "
             f"or -{prefix}pc_type redundant -{prefix}redundant_pc_factor_mat_solver_type mumps (MUMPS on the "
             "whole matrix on every rank)", comm)
        return True
    return False


def has_package(name):
    """Whether this PETSc build has an external package (MUMPS, hypre, ...)."""
    PETSc = init()
    try:
        return bool(PETSc.Sys.hasExternalPackage(name))
    except AttributeError:  # very old petsc4py
        return True


def direct_solver_defaults(comm, soil=False):
    """KSP defaults for a factorise-once direct solve.

    MUMPS when PETSc has it; PETSc's own LU only on one rank, with a warning;
    a clear error in parallel without MUMPS or SuperLU_dist (never a silent
    fall back to a serial-only factorisation, Firedrake's rule). With
    ``-ssi_reproducible`` on more than one rank, SuperLU_dist first: MUMPS's parallel
    factorisation may sum in another order from run to run (jobscripts/rerun_determinism.sh:
    the structure's D of a coupled contact case at -n 2 gave other bits in every rerun, 1e-8 in
    u_f, and identical ones with SuperLU_dist). A coupled run has two factorisations, and two
    SuperLU_dist ones in one process corrupt PETSc 3.18's heap at exit, so there the soil's step
    matrix (``soil``) is factorised redundantly, whole on every rank, by PETSc's sequential LU
    (deterministic; the step matrix holds only the local lags 1 and 2).
    """
    PETSc = init()
    order = ("mumps", "superlu_dist")
    if comm.getSize() > 1 and PETSc.Options().getBool("ssi_reproducible", False):
        if soil and PETSc.Options().getString("ssi_problem", "bem").strip().lower() == "ssi":
            return {"ksp_type": "preonly", "pc_type": "redundant", "redundant_pc_type": "lu",
                    "redundant_pc_factor_mat_solver_type": "petsc",
                    "redundant_pc_factor_mat_ordering_type": "nd"}
        order = ("superlu_dist", "mumps")
        if not has_package("superlu_dist"):
            warn("-ssi_reproducible: this PETSc has no SuperLU_dist; MUMPS reruns may differ at round-off", comm)
    for pkg in order:
        if has_package(pkg):
            return {"ksp_type": "preonly", "pc_type": "lu",
                    "pc_factor_mat_solver_type": pkg}
    if comm.getSize() == 1:
        warn("PETSc has neither MUMPS nor SuperLU_dist: using PETSc's serial LU")
        return {"ksp_type": "preonly", "pc_type": "lu",
                "pc_factor_mat_solver_type": "petsc"}
    raise SSIError("this PETSc has no parallel direct solver (MUMPS, SuperLU_dist); "
                   "run on one rank or choose an iterative solver with -ssi_*_ksp_type/-pc_type")


# MUMPS's ordering of the soil's matrices (the step matrix, the interface region's): PETSc hands MUMPS a
# matrix of block size 3 (a node's DOFs) with ICNTL(15) = -3, MUMPS then orders the graph of the nodes,
# whose 3 x 3 blocks are half empty on a flat surface (the H pattern's zx/zy and xz/yz, not xy). The uniform
# 72 m building (jobscripts/building_uniform.sh's uniform-72 options, -ssi_bem_ksp_view ::ascii_info_detail,
# INFOG(29)): 106.4 M entries in the LU with the nodes' graph and PORD (the automatic choice of a MUMPS without
# METIS or SCOTCH, as Debian's), 77.6 M with ICNTL(15) 0 and AMD (ICNTL(7) 0; PORD without the blocks
# 92.8 M); the graded 36 m building 6.20 -> 5.77 M, the paper's Lamb quarter model 2.70 -> 1.77 M. The whole
# 72 m run (runs/building/README.md): factorisation 5.11 -> 4.31 s, step solves 20.2 -> 19.5 s, peak
# 6.07 -> 5.81 GB. A MUMPS with METIS may order better still: -ssi_bem_mat_mumps_icntl_7 5.
SOIL_MUMPS = {"mat_mumps_icntl_15": "0", "mat_mumps_icntl_7": "0"}


def soil_solver_defaults(comm):
    """``direct_solver_defaults(comm, soil=True)`` and, when that is MUMPS, the soil's ordering
    (``SOIL_MUMPS``)."""
    d = dict(direct_solver_defaults(comm, soil=True))
    if d.get("pc_factor_mat_solver_type") == "mumps":
        d.update(SOIL_MUMPS)
    return d


def mumps_failure(ksp):
    """'' or what failed in a MUMPS factorisation of the KSP's PC (INFOG(1) < 0, the same on every rank):
    PETSc does not raise it at set-up, and the solves then stop with MUMPS's INFOG(1) = -3, which does not
    name the cause (-9, -8: the workspace too small after pivoting; -13, -19: memory; -10: singular)."""
    v = _mumps_infog(ksp, 1)
    return f"MUMPS's LU failed, INFOG(1) = {v[0]}" if v and v[0] < 0 else ""


def _mumps_infog(ksp, *which):
    """(INFOG(i) for i in ``which``) of the KSP's PC's MUMPS factorisation, or None when the PC is not a
    MUMPS LU or Cholesky or this petsc4py has no MUMPS accessor."""
    pc = ksp.getPC()
    try:
        if pc.getType() not in ("lu", "cholesky") or pc.getFactorSolverType() != "mumps":
            return None
        F = pc.getFactorMatrix()
        return tuple(int(F.getMumpsInfog(i)) for i in which)
    except Exception:                   # (no MUMPS accessor in this petsc4py: nothing to say)
        return None


MUMPS_ORDERINGS = {0: "AMD", 1: "given", 2: "AMF", 3: "SCOTCH", 4: "PORD", 5: "METIS", 6: "QAMD"}


def mumps_factor_info(ksp):
    """'' or the size of a MUMPS LU of the KSP's PC and the ordering MUMPS used (INFOG(29): entries in
    the factors, negative in millions; INFOG(7)), for the run's log: the factors' bytes bound each step's
    solve."""
    v = _mumps_infog(ksp, 29, 7)
    if v is None:
        return ""
    n, o = v
    entries = -n * 1e6 if n < 0 else float(n)
    return (f"MUMPS LU, {entries / 1e6:.4g} M entries in the factors ({8 * entries / 1e9:.3g} GB), ordering "
            f"{MUMPS_ORDERINGS.get(o, o)} (INFOG(7) = {o})")


def solve_columns(ksp, template, m, fill, take, chunk=256, block=None, Q=None):
    """Collective: x_j = A^-1 b_j for j = 0 .. m-1 with the KSP's operator A. ``fill(j, b)`` writes
    right-hand side j into the Vec b (layout of ``template``), ``take(j, x)`` receives its solution
    (a Vec, valid during the call); ``block(j0, j1)``, if given, returns the local rows of the
    right-hand sides j0 .. j1-1 at once as an array (local size, j1 - j0), or None (then ``fill``).
    When the KSP is a direct solve (preonly with an LU or Cholesky
    factorisation by MUMPS, or PETSc's own on one rank) the columns are solved ``chunk`` at a time in
    one multi-right-hand-side solve of the factors (MatMatSolve: the triangular solves done for
    many columns at once, 3-10x fewer seconds than one solve per column; the solutions equal to
    round-off). Otherwise (an iterative solver, a redundant PC, SuperLU_dist) one ``ksp.solve`` per
    column, whose divergence raises SSIError. ``Q`` (an orthogonal AIJ Mat: the template's rows): the KSP's
    operator is Q^T A Q (the step matrix's mirror-symmetric blocks, ``bem.mirror``), x_j = Q (Q^T A Q)^-1 Q^T b_j."""
    PETSc = init()
    b, x = template.duplicate(), template.duplicate()
    if Q is not None:
        bq, xq = Q.createVecRight(), Q.createVecRight()

        def qsolve(bv, xv):
            Q.multTranspose(bv, bq)
            ksp.solve(bq, xq)
            Q.mult(xq, xv)
    else:
        def qsolve(bv, xv):
            ksp.solve(bv, xv)
    F = None
    pc = ksp.getPC()
    if ksp.getType() == "preonly" and pc.getType() in ("lu", "cholesky"):
        # MUMPS, and PETSc's own LU on one rank; not SuperLU_dist (-ssi_reproducible's structure
        # solver): PETSc 3.18's MatMatSolve with SuperLU_dist corrupted the heap ('double free or
        # corruption') on the demo building's structure matrix at -n 2, while a tridiagonal test
        # matrix passed
        pkg = pc.getFactorSolverType()
        if pkg == "mumps" or (pkg == "petsc" and template.getComm().getSize() == 1):
            try:
                ksp.setUp()                        # the factors of the current operator
                F = pc.getFactorMatrix()
            except PETSc.Error:
                F = None
    try:
        def rhs(j0, j1):
            """The right-hand sides j0 .. j1-1 as an array, or None (fill them one by one)."""
            blk = None if block is None else block(j0, j1)
            if blk is not None and blk.shape != (template.getLocalSize(), j1 - j0):
                raise ValueError(f"solve_columns: block({j0}, {j1}) gave shape {blk.shape}, not "
                                 f"({template.getLocalSize()}, {j1 - j0})")
            return blk

        if F is None:
            for j0 in range(0, m, chunk):
                j1 = min(m, j0 + chunk)
                blk = rhs(j0, j1)
                for j in range(j0, j1):
                    if blk is None:
                        fill(j, b)
                    else:
                        b.getArray()[:] = blk[:, j - j0]
                    qsolve(b, x)
                    if ksp.getConvergedReason() < 0:
                        raise SSIError(f"a solve for column {j} of {m} diverged (KSP reason {ksp.getConvergedReason()})")
                    take(j, x)
            return
        nloc, n = template.getLocalSize(), template.getSize()
        for j0 in range(0, m, chunk):
            w = min(chunk, m - j0)
            B = PETSc.Mat().createDense(size=((nloc, n), (None, w)), comm=template.getComm())
            X = None if Q is not None else PETSc.Mat().createDense(size=((nloc, n), (None, w)),
                                                                   comm=template.getComm())
            B.setUp()
            if X is not None:
                X.setUp()
            Ba = B.getDenseArray()
            blk = rhs(j0, j0 + w)
            if blk is not None:
                Ba[:, :] = blk
            for c in range(w if blk is None else 0):
                fill(j0 + c, b)
                Ba[:, c] = b.getArray(readonly=True)
            B.assemble()
            if Q is None:
                F.matSolve(B, X)
            else:                                   # (in the blocks' basis: Q^T B solved, Q times the solutions)
                Bq = Q.transposeMatMult(B)
                Xq = Bq.duplicate()
                try:
                    F.matSolve(Bq, Xq)
                    X = Q.matMult(Xq)
                finally:
                    for o in (Bq, Xq):
                        o.destroy()
            Xa = X.getDenseArray()
            for c in range(w):
                x.getArray()[:] = Xa[:, c]
                take(j0 + c, x)
            B.destroy()
            X.destroy()
    finally:
        b.destroy()
        x.destroy()
        if Q is not None:
            bq.destroy()
            xq.destroy()
