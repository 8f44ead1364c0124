"""Workspace studies: algorithms x poses x runs, with statistics, tracking and scale-out.

* :mod:`.config`     -- the YAML schema (``kind: study``), :func:`load_study`, :func:`load_any`;
* :mod:`.poses`      -- pose sets: uniform, grid, waypoints, circle;
* :mod:`.runner`     -- a study's tasks and merge for the one runner (:mod:`fkopt.experiment.tasks`:
  executors, task files, resume): :func:`run_study`;
* :mod:`.statistics` -- ECDF of evaluations to target, Wilcoxon rank-sum tests with Holm;
* :mod:`.reports`    -- the files of a study folder;
* :mod:`.kind`       -- studies as a kind of the one config pipeline (load, run, write, check).
"""
from .config import StudyConfig, load_any, load_study, study_from_dict
from .runner import StudyResult, run_study

__all__ = ["StudyConfig", "StudyResult", "load_any", "load_study", "run_study", "study_from_dict"]
