"""Exclusive locks on the files a run writes (issue 30): two runs started at once with the same
-ssi_output (or -ssi_checkpoint pattern, or -ssi_lags_save) would write into one file together
and leave it unreadable.

``acquire`` (collective, before any heavy work) makes ``FILE.lock`` beside each file on rank 0,
holding the host, the pid and the start time: written to a file of its own and hard-linked to the
lock's name (atomic on local file systems and on NFS, and never seen empty), or with
``O_CREAT | O_EXCL`` where there are no hard links (a lock found empty is then read again for a moment). A second run finds it and is refused in one line on every rank. A lock
whose pid is no longer alive on this host (a run killed by SIGKILL or by the node) is stale: it
is taken over with a warning. A lock of another host cannot be checked: refused, the message says
which run holds it and that the file may be removed if that run is gone.

The lock goes away at the end of the run (``release``: ``TransientProblem.run`` on success and on
any error), at the exit of the process (atexit), and on SIGTERM/SIGHUP outside the time-stepping
(where ``problem._Signals`` turns them into a checkpoint and an SSIError, which releases it too).
"""
import atexit
import os
import platform
import signal
import time
import weakref

from ..petsc import collective_error, warn

SUFFIX = ".lock"
_HELD = {}          # lock file -> weak reference to its holder (a TransientProblem); rank 0 only


def lock_path(path):
    return path + SUFFIX


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:                        # another user's live process
        return True
    return True


def _read(lockfile):
    """{host, pid, started} of a lock file ({} if unreadable)."""
    info = {}
    try:
        with open(lockfile, "rb") as fh:
            text = fh.read(4096).decode("utf-8", errors="replace")      # any bytes: never a crash
    except OSError:
        return info
    for line in text.splitlines():
        k, _, v = line.partition(" ")
        if k in ("host", "pid", "started"):
            info[k] = v.strip()
    return info


# a lock found without host and pid is read again this often, this far apart, before it counts as foreign: a run
# that made its lock with O_EXCL (``_make`` where the file system has no hard links) writes it right after
EMPTY_RETRIES, EMPTY_WAIT = 20, 0.05


def _make(lockfile, text):
    """Make ``lockfile`` holding ``text``, atomically where the file system allows: written to a file of this
    process's own, then hard-linked to the lock's name (the link fails if the lock exists), so that no run can
    find the lock empty; where there are no hard links, O_CREAT | O_EXCL and the text written after. Raises
    FileExistsError if the lock exists, OSError otherwise."""
    tmp = f"{lockfile}.{platform.node()}.{os.getpid()}.tmp"
    try:
        with open(tmp, "w") as fh:
            fh.write(text)
        try:
            os.link(tmp, lockfile)
            return
        except FileExistsError:
            raise
        except OSError:
            pass                                    # (no hard links here: O_EXCL below)
    finally:
        try:
            os.remove(tmp)
        except OSError:
            pass
    fd = os.open(lockfile, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
    with os.fdopen(fd, "w") as fh:
        fh.write(text)


def _read_settled(lockfile):
    """``_read``, again for a while when the lock has neither host nor pid yet (being written)."""
    info = _read(lockfile)
    for _ in range(EMPTY_RETRIES):
        if "host" in info and "pid" in info or not os.path.exists(lockfile):
            break
        time.sleep(EMPTY_WAIT)
        info = _read(lockfile)
    return info


def _create(lockfile, holder):
    """Rank 0: make ``lockfile``; returns (error message or None, warning or None)."""
    host, pid = platform.node(), os.getpid()
    note = None
    for _ in range(3):
        try:
            _make(lockfile, f"host {host}\npid {pid}\nstarted {time.strftime('%Y-%m-%dT%H:%M:%S%z')}\n")
        except FileExistsError:
            info = _read_settled(lockfile)
            try:
                opid = int(info.get("pid", "-1"))
            except ValueError:
                opid = -1
            mine = opid == pid and info.get("host") == host
            if mine:
                ref = _HELD.get(lockfile)
                if ref is not None and ref() is not None and ref() is not holder:
                    return (f"{lockfile} is held by another problem of this process: two runs may not write "
                            "the same file", None)
                stale = True                       # left by a problem of this process that is gone
            else:
                stale = info.get("host") == host and opid > 0 and not _alive(opid)
            if not stale and not mine and ("host" not in info or opid <= 0):
                return (f"{lockfile} exists and is not a petsc-ssi lock (no host and pid in it): "
                        f"{lockfile[:-len(SUFFIX)]} may be in use; remove {lockfile} if no run writes it", None)
            if not stale:
                return (f"{lockfile[:-len(SUFFIX)]} is being written by another run (host {info.get('host', '?')}, "
                        f"pid {info.get('pid', '?')}, started {info.get('started', '?')}; its lock {lockfile}); "
                        "wait for it, choose another name, or remove the lock if that run is gone", None)
            if not mine:
                note = (f"took over the stale lock {lockfile} of pid {opid} (no longer running on {host}, "
                        f"started {info.get('started', '?')}): that run ended without removing it")
            try:
                os.remove(lockfile)
            except FileNotFoundError:
                pass
            continue
        except OSError as exc:
            return f"cannot create the lock {lockfile} ({exc.strerror or exc})", None
        _HELD[lockfile] = weakref.ref(holder) if holder is not None else (lambda: True)
        return None, note
    return f"cannot take the lock {lockfile} (it keeps coming back)", None


def acquire(paths, comm, holder, what="-ssi_output"):
    """Collective: a lock on each of ``paths`` (rank 0); SSIError in one line on every rank if
    another run holds one (the locks made are given back); the list of lock files held."""
    # the real path: two names of one file (a symbolic link, a linked directory) take one lock
    files = list(dict.fromkeys(lock_path(os.path.realpath(p)) for p in paths))
    err, notes, made = None, [], []
    if comm.getRank() == 0:
        for f in files:
            err, note = _create(f, holder)
            if note:
                notes.append(note)
            if err:
                break
            made.append(f)
        if err:
            _remove(made)
        else:
            _install_signal_handlers()
    collective_error(err, comm)
    for note in comm.tompi4py().bcast(notes, root=0):
        warn(note, comm)
    return files


def _remove(files):
    """Rank 0: remove the locks of ``files`` this process holds (a lock rewritten by another run is
    left alone)."""
    pid, host = str(os.getpid()), platform.node()
    for f in files:
        if _HELD.pop(f, None) is None:
            continue
        info = _read(f)
        if info.get("pid") == pid and info.get("host") == host:
            try:
                os.remove(f)
            except OSError:
                pass


def release(files, comm=None):
    """The locks ``files`` (``acquire``'s list) removed on rank 0; other ranks do nothing. Not
    collective: safe on an error path."""
    if files and (comm is None or comm.getRank() == 0):
        _remove(list(files))


def release_all():
    _remove(list(_HELD))


atexit.register(release_all)

_INSTALLED = []


def _install_signal_handlers():
    """Rank 0: SIGTERM and SIGHUP (whose default ends the process without atexit) remove the locks
    first, then do what they did (once; only where the default handler was in place)."""
    if _INSTALLED:
        return
    _INSTALLED.append(True)
    for name in ("SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is None:
            continue
        try:
            if signal.getsignal(sig) is not signal.SIG_DFL:
                continue

            def handler(signum, frame):
                release_all()
                signal.signal(signum, signal.SIG_DFL)
                os.kill(os.getpid(), signum)
            signal.signal(sig, handler)
        except (ValueError, OSError):              # not the main thread
            pass

