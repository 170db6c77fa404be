"""Declarations of the options every problem kind shares (group "common"); each package declares
its own (``bem/options.py``, ``fem/options.py``, ``coupling/options.py``, the commands in ``app/``).

Units are SI. Coordinates: the free surface is z = 0, soil in z < 0, z up.
"""
from .options import register, register_check, positive, at_least

# ---------------------------------------------------------------- common
register("problem", "enum", "bem", "", "what to run: bem (half-space alone), fem (structure alone), ssi (coupled)",
         "common", choices=("bem", "fem", "ssi"))
register("dt", "real", 7.5e-4, "s", "time step", "common", validator=positive)
register("t_end", "real", 0.04, "s", "end time of the run", "common", validator=positive)
register("output", "str", "out/run.h5", "", "HDF5 output file (an .xmf for ParaView and a .json record are written beside it); '' "
         "(no output) only in a FEM run: a BEM or coupled run refuses it", "common")
register("output_stride", "int", 1, "steps", "write the fields every this many steps (0: receivers only)", "common",
         validator=lambda v: None if v >= 0 else "must be >= 0")
register("receivers", "str", "", "m", "receiver points 'x,y,z;x,y,z' (snapped to the surface mesh / nearest FE "
         "node); for a structure also 'group:NAME' (every node of a physical group)", "common")
register("monitor", "bool", False, "", "print progress: assembly, per-step time, elapsed, ETA (rank 0)", "common")
register("monitor_every", "int", 0, "steps", "monitor line every this many steps (0: about 20 lines per run)", "common",
         validator=lambda v: None if v >= 0 else "must be >= 0")
register("output_overwrite", "bool", False, "", "replace an existing -ssi_output (and its sidecars); without it a run "
         "refuses to start when the output exists", "common")
register("output_flush", "real", 10.0, "s", "make the output file readable (time, receivers, sidecars, run "
         "status) at least this often during the run, so a stopped run keeps its results; 0: only at the end",
         "common", validator=lambda v: None if v >= 0 else "must be >= 0")
register("output_merge", "bool", True, "", "at the end, copy the datasets of the output's parts (FILE.parts/, where "
         "the run writes its snapshots so that a kill never tears what a flush made readable) into FILE.h5 and "
         "remove them: rank 0 reads and writes them once more (0.37-0.40 GB/s on the development machine, "
         "jobscripts/final_copy_rate.py); 0: FILE.h5 keeps linking its parts (move the two together)", "common")
register("reproducible", "bool", False, "", "bitwise identical reruns at a fixed rank count: on more than one rank "
         "the direct solves default to SuperLU_dist instead of MUMPS (MUMPS's parallel sums change order between "
         "runs); a coupled run factorises the soil's step matrix whole on every rank with PETSc's LU instead "
         "(-ssi_bem_pc_type redundant). Finished HDF5 files carry no modification times (with or without this "
         "option), so identical results give identical files", "common")
register("huge_pages", "enum", "auto", "", "transparent huge pages for the large arrays, the stored lag blocks among "
         "them: auto (numpy's advice as numpy has it, on unless NUMPY_MADVISE_HUGEPAGE=0, except that the BEM's lag "
         "arrays get 4 kB pages where the machine is a virtual machine whose balloon hands free memory back to its "
         "host: there a huge page's first write cost 2-4 times a small page's, and the paper's Lamb case "
         "assembled in 5.2-7.2 s instead of 9.3-10.2 s, its history sum up to 0.3 s slower), numpy (numpy's advice for "
         "every array), on, or off (no huge pages for the lag arrays either). Which is faster is the machine's: "
         "jobscripts/paper_repeat.sh and huge_pages_bench.sh measure it; results do not depend on it", "common",
         choices=("auto", "off", "on", "numpy"))
register("checkpoint", "str", "", "", "checkpoint file (default <output stem>-checkpoint.h5); '%d' in the name "
         "becomes the step, to keep every checkpoint; never an output or sidecar of the run", "common")
register("checkpoint_every", "int", 0, "steps", "write a checkpoint every this many steps (0: never; a signal "
         "always writes one)", "common", validator=lambda v: None if v >= 0 else "must be >= 0")
register("checkpoint_interval", "real", 0.0, "s", "write a checkpoint when this much wall time has passed since "
         "the last one (0: never)", "common", validator=lambda v: None if v >= 0 else "must be >= 0")
register("restart", "str", "", "", "resume the run from this checkpoint (same options, any rank count; the "
         "output of the interrupted run is continued)", "common")
register("debug", "bool", False, "", "print the Python traceback of a file or memory error (an unreadable or "
         "damaged file, a failed allocation) beside its one-line message; a bug's traceback is printed always",
         "common")
register("plot", "bool", False, "", "write a PNG of the receiver histories beside the output", "common")
register("disk_check", "bool", True, "", "before the assembly, compare the free space of the output's file system "
         "with the run's estimated output (fields x snapshots x nodes x 8 B, receiver and interface series) and "
         "refuse a run that cannot fit (0: skip the check; the per-snapshot check still stops a run whose disk "
         "fills)", "common")

register("estimate_constants", "str", "", "", "JSON file of machine constants of the cost model, for petsc-ssi "
         "estimate and the run's own prediction of its time loop (default: petsc_ssi/estimate_constants.json; "
         "jobscripts/calibrate.py writes one)", "common")

register("max_steps", "int", 1000000, "steps", "refuse a run of more time steps than this, before any work: "
         "t_end / dt is reported with the predicted time of the loop, and a t_end or dt off by a few orders "
         "of magnitude would otherwise step for days; raise it for a longer run", "common", validator=at_least(1))


def _steps_check(cfg):
    from .timegrid import n_steps
    n = n_steps(cfg.t_end, cfg.dt)
    if n > cfg.max_steps:
        return (f"-ssi_t_end {cfg.t_end:g} with -ssi_dt {cfg.dt:g} is {n:.4g} time steps, more than -ssi_max_steps "
                f"{cfg.max_steps}; check t_end and dt, or raise -ssi_max_steps to run them")
    return None


register_check(("common",), _steps_check)
