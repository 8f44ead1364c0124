"""Studies as a kind of the one config pipeline (:mod:`fkopt.experiment.kinds`)."""
from __future__ import annotations

from ..experiment.kind import algorithm_resources
from ..experiment.tasks import Kind
from ..solve import batch_bytes, chunk_size
from .config import StudyConfig, study_from_dict
from .runner import merge_study, study_plan


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
        # kept for every (pose, run): fitness, counts, solution, as JSON task records (~10x)
        kept += n * config.runs * (dim + 6) * 8 * 10
    return work + kept


STUDY = Kind("study", study_from_dict, study_plan, _validate, merge_study)
