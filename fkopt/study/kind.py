"""Studies as a kind of the one config pipeline (:mod:`fkopt.experiment.kinds`)."""
from __future__ import annotations

from ..experiment.kinds import Kind
from .config import StudyConfig, study_from_dict


def _validate(config: StudyConfig) -> tuple[int, int]:
    from ..experiment.kinds import algorithm_resources
    from ..solve import batch_bytes, chunk_size
    from .runner import plan_tasks, validate_study
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


def _plan(config: StudyConfig, source):
    from .runner import study_plan
    return study_plan(config, source)


def _merge(config: StudyConfig, plan, ran, **options):
    from .runner import merge_study
    return merge_study(config, plan, ran, **options)


STUDY = Kind("study", lambda data, where: study_from_dict(data, where), _validate, _plan, _merge)
