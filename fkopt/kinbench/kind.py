"""Suites as a kind of the one config pipeline (:mod:`fkopt.experiment.kinds`)."""
from __future__ import annotations

import shutil
from pathlib import Path

from ..experiment.kinds import Kind, Outcome
from ..outputs import write_outputs, write_result
from .config import SuiteConfig, suite_from_dict


def _validate(config: SuiteConfig) -> tuple[int, int]:
    from .runner import validate_suite
    return validate_suite(config)


def work_folder(out, config: SuiteConfig) -> Path:
    """Where an unfinished run keeps its task files: ``OUT/<paper>/.<name>.partial/`` (hidden:
    never taken for a result)."""
    paper, name = config.folder_parts
    return Path(out) / paper / f".{name}.partial"


def _run(config: SuiteConfig, out, *, source=None, progress=None, jobs: int = 1, executor: str = "local",
         scheduler: str | None = None, resume: bool = False, publish_check=None, **_) -> Outcome:
    from ..files import inside
    from ..study.executors import check_scheduler
    from .runner import run_suite
    work = inside(out, work_folder(out, config))      # no task file written or read through a link
    check_scheduler(executor, scheduler)              # reachable before the work folder is touched
    result = run_suite(config, source=source, progress=progress, jobs=jobs, executor=executor, scheduler=scheduler,
                       work=work, resume=resume)
    folder = write_result("suite", result, out, publish_check)
    shutil.rmtree(work, ignore_errors=True)
    return Outcome(folder, result.wall_s, result)


def _rerun_files(config: SuiteConfig, folder: Path, source: str | None) -> None:
    from .runner import run_suite
    write_outputs("suite", run_suite(config, source=source), folder, figures=False, timing=False)


def _from_dict(data: dict, where: str) -> SuiteConfig:
    config = suite_from_dict(data, where)
    if where and Path(where).suffix in (".yaml", ".yml"):
        config._folder = Path(where).parent
    return config


SUITE = Kind("suite", _from_dict, _validate, _run, _rerun_files)
