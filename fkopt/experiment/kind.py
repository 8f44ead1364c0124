"""Experiments as a kind of the one config pipeline (:mod:`fkopt.experiment.kinds`), and the
memory checks every kind's validation shares (:func:`check_memory`, :func:`algorithm_resources`)."""
from __future__ import annotations

import os

from ..errors import FkoptError
from ..solve import batch_bytes, chunk_size, make_algorithm
from .config import experiment_from_dict
from .runner import experiment_plan, keeps_x_history, merge_experiment
from .tasks import Kind

#: Share of the currently available memory a job may be estimated to need.
MEMORY_SHARE = 0.8


def available_memory() -> int:
    """Bytes of memory available now (``MemAvailable``; else the physical memory)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError):
        pass
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 1 << 62


def check_memory(needed: int, what: str) -> None:
    """Refuse a job estimated to need more than :data:`MEMORY_SHARE` of the available memory."""
    avail = available_memory()
    if needed > MEMORY_SHARE * avail:
        raise FkoptError(f"{what} needs about {needed / 2**30:.1f} GiB of memory, more than the "
                         f"{avail / 2**30:.1f} GiB available; reduce runs, population, iterations or cases")


# -- experiments -----------------------------------------------------------------------------------
def _experiment_validate(config, plan) -> int:
    mech, cases = plan.context.mech, plan.context.cases     # validated by experiment_plan
    dim, keep_x = len(mech.unknown_names), keeps_x_history(config, mech)
    need = 0   # every algorithm's records stay in memory until the folder is written: the solves' sum
    for spec in config.algorithms:
        pop = spec.population or config.population
        its = spec.iterations or config.iterations
        size = chunk_size(len(cases), config.runs, pop, its, dim, batch=config.batch,
                          snapshots=len(config.snapshots), x_history=keep_x)
        need += batch_bytes(len(cases) * config.runs, size, pop, its, dim, len(config.snapshots), keep_x)
        need += algorithm_resources(spec, pop, its, dim)
    return need


def algorithm_resources(spec, population: int, iterations: int, dim: int) -> int:
    """An algorithm's own memory beyond fkopt's arrays (an adapter's library population), or a
    one-line error naming it when its settings cannot run -- for every algorithm of a config,
    before the first one starts (:meth:`fkopt.algorithms.base.Algorithm.resources`)."""
    try:
        return int(make_algorithm(spec.name, spec.params).resources(population, iterations, dim))
    except FkoptError as err:
        raise FkoptError(f"algorithms[{spec.key}]: {err}") from None


def _experiment_merge(config, plan, ran, *, source=None, **_):
    return merge_experiment(config, plan, ran, source=source)


def _experiment_from_dict(data: dict, where: str):
    if "kind" in data:
        data = {k: v for k, v in data.items() if k != "kind"}
    return experiment_from_dict(data, where)


EXPERIMENT = Kind("experiment", _experiment_from_dict, experiment_plan, _experiment_validate, _experiment_merge)
