"""Studies as a kind of the one config pipeline (:mod:`fkopt.run.pipeline`)."""
from __future__ import annotations

from fkopt.run.memory import algorithm_resources
from fkopt.kinds.study import reports
from fkopt.run.kinds import register
from fkopt.run.record import ALGORITHM_NAMES
from fkopt.run.solving import build_mechanism, make_problem
from fkopt.run.tasks import Kind
from fkopt.run.writers import CURVES, FIGURE, RUNS_FILE, STEPS, TABLE, TIMING, Output
from fkopt.solve import batch_bytes, chunk_size
from fkopt.kinds.study.config import StudyConfig, study_from_dict
from fkopt.kinds.study.poses import build_poses
from fkopt.kinds.study.runner import merge_study, study_plan


def _validate(config: StudyConfig, plan) -> int:
    mech, poses = plan.context.mech, plan.context.poses     # validated by study_plan
    dim, n = len(mech.unknown_names), len(poses)
    # rows of one solve: a chunk of poses x runs, or (tracking) the trajectories x runs of a step
    cases = len(poses.segments) if config.mode == "tracking" else min(config.chunk, n)
    work = kept = 0
    for spec in config.algorithms:
        pop = spec.population or config.population
        its = spec.iterations or config.iterations
        size = chunk_size(cases, config.runs, pop, its, dim)      # refuses a solve over the per-solve limit
        work = max(work, batch_bytes(cases * config.runs, size, pop, its, dim)
                   + algorithm_resources(spec, pop, its, dim))
        # kept for every (pose, run): its row of the run record (10 fixed columns, the solution, its
        # start when tracking, its error per pose variable) as JSON task records (~10x)
        kept += n * config.runs * (10 + 2 * dim + len(mech.pose_names)) * 8 * 10
    return work + kept


def _stored_problems(config: StudyConfig, runs) -> list:
    """``fkopt check``'s recomputed fitness: one problem per pose of the pose set, and its rows."""
    mech = build_mechanism(config)
    poses = build_poses(config, mech)
    # poses count from 0 (fkopt.run.record); a folder written before the run record counted from 1
    first = 1 if len(runs) and runs["pose"].min() >= 1 else 0
    return [(f"pose {i}", runs["pose"] == i + first, lambda i=i: make_problem(config, mech, poses.inputs[i]))
            for i in range(len(poses))]


#: The files of a study's folder, in the order they are written.
OUTPUTS = (
    Output("summary.csv", reports.summary_table, TABLE),
    Output("timing.csv", reports.timing_table, TIMING),
    Output("poses.csv", reports.poses_table, CURVES),
    RUNS_FILE,
    Output("ecdf.csv", reports.ecdf_of, CURVES, rows=STEPS),
    Output("stats.csv", reports.stats_of, CURVES),
    Output("heatmap.csv", reports.heatmap_table, CURVES),
    Output("tracking.csv", reports.tracking_table, CURVES),
    Output("tracking_timing.csv", reports.tracking_timing_table, TIMING),
    Output("ecdf", reports.ecdf_figure, FIGURE),
    Output("heatmap", reports.heatmap_figure, FIGURE),
    Output("tracking", reports.tracking_figure, FIGURE),
    Output("tracking_time", reports.tracking_time_figure, FIGURE),
)

STUDY = register(Kind("study", study_from_dict, study_plan, _validate, merge_study, OUTPUTS, reports.meta, StudyConfig,
                      console=lambda result, folder: reports.summary_table(result), stored_problems=_stored_problems,
                      # runs.csv: a study has poses, not cases; one problem per folder
                      not_in_runs=frozenset({"kind", "problem", "case"}), file_names=ALGORITHM_NAMES))
