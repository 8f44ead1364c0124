"""Suites as a kind of the one config pipeline (:mod:`fkopt.experiment.kinds`)."""
from __future__ import annotations

from pathlib import Path

from ..experiment.tasks import Kind
from ..experiment.tasks import work_folder  # noqa: F401 (where a suite's task files live; tests)
from .config import SuiteConfig, suite_from_dict
from .runner import merge_suite, suite_plan, validate_suite


def _from_dict(data: dict, where: str) -> SuiteConfig:
    config = suite_from_dict(data, where)
    if where and Path(where).suffix in (".yaml", ".yml"):
        config._folder = Path(where).parent
    return config


SUITE = Kind("suite", _from_dict, suite_plan, validate_suite, merge_suite)
