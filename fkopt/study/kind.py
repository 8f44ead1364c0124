"""Studies as a kind of the one config pipeline (:mod:`fkopt.experiment.kinds`)."""
from __future__ import annotations

from pathlib import Path

from ..experiment.kinds import Kind, Outcome
from ..outputs import write_outputs
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


def _run(config: StudyConfig, out, *, source=None, progress=None, jobs: int = 1, executor: str = "local",
         scheduler: str | None = None, resume: bool = False, keep_tasks: bool = True, publish_check=None,
         **_) -> Outcome:
    from .runner import run_study
    result = run_study(config, out, jobs=jobs, executor=executor, scheduler=scheduler, resume=resume,
                       progress=progress, source=source, keep_tasks=keep_tasks, publish_check=publish_check)
    return Outcome(result.folder, result.wall_s, result)


def _rerun_files(config: StudyConfig, folder: Path, source: str | None) -> None:
    from .runner import rerun_in_memory
    result = rerun_in_memory(config)
    result.source = source
    write_outputs("study", result, folder, figures=False, timing=False)


STUDY = Kind("study", lambda data, where: study_from_dict(data, where), _validate, _run, _rerun_files)
