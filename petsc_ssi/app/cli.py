"""Command line: ``petsc-ssi [COMMAND] [PETSc/-ssi_ options]``.

Commands:
  (none) | run    run the case the options describe (-ssi_problem bem|fem|ssi)
  post FILE.h5    post-process an output file (--receivers --csv, --spectrum, --transfer A B,
                  --response-spectrum, SSI.h5 --glance FIXED.h5)
  modes           natural frequencies and mode shapes of a FE structure (SLEPc)
  static          static solution K u = F of a FE structure (loads at h = 1), written like a run
  impedance       dynamic stiffness K(a0) of a surface footing (-ssi_disp_group), one run per mode
  input-motion    foundation input motion of a rigid massless footing (-ssi_disp_group) under the
                  seismic wave (-ssi_seismic): its translations and rotations, free field beside
  record FILE     read and process an earthquake record as a run would (-ssi_seismic_* options):
                  the report, the units' check, a target's factor; -ssi_record_csv the motion
  estimate        predicted time per stage and memory of the run, per rank count, and
                  whether it fits the nodes (no assembly; -ssi_estimate_* options)
  help            list every -ssi_ option with default, unit and meaning (also -help, --help)
  --version       the versions of petsc-ssi, PETSc, petsc4py, mpi4py, numpy, numba

Errors in the input end the run with one line, ``petsc-ssi: error: ...``, on
standard error (the run's log stays on standard output), and exit status 2 on every rank.
"""
import sys

COMMANDS = ("run", "post", "modes", "static", "help", "estimate", "impedance", "input-motion", "record")


def _split(argv):
    if len(argv) > 1 and argv[1] in COMMANDS:
        return argv[1], [argv[0]] + argv[2:]
    return "run", list(argv)


def _bad_command(argv):
    """The one-line error for a first argument that is neither a command nor an option, or None."""
    if len(argv) > 1 and argv[1] not in COMMANDS and not argv[1].startswith("-"):
        import difflib
        near = difflib.get_close_matches(argv[1], COMMANDS, n=1)
        return (f"petsc-ssi: error: unknown command '{argv[1]}'" + (f" (did you mean {near[0]}?)" if near else "")
                + f"; commands: {', '.join(COMMANDS)}; options start with '-'")
    return None


def _is_option(tok):
    """An option's name ('-name', not a negative number such as -1e-6 or -.5), as PETSc reads its arguments."""
    return len(tok) > 1 and tok[0] == "-" and not (tok[1].isdigit() or tok[1] == ".")


def _bad_args(argv):
    """The one-line error for arguments PETSc would take without a word and not use, or None (commands that read
    PETSc options only; ``post`` has its own --flags): an option written with two dashes (PETSc stores
    '--ssi_dt 1e-3' under another name: the run would keep the default) and a second value after an option's
    value (PETSc keeps the first and drops the rest: '-ssi_dt 1e-3 2e-3', or a file name at the end)."""
    cmd, rest = _split(argv)
    if cmd == "post":
        return None
    args = rest[1:]
    if cmd == "record" and args and not _is_option(args[0]):
        args = args[1:]                          # (its record file)
    prev, values = None, 0
    for tok in args:
        if tok.startswith("--") and len(tok) > 2:
            if tok in ("--help", "--version"):
                prev, values = tok, 0
                continue
            return (f"petsc-ssi: error: {tok}: options take one dash ({tok[1:]}); with two, PETSc would keep the "
                    "option under another name and the run would not use it")
        if _is_option(tok):
            prev, values = tok, 0
            continue
        values += 1
        if values > 1 or prev is None:
            where = f"after {prev} and its value" if prev is not None else "before any option"
            return (f"petsc-ssi: error: '{tok}' {where}: an option takes one value (quote a value with spaces or "
                    "semicolons, e.g. -ssi_receivers '1,0,0;2,0,0'); PETSc would drop it without a word")
    return None


def versions():
    """One line per component: petsc-ssi, Python, PETSc, petsc4py, mpi4py, numpy."""
    import platform
    from .. import __version__
    lines = [f"petsc-ssi {__version__}", f"Python {platform.python_version()}"]
    try:
        from ..petsc import init
        PETSc = init([sys.argv[0]])
        import petsc4py
        lines.append("PETSc {}.{}.{}".format(*PETSc.Sys.getVersion()) + f", petsc4py {petsc4py.__version__}")
    except Exception as exc:  # noqa: BLE001 -- report, do not fail
        lines.append(f"PETSc: not available ({exc})")
    for mod in ("mpi4py", "mpi4py_fft", "numpy", "numba"):
        try:
            lines.append(f"{mod} {__import__(mod).__version__}")
        except Exception:  # noqa: BLE001
            lines.append(f"{mod}: not available")
    return "\n".join(lines)


def _bad_options_file(argv):
    """One line if an -options_file is missing, unreadable, has a line PETSc would reject (a value
    without its option, or more than one option on a line: PETSc takes one '-name value' a line, a
    value in double quotes one token, and stops in PetscInitialize with a page of diagnostics and a
    traceback) or includes itself
    through its own -options_file lines, directly or through other files (PETSc recurses until the
    stack overflows: a segmentation fault), else None. Included files are checked the same way;
    their paths are taken as PETSc takes them (relative to the working directory)."""
    import os
    import re

    def files_in(args):
        return [args[i + 1] for i, a in enumerate(args[:-1]) if a == "-options_file"]

    def visit(path, chain):
        key = os.path.realpath(path)
        if key in chain:
            names = [p for _, p in chain.values()] + [path]
            return ("petsc-ssi: error: -options_file " + " -> ".join(names[names.index(chain[key][1]):])
                    + ": the options files include each other in a cycle (remove one -options_file line)"
                    if len(names) > 2 or names[0] != path else
                    f"petsc-ssi: error: -options_file {path} includes itself (remove its -options_file line)")
        try:
            with open(path) as fh:
                lines = fh.read().splitlines()
        except OSError as exc:
            where = f" (included by {list(chain.values())[-1][1]})" if chain else ""
            return f"petsc-ssi: error: -options_file {path}{where}: {exc.strerror or exc}"
        tokens = []
        for k, line in enumerate(lines, 1):
            text = line.split("#", 1)[0].strip()
            if text and not text.startswith("-") and text.split()[0] not in ("alias",):
                return (f"petsc-ssi: error: -options_file {path}, line {k}: '{text.split()[0]}' is not an option "
                        "(one '-name value' per line)")
            words = re.findall(r'"[^"]*"|\S+', text)
            if len(words) > (3 if words and words[0] == "alias" else 2):
                return (f"petsc-ssi: error: -options_file {path}, line {k}: '{words[2 + (words[0] == 'alias')]}' "
                        "follows the option and its value: PETSc takes one '-name value' a line (a value with "
                        "spaces in double quotes)")
            if text and not text.startswith("alias"):
                tokens += text.split()
        chain = dict(chain)
        chain[key] = (len(chain), path)
        for inc in files_in(tokens):
            bad = visit(inc, chain)
            if bad:
                return bad
        return None

    for path in files_in(argv):
        bad = visit(path, {})
        if bad:
            return bad
    return None


SOLVERS = (("ssi_bem_", "the soil's step solve (BEM)"), ("ssi_fem_", "the structure's solve (FEM)"))


def _solver_help(PETSc):
    """-help: the PETSc solver options under petsc_ssi's prefixes, with the defaults a run inserts
    where the user set nothing (a run makes these solvers only after the assembly, so without
    this -help would never list them): PETSc prints each KSP's options with their current
    values (its own -help output)."""
    from ..petsc import direct_solver_defaults
    comm = PETSc.COMM_WORLD
    db = PETSc.Options()
    for prefix, what in SOLVERS:
        PETSc.Sys.Print(f"PETSc solver options of {what}: prefix -{prefix} (any KSP/PC option; "
                        "petsc-ssi's defaults where you set none: " + " ".join(
                            f"-{prefix}{k} {v}" for k, v in direct_solver_defaults(comm).items()) + ")")
        inserted = []
        for k, v in direct_solver_defaults(comm).items():
            if not db.hasName(prefix + k):
                db.setValue(prefix + k, v)
                inserted.append(prefix + k)
        ksp = PETSc.KSP().create(comm)
        ksp.setOptionsPrefix(prefix)
        ksp.setFromOptions()            # with -help in the database, PETSc prints the options here
        ksp.destroy()
        for k in inserted:
            db.delValue(k)


def _post(rest):
    """The post commands; a reader that stops reading (``post X.h5 --receivers --csv | head``) ends the command
    quietly with status 141 (128 + SIGPIPE, as a shell's own tools), not with an error line."""
    try:
        return _post_command(rest)
    except BrokenPipeError:
        import os
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())   # (the exit's flush must not fail again)
        except OSError:
            pass
        return 141


def _post_command(rest):
    if "--response-spectrum" in rest:          # earthquake-engineering response spectra
        from .response import main as response_main
        return response_main(rest[1:])
    if "--glance" in rest:                     # SSI at a glance: coupled run vs fixed-base twin
        from .glance import main as glance_main
        return glance_main(rest[1:])
    from .post import main as post_main
    return post_main(rest[1:])


def _serial_status(run):
    """``run()`` (a serial command: post) on rank 0 only under mpirun, every rank exiting with rank 0's
    status (before: the other ranks only opened the file and exited 0 when rank 0 refused an argument).
    Rank 0 sends its status whatever happens (an exception too: status 1), so no rank waits for ever."""
    import os
    size = next((int(os.environ[k]) for k in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MV2_COMM_WORLD_SIZE")
                 if os.environ.get(k, "").isdigit()), 1)
    if size <= 1:
        return run()
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    if comm.Get_size() == 1:
        return run()
    if comm.Get_rank() == 0:
        status = 1
        try:
            status = run()
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            comm.bcast(status, root=0)
        return status
    status = comm.bcast(None, root=0)
    if status:
        import time
        time.sleep(0.3)                          # rank 0's error line first (mpirun ends at the first non-zero exit)
    return status


def main(argv=None):
    argv = list(sys.argv if argv is None else argv)
    bad = _bad_command(argv) or _bad_args(argv) or _bad_options_file(argv)
    if bad:                    # before PETSc starts: every rank exits, rank 0 says why
        from mpi4py import MPI
        if MPI.COMM_WORLD.Get_rank() == 0:
            _whole_line(bad)
        return 2
    if any(a in ("--version", "-version") for a in argv[1:]):
        from ..petsc import init
        init([argv[0]])
        from mpi4py import MPI
        if MPI.COMM_WORLD.Get_rank() == 0:
            print(versions(), flush=True)
        return 0
    cmd, rest = _split(argv)
    if cmd == "post":
        return _serial_status(lambda: _post(rest))
    from ..petsc import init, SSIError
    try:
        PETSc = init(rest)
    except Exception as exc:       # PetscInitialize refused the options (its own message above): no traceback
        if not type(exc).__module__.startswith("petsc4py"):
            raise
        _whole_line(f"petsc-ssi: error: PETSc did not start (error code {getattr(exc, 'ierr', '?')}): its message "
                    "above names the option or file it refused")
        return 2
    from .. import options
    from . import kinds, estimate, impedance, record  # noqa: F401  (every option declared, also for -help)
    if cmd == "help" or "-help" in rest or "--help" in rest:
        PETSc.Sys.Print(__doc__.split("Errors in the input")[0].rstrip() + "\n")
        PETSc.Sys.Print(options.help_text())
        _solver_help(PETSc)
        return 0                # help prints and exits: it never starts a run
    try:
        if cmd == "run":
            kinds.run()
        elif cmd == "static":
            from .static import main as static_main
            static_main()
        elif cmd == "modes":
            from .modes import main as modes_main
            modes_main()
        elif cmd == "estimate":
            estimate.main()
        elif cmd == "impedance":
            impedance.main()
        elif cmd == "record":
            record.main(rest[1:])
        elif cmd == "input-motion":
            from .input_motion import main as input_motion_main
            input_motion_main()
        if cmd != "estimate":
            options.warn_unused_options()
    except SSIError as exc:
        comm = PETSc.COMM_WORLD.tompi4py()
        if comm.Get_rank() == 0:
            _whole_line(f"petsc-ssi: error: {exc}")
        comm.Barrier()
        if comm.Get_rank() > 0:
            # mpirun ends the job at the first non-zero exit and may drop rank 0's last output
            # still in its pipe (the error line): rank 0 exits first
            import time
            time.sleep(0.3)
        return 2
    except Exception as exc:  # a bug or an I/O failure on some ranks only: never hang mpirun
        import traceback
        from ..petsc import debug
        if type(exc).__module__.startswith("petsc4py") and not debug():
            # PETSc stopped (an option's value it refuses, a failed solver set-up, ...): one line with where and
            # PETSc's own message, on each rank that met it (maybe not all of them: then Abort)
            _whole_line(f"petsc-ssi: error: PETSc stopped with error code {getattr(exc, 'ierr', '?')} in "
                        f"{_where(exc)}{_petsc_message(exc)} (-ssi_debug for the traceback)")
        else:
            traceback.print_exc()
        sys.stderr.flush()
        comm = PETSc.COMM_WORLD.tompi4py()
        if comm.Get_size() > 1:
            comm.Abort(1)
        return 1
    return 0


def _whole_line(text):
    """``text`` and its newline to standard error in one write (Python's buffered output flushed first, so the
    log's lines before it come before it on a terminal): each rank that meets a PETSc error prints its line, and
    two ranks' lines came out run together, one's text straight after the other's, with the line written in parts
    (a CI run of 1a9c676). Errors go to standard error: a user who sends the log (standard output) to a file
    still sees why the run stopped."""
    from ..petsc import error_line
    error_line(text)


def _petsc_message(exc):
    """': <PETSc function>: <its messages>' of a petsc4py error (its traceback entries: the call stack's
    'F() at file:line' entries, then the message lines), '' without one. Newer petsc4py keeps them on the
    error itself (``_traceback``); 3.18's keeps one class-wide list of the last error's (``_traceback_``)."""
    own = getattr(exc, "_traceback", None)
    tb = [str(t).strip() for t in (own if own is not None else getattr(exc, "_traceback_", None) or [])]
    calls = [t for t in tb if "() at " in t]
    msgs = [t for t in tb if t and "() at " not in t]
    if not msgs:
        return ""
    at = f" at {calls[-1].split(' at ')[0]}" if calls else ""
    return f"{at}: {'; '.join(msgs)}"


def _where(exc):
    """'module path:line (function)' of the innermost petsc_ssi frame of an exception's traceback."""
    import os
    import traceback
    pkg = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if os.path.abspath(f.filename).startswith(pkg + os.sep)]
    if not frames:
        return "petsc-ssi"
    f = frames[-1]
    return f"{os.path.relpath(os.path.abspath(f.filename), os.path.dirname(pkg))}:{f.lineno} ({f.name})"


if __name__ == "__main__":
    sys.exit(main())
