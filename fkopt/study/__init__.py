"""Workspace studies: algorithms x poses x runs, with statistics, tracking and scale-out.

* :mod:`.config`     -- the YAML schema (``kind: study``), :func:`load_study`, :func:`load_any`;
* :mod:`.poses`      -- pose sets: uniform, grid, waypoints, circle;
* :mod:`.runner`     -- a study's tasks and merge for the one runner (:mod:`fkopt.experiment.tasks`:
  executors, task files, resume); :func:`run_study` (here) runs one through the pipeline;
* :mod:`.statistics` -- ECDF of evaluations to target, Wilcoxon rank-sum tests with Holm;
* :mod:`.reports`    -- the files of a study folder;
* :mod:`.kind`       -- studies as a kind of the one config pipeline (load, run, write, check).
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from .config import StudyConfig, load_study, study_from_dict
from .runner import StudyResult


def load_any(path: str | Path):
    """An experiment, study or assembly config, by the file's ``kind`` (:mod:`fkopt.experiment.kinds`)."""
    from ..experiment.kinds import load_any as load   # the registry imports this package's kind
    return load(path)


def run_study(config: StudyConfig, out: str | Path = "results", *, jobs: int = 1, executor: str = "local",
              scheduler: str | None = None, resume: bool = False,
              progress: Callable[[str, int, int], None] | None = None, source: str | None = None,
              keep_tasks: bool = True) -> StudyResult:
    """Run (or resume) a study into ``OUT/<paper>/<name>/`` through the one pipeline
    (:func:`fkopt.experiment.kinds.run_config`; the library call replaces an earlier result of
    any config, as ``--force`` does).

    ``progress(label, done, total)`` is called after each finished task (``done`` counts the
    tasks already on disk too). An exception raised by it (e.g. KeyboardInterrupt) stops the
    study; every task finished so far stays in the work folder for ``resume=True``, and a
    previous result stays complete. ``keep_tasks=False`` drops the task files once the study
    is written (``fkopt reproduce``).
    """
    # imported here: the registry of kinds (fkopt.experiment.kinds) imports this package's kind
    from ..experiment.kinds import run_config
    return run_config(config, out, source=source, progress=progress, force=True, jobs=jobs, executor=executor,
                      scheduler=scheduler, resume=resume, keep_tasks=keep_tasks).result


def rerun_in_memory(config: StudyConfig) -> StudyResult:
    """Every task computed in this process, nothing written (for checks and tests)."""
    from ..experiment.kinds import run_in_memory
    return run_in_memory(config)


__all__ = ["StudyConfig", "StudyResult", "load_any", "load_study", "run_study", "study_from_dict"]
