"""Workspace studies: algorithms x poses x runs, with statistics, tracking and scale-out.

* :mod:`.config`     -- the YAML schema (``kind: study``), :func:`load_study`;
* :mod:`.poses`      -- pose sets: uniform, grid, waypoints, circle;
* :mod:`.runner`     -- a study's tasks and merge for the one runner (:mod:`fkopt.run.tasks`:
  executors, task files, resume); :func:`run_study` (here) runs one through the pipeline;
* :mod:`.statistics` -- ECDF of evaluations to target, Wilcoxon rank-sum tests with Holm;
* :mod:`.reports`    -- the files of a study folder;
* :mod:`.kind`       -- studies as a kind of the one config pipeline (load, run, write, check).
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from fkopt.kinds.study.config import StudyConfig, load_study, study_from_dict
from fkopt.kinds.study.kind import STUDY  # noqa: F401 (registers the kind)
from fkopt.run.result import RunResult
from fkopt.run.pipeline import run_config, run_in_memory


def run_study(config: StudyConfig, out: str | Path = "results", *, jobs: int = 1, executor: str = "local",
              scheduler: str | None = None, resume: bool = False,
              progress: Callable[[str, int, int], None] | None = None, source: str | None = None,
              keep_tasks: bool = True) -> RunResult:
    """Run (or resume) a study into ``OUT/<paper>/<name>/`` through the one pipeline
    (:func:`fkopt.run.pipeline.run_config`; the library call replaces an earlier result of
    any config, as ``--force`` does).

    ``progress(label, done, total)`` is called after each finished task (``done`` counts the
    tasks already on disk too). An exception raised by it (e.g. KeyboardInterrupt) stops the
    study; every task finished so far stays in the work folder for ``resume=True``, and a
    previous result stays complete. ``keep_tasks=False`` drops the task files once the study
    is written (``fkopt reproduce``).
    """
    return run_config(config, out, source=source, progress=progress, force=True, jobs=jobs, executor=executor,
                      scheduler=scheduler, resume=resume, keep_tasks=keep_tasks).result


def rerun_in_memory(config: StudyConfig) -> RunResult:
    """Every task computed in this process, nothing written (for checks and tests)."""
    return run_in_memory(config)


__all__ = ["StudyConfig", "load_study", "run_study", "study_from_dict"]
