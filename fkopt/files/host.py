"""What this machine lets the process use: the CPUs it may run on (worker counts are bounded by
them), and which release of a package is installed (env.json, boards' settings, messages)."""
from __future__ import annotations

import os


def installed_version(distribution: str) -> str | None:
    """The installed version of a distribution ("numba" -> "0.61.2"), or None when it is not
    installed (fkopt itself run from a source tree). The one lookup every caller words its own way."""
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version(distribution)
    except PackageNotFoundError:
        return None


def available_cpus() -> int:
    """CPUs this process may run on (its affinity mask, else the CPU count)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)
