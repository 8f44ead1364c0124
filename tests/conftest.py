import os
import sys
import time

import numpy as np
import pytest
from hypothesis import settings

import fkopt.kinbench  # noqa: F401 (registers every built-in kind of config with the engine)

# The property tests draw their examples from a fixed seed, so a run of README's test command is
# reproducible like everything else here (a red CI names an example that fails every time).
# FKOPT_HYPOTHESIS=explore draws fresh examples, to hunt for new counterexamples.
settings.register_profile("deterministic", derandomize=True, database=None)
settings.register_profile("explore")
settings.load_profile(os.environ.get("FKOPT_HYPOTHESIS", "deterministic"))


class Sphere:
    """f(x) = |x - c|^2 on a box; residuals x - c (for Newton/LM)."""

    def __init__(self, dim=3, centre=0.3, half=5.0):
        self.variable_names = tuple(f"x{i}" for i in range(dim))
        self.variable_units = ("",) * dim
        self.bounds = np.array([[-half, half]] * dim)
        self.centre = np.full(dim, centre)

    @property
    def dim(self):
        return len(self.variable_names)

    def residuals(self, x):
        return np.asarray(x) - self.centre

    def fitness(self, x):
        r = self.residuals(x)
        return (r * r).sum(axis=-1)


@pytest.fixture
def sphere():
    return Sphere()


@pytest.fixture
def cli(monkeypatch, capsys):
    """Run ``fkopt ARGS`` in this process (as the console script does); (status, stdout, stderr)."""
    from fkopt.cli import main

    def run(*args):
        monkeypatch.setattr(sys, "argv", ["fkopt", *map(str, args)])
        try:
            main()
            code = 0
        except SystemExit as exc:
            code = exc.code or 0
        out = capsys.readouterr()
        return code, out.out, out.err
    return run


@pytest.fixture
def fkopt_run(cli, monkeypatch):
    """``cli`` read like ``subprocess.run(["fkopt", ...])`` (returncode, stdout, stderr), run from ``cwd``
    on a terminal ``columns`` wide: for tests whose subject is fkopt's text, files and exit status, not
    its start-up (those keep a subprocess), without an interpreter start-up per call."""
    from types import SimpleNamespace

    def run(*args, cwd=None, columns=200):
        monkeypatch.setenv("COLUMNS", str(columns))
        if cwd is not None:
            monkeypatch.chdir(cwd)
        code, out, err = cli(*args)
        return SimpleNamespace(returncode=code, stdout=out, stderr=err)
    return run


# --- Test tiers -------------------------------------------------------------------------------
# README's `python -m pytest` runs everything (CI). `make test-fast` runs
#   python -m pytest -m "not slow and not stored and not external and not browser"
# after every change: a few minutes at most on 2 cores, and still importing every module of fkopt
# (checked at the end of such a run, see pytest_sessionfinish below).
#   slow      seconds of solving (full budgets, whole suites, several experiments in one test)
#   stored    reruns stored results under results/ (or a whole `fkopt reproduce`)
#   external  needs something outside this process: pip install, a Dask cluster, worker
#             processes killed by signals, slow comparisons with example-robot-data's robots
#   browser   drives a real browser (selenium + chromium)
# The markers are set here, keyed by test function, so one table shows the tiers; a name listed here
# that no longer exists in its (collected) file is a usage error, not a silent no-op.
FAST_TIER = "not slow and not stored and not external and not browser"
TIERS = {
    "tests/test_bench_fksgp.py::test_beside_fksgp_every_platform_gives_the_same_real_solutions": ("external",),
    "tests/test_numerics_fallback.py::test_every_kind_of_corrupted_cache_file_is_set_aside_and_rebuilt": ("slow",),
    "tests/test_all_solutions.py::test_all_solutions_recall_against_eaik_on_the_ur5": ("external",),
    "tests/test_bench_ik.py::test_pinocchio_check_accepts_the_drawn_joints_and_rejects_wrong_ones": ("external",),
    "tests/test_bench_ik.py::test_ik_sections_report_every_arm_ratios_and_verified_counts": ("external",),
    "tests/test_kinbench_v3.py::test_fkopt_check_rejudges_every_stored_answer_and_recomputes_the_board": ("slow",),
    "tests/test_hostile_readers.py::test_check_fails_a_board_whose_answers_are_missing_duplicated_extra_or_unreadable":
        ("slow",),
    "tests/test_hostile_readers.py::test_fkopt_check_of_a_board_whose_answers_are_not_gzip_names_the_file_and_exits_1":
        ("slow",),
    "tests/test_kinbench_v3.py::test_a_suite_with_tracks_writes_the_robot_board_and_every_answer": ("slow",),
    "tests/test_kinbench_v3.py::test_fk_of_a_parallel_mechanism_on_the_clock_counts_other_assembly_modes_apart":
        ("slow",),
    "tests/test_kinbench_v3.py::test_a_submission_claiming_success_on_wrong_answers_gets_failures": ("slow",),
    "tests/test_kinbench_v3.py::test_fkopt_suite_exits_2_with_one_line_and_writes_nothing_on_a_bad_submission":
        ("slow",),
    "tests/test_bench.py::test_quick_run_writes_csv_and_plot": ("slow",),
    "tests/test_kinbench.py::test_fkopt_check_passes_on_the_v2_quick_tier_and_fails_on_an_edited_number":
        ("slow", "stored"),
    "tests/test_kinbench.py::test_v2_quick_tier_ranks_urdf_arms_dietmaier_and_the_exact_track": ("slow",),
    "tests/test_kinbench.py::test_fkopt_suite_writes_the_leaderboard_and_fkopt_check_reruns_it": ("slow",),
    "tests/test_kinbench.py::test_worker_processes_and_a_dask_scheduler_write_the_same_bytes": ("external",),
    "tests/test_kinbench.py::test_an_interrupted_suite_resumes_with_the_same_bytes": ("slow",),
    "tests/test_kinbench.py::test_fkopt_run_accepts_a_suite_and_numbers_do_not_depend_on_other_solvers":
        ("slow",),
    "tests/test_kinbench.py::test_v2_urdf_copies_match_example_robot_data": ("external",),
    "tests/test_kinbench.py::test_v3_quick_tier_ranks_instances_urdf_and_mjcf_arms_and_chains": ("slow",),
    "tests/test_releases.py::test_fkopt_check_refuses_a_run_whose_released_pose_sets_were_swapped_after_it":
        ("slow",),
    "tests/test_robots.py::test_stored_urdf_copy_matches_pinocchio_on_the_original": ("external",),
    "tests/test_hostile_robots.py::test_break8_every_outside_solver_reads_an_arm_with_a_fixed3_joint":
        ("external",),
    "tests/test_hostile_robots.py::test_v3s_robot_files_are_pinned_by_sha256_like_v1_and_v2": ("slow",),
    "tests/test_robots.py::test_stored_mjcf_copy_matches_mj_kinematics_on_the_original": ("external",),
    "tests/test_hostile.py::test_ctrl_c_of_a_parallel_run_keeps_its_tasks_and_resume_finishes_it":
        ("external",),
    "tests/test_hostile.py::test_interrupted_study_rerun_keeps_previous_result": ("external",),
    "tests/test_hostile.py::test_interrupted_experiment_rerun_keeps_previous_result": ("external",),
    "tests/test_hostile.py::test_jobs_10000_starts_no_more_processes_than_cpus": ("external",),
    "tests/test_hostile.py::test_export_keeps_pso_plus_lm_and_an_outside_pso_minus_lm_apart": ("slow",),
    "tests/test_reproduce.py::test_stored_results_are_reproduced": ("stored",),
    "tests/test_reproduce.py::test_reproduce_in_worker_processes_gives_the_serial_files": ("stored", "slow"),
    "tests/test_reproduce.py::test_report_is_generated_not_edited": ("stored",),
    "tests/test_reproduce.py::test_one_ulp_in_the_exact_solvers_starts_passes_the_cross_platform_rules":
        ("stored",),
    "tests/test_reproduce.py::test_edits_of_path_dependent_rows_and_of_runs_are_caught_in_every_tier":
        ("stored",),
    "tests/test_reproduce.py::test_tolerances_catch_the_edits_of_issue_10": ("stored",),
    "tests/test_reproduce.py::test_check_cli_fails_and_names_experiment_column_values": ("stored",),
    "tests/test_reproduce.py::test_check_cli_tolerant_forces_the_cross_platform_rules": ("stored",),
    "tests/test_reproduce.py::test_check_accepts_a_paper_folder": ("stored",),
    "tests/test_reproduce.py::test_unedited_copy_passes_both_modes": ("stored",),
    "tests/test_study.py::test_stored_configs_run_small_and_feed_report_check_claims": ("slow",),
    "tests/test_study.py::test_jobs_1_and_2_and_dask_give_identical_results": ("external",),
    "tests/test_plugins.py::test_example_plugin_runs_from_yaml_end_to_end": ("external",),
    "tests/test_plugins.py::test_example_plugin_found_through_entry_points": ("external",),
    "tests/test_urdf.py::test_real_robot_jacobian_matches_finite_differences": ("external",),
    "tests/test_cli.py::test_run_is_deterministic": ("slow",),
    "tests/test_kinbench_pages.py::test_fkopt_pages_remakes_a_stored_board_from_its_files_alone": ("slow", "stored"),
    "tests/test_newcomer.py::test_ctrl_c_of_a_fresh_experiment_names_the_command_that_resumes_it":
        ("external",),
    "tests/test_run_result.py::test_ctrl_c_of_an_experiment_keeps_its_tasks_and_resume_finishes_it": ("external",),
    "tests/test_run_result.py::test_run_tasks_hands_the_same_records_to_a_worker_process": ("external",),
    "tests/test_newcomer.py::test_ctrl_c_of_a_study_names_the_command_that_resumes_it": ("external",),
    "tests/test_export.py::test_export_refuses_what_it_must_not_touch": ("slow",),
}
TIER_MARKERS = ("slow", "stored", "external", "browser")

# Files whose module-scoped fixtures cost seconds (stored claims judged, small runs of every config of a
# paper, a small suite or experiment written once and copied): xdist's default scheduling would deal
# their tests to both workers and each would make the fixture; pytest_xdist_make_scheduler below sends a
# file of this set to one worker as one unit. (xdist's own --dist loadgroup cannot: it renames node ids,
# which pytest >= 9.2 no longer lets it do.)
ONE_WORKER_FILES = {"tests/test_paper_claims.py", "tests/test_paper_wang7dof.py", "tests/test_paper_liu2008.py",
                    "tests/test_paper_wu2015.py", "tests/test_paper_chang2024.py", "tests/test_hostile.py",
                    "tests/test_hostile_readers.py", "tests/test_kinbench_ioh.py", "tests/test_export.py",
                    "tests/test_kinbench_subsets.py", "tests/test_assembly.py", "tests/test_inverse_solver.py"}


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """`-n 2` (xdist's `load`): tests dealt out one by one, except each ONE_WORKER_FILES file as one unit
    (largest units first: xdist's loadscope order)."""
    if config.getvalue("dist") != "load":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class OneWorkerFiles(LoadScopeScheduling):
        def _split_scope(self, nodeid):
            path = nodeid.split("::", 1)[0]
            return path if path in ONE_WORKER_FILES else nodeid
    return OneWorkerFiles(config, log)


def _tier_key(item):
    """`tests/test_x.py::test_name` of a collected test (its parameters and class dropped)."""
    path = os.path.relpath(str(item.path), os.path.dirname(os.path.dirname(__file__)))
    return f"{path.replace(os.sep, '/')}::{item.originalname}"


@pytest.hookimpl(tryfirst=True)   # before -m/-k deselect, so every test of a collected file is seen
def pytest_collection_modifyitems(config, items):
    seen, files = set(), set()
    for item in items:
        key = _tier_key(item)
        seen.add(key)
        files.add(key.split("::")[0])
        for name in TIERS.get(key, ()):
            item.add_marker(getattr(pytest.mark, name))
    gone = [key for key in TIERS if key.split("::")[0] in files and key not in seen]
    if gone:
        raise pytest.UsageError("tests/conftest.py TIERS lists tests that no longer exist: " + ", ".join(gone)
                                + " (rename or remove them in TIERS)")


def _every_fkopt_module():
    import pkgutil

    import fkopt
    return sorted(name for _, name, _ in pkgutil.walk_packages(fkopt.__path__, "fkopt."))


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """pytest-xdist (make test-fast runs -n 2): a worker's imported fkopt modules, for the check below."""
    names = getattr(node, "workeroutput", {}).get("fkopt_modules", [])
    node.config._fkopt_worker_modules = getattr(node.config, "_fkopt_worker_modules", set()) | set(names)


def pytest_sessionfinish(session, exitstatus):
    """After a whole fast tier (every file of tests/, `-m FAST_TIER`, no -k) that passed: fail if a module
    of fkopt was imported by no test -- a module only slow tests reach gets no check after a change."""
    config = session.config
    if hasattr(config, "workeroutput"):       # an xdist worker: report what it imported to the controller
        config.workeroutput["fkopt_modules"] = sorted(n for n in sys.modules if n.split(".")[0] == "fkopt")
        return
    if (exitstatus != 0 or config.option.collectonly or config.option.keyword
            or config.option.markexpr.strip() != FAST_TIER):
        return
    tests_dir = os.path.dirname(os.path.abspath(__file__))
    if any(os.path.abspath(os.path.join(str(config.invocation_params.dir), a)) != tests_dir for a in config.args):
        return
    seen = set(sys.modules) | getattr(config, "_fkopt_worker_modules", set())
    missing = [name for name in _every_fkopt_module() if name not in seen]
    if missing:
        session.config.get_terminal_writer().line(
            "fast tier imports no test of these fkopt modules (add a small fast test): " + ", ".join(missing),
            red=True)
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def wait_while_running(proc, ready, timeout: float) -> None:
    """Poll ``ready()`` every 50 ms until it holds, ``proc`` (a Popen) has ended or ``timeout`` s have
    passed: the interruption tests' wait for a run to reach the point where they send it SIGINT. A
    file that is being written (``OSError``, ``ValueError``, ``KeyError`` while reading it) is not
    ready yet. The caller asserts that ``proc`` still runs."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            if ready():
                return
        except (OSError, ValueError, KeyError):
            pass
        time.sleep(0.05)


def interrupted_after_first_task(config, out) -> None:
    """Run ``config`` into ``out`` and stop it (KeyboardInterrupt, as Ctrl-C) once its first task has
    finished: what the resume tests resume from (the finished task's file stays in the work folder)."""
    from fkopt.run.pipeline import run_config

    def stop_after_one(label, done, total):
        if done == 1:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        run_config(config, out, progress=stop_after_one)
