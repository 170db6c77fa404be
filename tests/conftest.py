import os
import sys

os.environ.setdefault("PETSC_DIR", "/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real")
os.environ.setdefault("SLEPC_DIR", "/usr/lib/slepcdir/slepc3.18/x86_64-linux-gnu-real")
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# `make test` runs two pytest workers (pytest-xdist), so two mpiruns may share the 2 cores: their
# ranks yield in MPI waits instead of spinning against each other (results do not depend on it)
os.environ.setdefault("OMPI_MCA_mpi_yield_when_idle", "1")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)


# ---------------------------------------------------------------- test tiers (pytest.ini)
import re as _re

import pytest as _pytest

# Heavy cases, measured with `pytest --durations=0` on an idle 2-core machine: each over a
# minute, and each covered at a smaller size by a test that stays in `make test`.
SLOW = {
    # the full building's option files (the half building's and the CI building stay in make test)
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/building/ssi-common.opts]",
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/building/ssi-half-common.opts]",
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/building/ssi-full-bonded-ny4.opts]",
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/building/ssi-full-bonded-released.opts]",
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/building/ssi-full-unilateral.opts]",
    # the disk's impedance against Veletsos & Verbic (the square's against Pais & Kausel stays)
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/impedance/disk.opts]",
    "tests/bem/test_impedance.py::test_disk_against_veletsos_and_verbic",
    # the antisymmetric foundation cases and the rectangle's impedance (the symmetric foundation cases,
    # anti-unilateral and the square's impedance stay)
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/foundation/anti-bonded.opts]",
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/foundation/anti-unilateral-cohesive.opts]",
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/impedance/rectangle.opts]",
    # blocked == per-step history sum: stabilised and the prescribed motion stay (and the coupled
    # contact case at -n 2); plain, interpolated, symmetry+interp, the antisymmetric motion here
    "tests/bem/test_history_block.py::test_blocked_equals_per_step[plain]",
    "tests/bem/test_history_block.py::test_blocked_equals_per_step[interpolated]",
    "tests/bem/test_history_block.py::test_blocked_equals_per_step[symmetry+interp]",
    "tests/bem/test_history_block.py::test_blocked_equals_per_step[prescribed motion, plain, anti]",
    # a cold numba cache compiled from scratch (47 s): make deps warms the cache CI uses, and
    # test_warmup's other tests check the warm state
    "tests/test_warmup.py::test_cold_cache_is_announced_then_the_warm_up_covers_every_run",
    # a second checkout compiles every kernel once (30-80 s, 279 s on the loaded machine): the cheap
    # test_a_second_checkout_is_not_taken_for_warm checks the per-checkout warm check it rests on
    "tests/test_warmup.py::test_a_second_checkout_compiles_once_and_says_so",
    # SIGTERM to mpirun under three CPU hogs: mpirun's own two timeouts (2 x 5 s) are waited out (18 s
    # measured); the ranks' stop order and the packed checkpoint stay in make test (test_output_survives,
    # test_checkpoint's signal tests)
    "tests/test_checkpoint.py::test_sigterm_to_mpirun_on_a_loaded_machine_writes_the_checkpoint",
    # the options of a lag file's key changed in turn, each refused (27 s; the checkpoint key's
    # refusals stay in make test)
    "tests/bem/test_lagstore.py::test_a_changed_key_is_refused",
    # the balanced partition evens the assembled work: a speed property (jobscripts measure it);
    # balanced == equal partitions at -n 2 stays
    "tests/bem/test_partition.py::test_balanced_evens_the_assembled_work",
    # the fixed-base limit's convergence in the soil's stiffness (three soils; the light-block,
    # Newton and -n 2 checks of the seismic input stay)
    "tests/coupling/test_seismic.py::test_fixed_base_limit_converges_in_the_soil_stiffness",
    # restart and -n 2 == -n 1 with a contact preload, both couplings (three mpirun launches each: 13 s
    # for both on the idle machine, 25 s each under load): the preload is a constant recomputed from
    # the options; the contact state's restart is test_checkpoint's coupled contact restart, and
    # test_preload's in-process checks and its -n 2 refusal stay
    "tests/coupling/test_preload.py::test_preload_restart_and_two_ranks",
    # (fourth session: the seismic, demands, forces, input-motion, integrity and message tests added
    # about 4 minutes; these moved here, each with a smaller sibling in make test)
    # the literal CSR sums without symmetry planes (85 s under load; the planes' variant, which folds
    # images into the same sums, stays)
    "tests/bem/test_assembly_layout.py::test_blocks_equal_the_literal_sums_in_csr_order[False]",
    # single-precision lags interpolated, coupled and at -n 2 (30 s; single == double by rounding and
    # the lag file's bitwise reload stay)
    "tests/bem/test_single.py::test_single_lags_interpolated_coupled_and_parallel",
    # the folded quarter model of a rigid motion (30 s; the symmetry-reduced impedance runs == full
    # runs and the half model on a graded gmsh mesh stay)
    "tests/bem/test_rigid_motion.py::test_folded_quarter_model_equals_the_full_model",
    # the paper's building under 30 s of record at 3 steps: the half building's option file (same
    # mesh) and the seismic building's (same seismic options) stay
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/seismic/paper-building.opts]",
    # measured after the merges (make test at 1057 s on the idle machine): each has a sibling that stays
    # - the checkpoint key's refusals one by one (21 s; test_integrity's restart refusals stay)
    "tests/test_checkpoint.py::test_a_restart_that_changes_the_run_is_refused",
    # - checkpoint and lag names against every output and sidecar (20 s; the locks' tests stay)
    "tests/test_integrity.py::test_checkpoint_and_lag_files_may_not_be_outputs",
    # - the full building's bonded option file (19 s; the half building's stay, as its variants here)
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/building/ssi-full-bonded.opts]",
    # - a signal's checkpoint of a BEM run (13 s; the coupled contact run's stays)
    "tests/test_checkpoint.py::test_a_signal_writes_a_checkpoint_that_restarts_a_bem_run",
    # - impedance: symmetry-reduced == full and -n 2 (11 s; the off-centre footing's planes stay),
    #   the requested band's warning (8 s) and the meshed surface's low-frequency limit (6 s)
    "tests/bem/test_impedance.py::test_symmetry_reduced_runs_equal_full_runs_and_two_ranks_equal_one",
    "tests/bem/test_impedance.py::test_requested_band_outside_the_trusted_one_warns",
    "tests/bem/test_impedance.py::test_the_meshed_surface_limits_the_low_frequencies",
    # - blocked == per-step history with a prescribed motion (11 s; the stabilised case stays)
    "tests/bem/test_history_block.py::test_blocked_equals_per_step[prescribed motion]",
    # - a rigid motion's resultants at -n 2 and through a restart (9 s; the square's stiffness stays)
    "tests/bem/test_rigid_motion.py::test_two_ranks_equal_one_and_a_restart_keeps_the_resultants",
    # - single lags' file reload (6 s; the double lag file's bitwise reload stays)
    "tests/bem/test_single.py::test_single_lag_file_reloads_bitwise",
    # - the flat pattern against the general path in single precision and at -n 1 (15 s; block-sparse
    #   with interpolation and dense with a prescribed region at -n 2 stay)
    "tests/bem/test_flat_pattern.py::test_the_flat_pattern_is_the_general_path[single precision, symmetry, 2 ranks]",
    "tests/bem/test_flat_pattern.py::test_the_flat_pattern_is_the_general_path[auto storage, prescribed motion, 1 rank]",
    # - a flat lag file saved at -n 2 and reloaded at -n 1 (16 s; the in-process round trip of the stored
    #   entries through MPIAIJ and test_lagstore's bitwise reload stay)
    "tests/bem/test_flat_pattern.py::test_a_lag_file_holds_the_pattern_and_reloads",
    # make test took 925 s in a fresh clone (2026-11-26, a machine 10 % slower than the day before):
    # - a signal, checkpoint and restart of the coupled contact run (10 s; the BEM run's signal ->
    #   checkpoint -> restart, the coupled contact restarts bitwise and the coupled run stopped by a
    #   signal stay)
    "tests/test_checkpoint.py::test_a_signal_writes_a_checkpoint_that_restarts_a_coupled_contact_run",
    # - blocked == per-step at -n 2 with sub-blocks and a block longer than the run (9 s; stabilised
    #   at -n 1 and the coupled contact case at -n 2 with sub-blocks stay)
    "tests/bem/test_history_block.py::test_blocked_two_ranks_and_a_block_longer_than_the_lags",
    # - the half building unilateral options file reduced (6 s; the half building bonded and the CI
    #   building's unilateral == bonded in compression stay)
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/building/ssi-half-unilateral.opts]",
    # 2026-11-26, make test at 932 s in a fresh clone with the random-kill tests back (12 s) and the
    # output's parts tests:
    # - restarts inside a block with sub-blocks of 7 and 2 (8 s; sub-blocks of 3 at steps 10 and 58,
    #   and a restart with another block size stay)
    "tests/bem/test_history_block.py::test_a_restart_inside_a_block_is_bitwise[7-5-10]",
    "tests/bem/test_history_block.py::test_a_restart_inside_a_block_is_bitwise[2-5-10]",
    # - the symmetric foundation's bonded options files, staggered and implicit, reduced (9 s; the
    #   symmetric unilateral, the whole foundation and the antisymmetric unilateral files stay)
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/foundation/sym-bonded.opts]",
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/foundation/sym-bonded-staggered.opts]",
    # - a damaged lag file refused (7 s; the damaged checkpoint's refusal through the same checksums,
    #   io/integrity.py, and the lag file's bitwise reload stay)
    "tests/test_integrity.py::test_a_damaged_lag_file_is_refused",
    # - the full disk at -n 1 (4 s; -n 2 and the refusal before the assembly stay)
    "tests/test_disk_full.py::test_a_full_disk_stops_the_run_and_keeps_its_steps[1]",
    # - a restart with another block size (4 s; the restarts inside a block with sub-blocks of 3 at
    #   steps 10 and 58 stay): make test was 906 s in a fresh clone with ParaView's tests running
    "tests/bem/test_history_block.py::test_a_restart_with_another_block_size",
    # issue 29's session (make test 916-918 s in two runs, ParaView's tests included; four new
    # tests of the plane kernel, under a second):
    # - a restart naming another run's finished output refused (9 s; the refusals of a restart from a
    #   result and of another live run's file, tests/test_output_safety.py and test_integrity.py, stay)
    "tests/test_integrity.py::test_a_restart_does_not_continue_another_runs_output",
    # - the impedance driver's existing CSV refused before the first mode (8 s; the run outputs'
    #   refusals in tests/test_output_safety.py and the impedance's bad input stay)
    "tests/bem/test_impedance.py::test_existing_outputs_are_refused_before_the_first_run",
    # - the square's impedance options file reduced (7 s; the square against Pais & Kausel stays)
    "tests/test_runs_opts.py::test_options_file_runs_reduced[runs/impedance/square.opts]",
    # - balanced and equal partitions at 2 ranks agree (6 s; the partition's unit tests and the
    #   -n 1 / -n 2 agreement of tests/bem/test_parallel.py stay)
    "tests/bem/test_partition.py::test_two_ranks_balanced_and_equal_agree",
    # then 901 s in a fresh clone: five variants whose siblings stay (about 18 s)
    # - the staggered coupled contact restart (the implicit one stays)
    "tests/test_checkpoint.py::test_coupled_contact_restart_is_bitwise[staggered]",
    # - the plain scheme's BEM restart (the stabilised and interpolated ones stay)
    "tests/test_checkpoint.py::test_bem_restart_is_bitwise[plain]",
    # - a failed write at -n 1 (-n 2 stays)
    "tests/test_disk_full.py::test_a_failed_write_ends_the_job_in_one_line[1]",
    # - two refusals at -n 1 (their -n 2 runs, one line on every rank, stay)
    "tests/test_wrong_or_silent.py::test_mesh_params_without_a_geo_and_a_zero_mass_per_area_are_refused[1]",
    "tests/test_wrong_or_silent.py::test_interface_offset_on_bricks_is_refused[1]",
}
_MPI = _re.compile(r"nranks\s*=\s*[2-9]|mpirun|mpiexec|\"-n\", \"?[2-9]|-n 2")
_RUNS = _re.compile(r"\bcli\(|run_bem\(|run_ssi\(|run_fem\(|subprocess|from helpers import")
_SRC = {}


def _source(path):
    if path not in _SRC:
        try:
            _SRC[path] = open(path, encoding="utf-8").read()
        except OSError:
            _SRC[path] = ""
    return _SRC[path]


def pytest_collection_modifyitems(config, items):
    """Mark every test with its tier: slow (the SLOW table), mpi (its module starts mpirun with
    more than one rank), unit (its module makes no run and starts no process); a test may also
    carry a marker of its own."""
    for item in items:
        name = item.nodeid.split("[")[0]
        src = _source(str(item.fspath))
        if name in SLOW or item.nodeid in SLOW:
            item.add_marker(_pytest.mark.slow)
        if _MPI.search(src):
            item.add_marker(_pytest.mark.mpi)
        elif not _RUNS.search(src) and not item.get_closest_marker("slow"):
            item.add_marker(_pytest.mark.unit)
