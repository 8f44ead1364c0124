"""Experiments as a kind of the one config pipeline (:mod:`fkopt.run.pipeline`)."""
from __future__ import annotations

from fkopt.run.memory import algorithm_resources
from fkopt.solve import batch_bytes, chunk_size
from fkopt.kinds.experiment.config import ExperimentConfig, experiment_from_dict
from fkopt.kinds.experiment.runner import (build_cases, build_problem, experiment_plan, keeps_x_history, merge_experiment,
                                           one_answer_entries)
from fkopt.kinds.experiment import reports
from fkopt.kinds.experiment.ioh_functions import experiment_functions
from fkopt.run.kinds import register
from fkopt.run.record import ALGORITHM_NAMES
from fkopt.run.solving import build_mechanism
from fkopt.run.tasks import Kind
from fkopt.run.writers import (CURVES, FIGURE, RUNS, RUNS_FILE, STEPS, TABLE, TIMING, TIMING_RUNS_FILE, TRACE_FILE,
                               Output)

# -- experiments -----------------------------------------------------------------------------------
def _experiment_validate(config, plan) -> int:
    mech, cases = plan.context.mech, plan.context.cases     # validated by experiment_plan
    dim, keep_x = len(mech.unknown_names), keeps_x_history(config, mech)
    need = 0   # every algorithm's records stay in memory until the folder is written: the solves' sum
    for spec in one_answer_entries(config):      # a search of every solution keeps a few rows per case
        pop = spec.population or config.population
        its = spec.iterations or config.iterations
        size = chunk_size(len(cases), config.runs, pop, its, dim, batch=config.batch,
                          snapshots=len(config.snapshots), x_history=keep_x)
        need += batch_bytes(len(cases) * config.runs, size, pop, its, dim, len(config.snapshots), keep_x)
        need += algorithm_resources(spec, pop, its, dim)
    return need


def _experiment_from_dict(data: dict, where: str):
    if "kind" in data:
        data = {k: v for k, v in data.items() if k != "kind"}
    return experiment_from_dict(data, where)


def _stored_problems(config, runs) -> list:
    """``fkopt check``'s recomputed fitness: each case's rows of runs.csv and its problem."""
    mech = build_mechanism(config)
    return [(case.label, runs["case"].astype(str) == case.label, lambda c=case: build_problem(config, mech, c))
            for case in build_cases(config, mech)]


#: The files of an experiment's folder, in the order they are written.
OUTPUTS = (
    Output("summary.csv", reports.summary_table, TABLE),
    Output("timing.csv", reports.timing_table, TIMING),
    TIMING_RUNS_FILE,
    Output("values.csv", reports.values_table, TABLE),
    Output("inputs.csv", reports.inputs_table, TABLE),
    Output("solutions.csv", reports.solutions_table, CURVES, float_format="%.12g", rows=RUNS),
    RUNS_FILE,
    TRACE_FILE,
    Output("convergence.csv", reports.convergence_table, CURVES, rows=STEPS),
    Output("convergence", reports.convergence_figure, FIGURE),
    Output("variables", reports.variables_figure, FIGURE),
    Output("snapshots", reports.snapshot_figures, FIGURE),
    Output("extras", reports.extras_figure, FIGURE),
    Output("cases", reports.cases_figures, FIGURE),
    Output("time", reports.time_figure, FIGURE),
    Output("position_error", reports.position_error_figure, FIGURE),
)

EXPERIMENT = register(Kind("experiment", _experiment_from_dict, experiment_plan, _experiment_validate,
                           merge_experiment, OUTPUTS, reports.meta, ExperimentConfig,
                           console=reports.console, stored_problems=_stored_problems,
                           ioh_functions=experiment_functions,
                           # runs.csv: its case label names the pose; one problem per folder
                           not_in_runs=frozenset({"kind", "problem", "pose"}), file_names=ALGORITHM_NAMES))
