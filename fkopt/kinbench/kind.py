"""Suites as a kind of the one config pipeline (:mod:`fkopt.experiment.kinds`)."""
from __future__ import annotations

from pathlib import Path

from ..experiment.kinds import Kind
from ..experiment.tasks import work_folder  # noqa: F401 (where a suite's task files live; tests)
from .config import SuiteConfig, suite_from_dict


def _validate(config: SuiteConfig) -> tuple[int, int]:
    from .runner import validate_suite
    return validate_suite(config)


def _plan(config: SuiteConfig, source):
    from .runner import suite_plan
    return suite_plan(config, source)


def _merge(config: SuiteConfig, plan, ran, **options):
    from .runner import merge_suite
    return merge_suite(config, plan, ran, **options)


def _from_dict(data: dict, where: str) -> SuiteConfig:
    config = suite_from_dict(data, where)
    if where and Path(where).suffix in (".yaml", ".yml"):
        config._folder = Path(where).parent
    return config


SUITE = Kind("suite", _from_dict, _validate, _plan, _merge)
