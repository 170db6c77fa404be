"""Command line: ``petsc-ssi [COMMAND] [PETSc/-ssi_ options]``.

Commands:
  (none) | run    run the case the options describe (-ssi_problem bem|fem|ssi)
  post FILE.h5    post-process an output file (--receivers --csv, --spectrum, --transfer A B)
  modes           natural frequencies and mode shapes of a FE structure (SLEPc)
  static          static solution K u = F of a FE structure (loads at h = 1), written like a run
  estimate        predicted time per stage and memory of the run, per rank count, and
                  whether it fits the nodes (no assembly; -ssi_estimate_* options)
  help            list every -ssi_ option with default, unit and meaning

Errors in the input end the run with one line, ``petsc-ssi: error: ...``,
and exit status 2 on every rank.
"""
import sys

COMMANDS = ("run", "post", "modes", "static", "help", "estimate")


def _split(argv):
    if len(argv) > 1 and argv[1] in COMMANDS:
        return argv[1], [argv[0]] + argv[2:]
    return "run", list(argv)


def main(argv=None):
    argv = list(sys.argv if argv is None else argv)
    cmd, rest = _split(argv)
    if cmd == "post":
        from .post import main as post_main
        return post_main(rest[1:])
    from .petsc import init, SSIError
    PETSc = init(rest)
    from . import options
    if cmd == "estimate":
        from . import estimate  # noqa: F401  (declares the -ssi_estimate_ options, also for -help)
    if cmd == "help" or "-help" in rest or "--help" in rest:
        PETSc.Sys.Print(__doc__.split("Errors in the input")[0].rstrip() + "\n")
        PETSc.Sys.Print(options.help_text())
        if cmd == "help":
            return 0
    try:
        if cmd == "run":
            from .driver import run
            run()
        elif cmd == "static":
            from .fem.static import main as static_main
            static_main()
        elif cmd == "modes":
            from .fem.modes import main as modes_main
            modes_main()
        elif cmd == "estimate":
            from .driver import estimate
            estimate()
    except SSIError as exc:
        PETSc.Sys.Print(f"petsc-ssi: error: {exc}")
        sys.stdout.flush()
        PETSc.COMM_WORLD.tompi4py().Barrier()
        return 2
    except Exception:  # a bug or an I/O failure on some ranks only: never hang mpirun
        import traceback
        traceback.print_exc()
        sys.stderr.flush()
        comm = PETSc.COMM_WORLD.tompi4py()
        if comm.Get_size() > 1:
            comm.Abort(1)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
