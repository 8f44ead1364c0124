"""Studies as a kind of the one config pipeline (:mod:`fkopt.experiment.kinds`)."""
from __future__ import annotations

from ..experiment.kind import algorithm_resources
from ..experiment.tasks import Kind
from ..solve import batch_bytes, chunk_size
from .config import StudyConfig, study_from_dict
from .runner import merge_study, plan_tasks, study_plan, validate_study


def _validate(config: StudyConfig) -> tuple[int, int]:
    mech, poses = validate_study(config)
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
        # kept for every (pose, run): fitness, counts, solution, as JSON task records (~10x)
        kept += n * config.runs * (dim + 6) * 8 * 10
    return len(plan_tasks(config, n)), work + kept


STUDY = Kind("study", study_from_dict, _validate, study_plan, merge_study)
