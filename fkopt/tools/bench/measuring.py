"""What every section of ``fkopt bench`` measures with: the rows of ``bench.csv``
(:class:`Rows`), the best and the mean time of a call, uniform points in a box, the machine's
load average and description, and the mao2017 3-RPS case several sections time."""
from __future__ import annotations

import os
import platform
import time
from pathlib import Path

import numpy as np

import fkopt
from fkopt.problems import fk_problem

#: mao2017 Tab. 3: mean time per run (ms) in MATLAB on an i7-4510U.
PAPER_MS = {"aco": 250.6, "abc": 362.4, "gabc": 361.3}
#: The pose of mao2017's Tab. 2/3 case (alpha, beta in deg, z in mm).
MAO_POSE = (9.0, 13.0, 622.0)


class Rows:
    """The rows of ``bench.csv``: section, item, value, unit, note."""

    def __init__(self):
        self.rows: list[dict] = []

    def add(self, section, item, value, unit, note=""):
        self.rows.append(dict(section=section, item=item, value=float(value), unit=unit, note=note))


def best_call_time(fn, min_time: float, min_calls: int = 5) -> float:
    """Smallest wall time of one ``fn()`` call over at least ``min_calls`` calls / ``min_time`` s."""
    fn()   # warm-up
    best, spent, n = np.inf, 0.0, 0
    while n < min_calls or spent < min_time:
        t = time.perf_counter()
        fn()
        dt = time.perf_counter() - t
        best, spent, n = min(best, dt), spent + dt, n + 1
    return best


def single_call_time(fn, min_time: float) -> float:
    """Mean wall time of one cheap call, from loops of 200 calls (best loop)."""
    fn()
    best, spent = np.inf, 0.0
    while spent < min_time or best == np.inf:
        t = time.perf_counter()
        for _ in range(200):
            fn()
        dt = time.perf_counter() - t
        best, spent = min(best, dt / 200), spent + dt
    return best


def uniform(bounds: np.ndarray, shape, rng) -> np.ndarray:
    """Points of ``shape`` uniform in the box ``bounds`` (n, 2)."""
    lo, hi = bounds[:, 0], bounds[:, 1]
    return lo + rng.random((*shape, len(lo))) * (hi - lo)


def mao_problem():
    """mao2017's 3-RPS case as an FK problem (the paper's Tab. 3 experiment)."""
    m = fkopt.mechanism("3-rps")
    return fk_problem(m, m.ik(np.array(MAO_POSE)))


def load_average() -> str:
    """The 1-, 5- and 15-minute load averages, for the notes of timed rows (this machine is shared)."""
    try:
        return " ".join(f"{v:.2f}" for v in os.getloadavg())
    except (AttributeError, OSError):                # pragma: no cover - not on Linux/macOS
        return "unknown"


def machine() -> dict[str, str]:
    """CPUs, CPU model, numpy and Python versions: the title of the printed table."""
    cpu = platform.processor() or "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"cpus": str(os.cpu_count()), "cpu": cpu, "numpy": np.__version__,
            "python": platform.python_version()}
