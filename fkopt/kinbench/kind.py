"""Suites as a kind of the one config pipeline (:mod:`fkopt.run.pipeline`)."""
from __future__ import annotations

from pathlib import Path

from fkopt.kinbench import branch_tracks, pages, reports
from fkopt.run.kinds import register
from fkopt.run.tasks import Kind
from fkopt.run.tasks import work_folder  # noqa: F401 (where a suite's task files live; tests)
from fkopt.run.writers import CURVES, FIGURE, RUNS_FILE, STEPS, TABLE, TIMING, TRACE_FILE, Output
from fkopt.kinbench.config import SuiteConfig, suite_from_dict
from fkopt.kinbench.runner import merge_suite, suite_plan, validate_suite
from fkopt.kinbench.traces import suite_functions
from fkopt.kinbench.verify import reverify


def _from_dict(data: dict, where: str) -> SuiteConfig:
    config = suite_from_dict(data, where)
    if where and Path(where).suffix in (".yaml", ".yml"):
        config._folder = Path(where).parent
    return config


#: The files of a suite's folder, in the order they are written.
OUTPUTS = (
    Output("leaderboard.csv", reports.leaderboard_table, TABLE),
    Output("measures.csv", reports.measures_table, TABLE),
    Output("scaling.csv", reports.scaling_table, TABLE),      # classes of several dimensions only
    Output("ert_ratio.csv", reports.ert_ratio_table, TABLE),  # suites with subsets (v3) only
    Output("ecdf.csv", reports.ecdf_table, CURVES, rows=STEPS),
    RUNS_FILE,
    TRACE_FILE,
    Output("timing.csv", reports.timing_table, TIMING),
    # kinbench v3's tracks on the clock: wall times (and TRAC-IK's wall-clock outcomes) vary
    Output("answers.csv.gz", reports.answers_table, TIMING, float_format="%.17g"),
    Output("throughput.csv", reports.throughput_table, TIMING),
    Output("leaderboard-robots.csv", reports.robots_board_table, TIMING),
    # the all-solutions and paths tracks (fkopt.kinbench.branch_tracks): timing files too
    Output("solutions.csv.gz", branch_tracks.solutions_table, TIMING, float_format="%.17g"),
    Output("leaderboard-solutions.csv", branch_tracks.solutions_board_table, TIMING),
    Output("paths.csv.gz", branch_tracks.paths_table, TIMING, float_format="%.17g"),
    Output("leaderboard-paths.csv", branch_tracks.paths_board_table, TIMING),
    Output("ecdf", reports.ecdf_figures, FIGURE),
    Output("scaling", reports.scaling_figures, FIGURE),
    Output("clock", reports.clock_figures, FIGURE),
    Output("leaderboard.md", reports.leaderboard_markdown, FIGURE),   # never compared
    Output("index.html", pages.html_page, FIGURE),     # and arms.html, rankings.html (kinbench.pages)
)

def _console(result, folder: Path) -> list[str]:
    """After a run: the files to open, then the board's top lines."""
    return [": leaderboard.md, index.html", *reports.board_top_lines(folder)]


def _recheck(folder: Path, config: SuiteConfig, meta: dict) -> list[tuple]:
    """``fkopt check`` of a v3 suite: every stored answer judged again with fkopt's FK and the
    per-robot board recomputed from them (:func:`fkopt.kinbench.verify.reverify`)."""
    if config.tracks is None:
        return []
    if config._folder is None and meta.get("config_file"):
        config._folder = Path(meta["config_file"]).parent
    return reverify(folder, config)


SUITE = register(Kind("suite", _from_dict, suite_plan, validate_suite, merge_suite, OUTPUTS, reports.meta, SuiteConfig,
                      _console, reproduced=False, recheck=_recheck, report_section=reports.report_section,
                      ioh_functions=suite_functions,
                      # runs.csv keeps the layout of the frozen kinbench releases, whose stored folders
                      # are not rerun to add a column: a suite's seeds stay in its task files
                      not_in_runs=frozenset({"kind", "case", "task_seed"})))
