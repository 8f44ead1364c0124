"""The memory a job may take (floor 3, the engine): every kind's validation estimates its bytes
(:attr:`fkopt.run.tasks.Kind.validate`) and :func:`check_memory` refuses a job that cannot fit,
with one line, before any work; :func:`algorithm_resources` adds an algorithm's own memory (an
adapter's library population) and refuses settings it cannot run."""
from __future__ import annotations

import os

from fkopt.errors import FkoptError
from fkopt.solve import make_algorithm

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


def algorithm_resources(spec, population: int, iterations: int, dim: int) -> int:
    """An algorithm's own memory beyond fkopt's arrays (an adapter's library population), or a
    one-line error naming it when its settings cannot run -- for every algorithm of a config,
    before the first one starts (:meth:`fkopt.algorithms.base.Algorithm.resources`)."""
    try:
        return int(make_algorithm(spec.name, spec.params).resources(population, iterations, dim))
    except FkoptError as err:
        raise FkoptError(f"algorithms[{spec.key}]: {err}") from None
