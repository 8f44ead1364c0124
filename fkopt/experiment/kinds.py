"""The three kinds of files under ``configs/`` and what each needs before it runs.

* experiments (no ``kind``): :mod:`fkopt.experiment.config`;
* ``kind: study``: workspace studies, :mod:`fkopt.study`;
* ``kind: assembly``: all forward solutions, :mod:`fkopt.experiment.assembly`.
"""
from __future__ import annotations

from ..errors import FkoptError


def load_any(path):
    """An experiment, study or assembly config, by the file's ``kind``."""
    from ..study.config import load_any as load
    return load(path)


def validate_any(config) -> int:
    """Build everything a config needs without running it; returns its number of tasks."""
    from ..study.config import StudyConfig
    from .assembly import AssemblyConfig
    from .runner import build_mechanism, validate_experiment
    if isinstance(config, AssemblyConfig):
        mech = build_mechanism(config)
        if mech.kind != "parallel":
            raise FkoptError(f"mechanism '{mech.name}' is {mech.kind}; assembly modes need a parallel mechanism")
        mech.vector(config.joints, mech.joint_names, "joints")
        return 1
    if isinstance(config, StudyConfig):
        from ..study.runner import plan_tasks, validate_study
        return len(plan_tasks(config, len(validate_study(config)[1])))
    mech, cases, _ = validate_experiment(config)
    return len(config.algorithms) * len(cases)
