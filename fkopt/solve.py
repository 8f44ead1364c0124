"""``fkopt.solve(problem, algorithm, ...)``: run an algorithm, by registered name or as an object, on
a problem for several seeded runs (the public API, floor 2 of docs/design.md).

Names resolve through the one solver registry (:mod:`fkopt.registry`: built-in, adapters,
entry points, plug-ins); the runs themselves -- rows, per-row random streams, chunks, memory --
are :mod:`fkopt.algorithms.runs`, whose docstring says how.
"""
from __future__ import annotations

from typing import Any, Sequence

from fkopt.algorithms.base import Algorithm
from fkopt.algorithms.runs import (CHUNK_POINTS, MEMORY_LIMIT, Result, batch_bytes, case_seeds,  # noqa: F401
                                   check_record, chunk_size, contained, pick_events, plugin_of, validate_budget)
from fkopt.algorithms.runs import solve as run_algorithm
from fkopt.errors import FkoptError
from fkopt.registry import algorithm_class


def make_algorithm(algorithm: str | Algorithm, params: dict[str, Any] | None = None) -> Algorithm:
    """The algorithm a registered name (with ``params``) or an object names; a plug-in's
    constructor runs contained (its failure is one line naming it)."""
    if isinstance(algorithm, Algorithm):
        if params:
            raise FkoptError("pass parameters either to the algorithm object or to solve(), not both")
        return algorithm
    cls = algorithm_class(algorithm)
    who = f"algorithm plug-in '{algorithm}' ({plugin_of(cls)})" if plugin_of(cls) else None
    return contained(who, lambda: cls(**(params or {})))


def solve(problem, algorithm: str | Algorithm, *, population: int = 10, iterations: int = 100,
          runs: int = 1, seed: int | Sequence[int] = 0, target: float | None = None,
          stop_at_target: bool = False, x0=None, run_ids=None, batch: bool = True, snapshots=(),
          x_history: bool = False, chunk_rows: int | None = None,
          params: dict[str, Any] | None = None) -> Result:
    """Minimise ``problem.fitness`` with ``algorithm`` over ``runs`` seeded runs of every case.

    ``algorithm`` is a registered name (with ``params``) or an :class:`Algorithm` instance; the
    other arguments are :func:`fkopt.algorithms.runs.solve`'s (seeds, target, starts, run ids,
    snapshots, chunks).
    """
    return run_algorithm(problem, make_algorithm(algorithm, params), population=population, iterations=iterations,
                         runs=runs, seed=seed, target=target, stop_at_target=stop_at_target, x0=x0, run_ids=run_ids,
                         batch=batch, snapshots=snapshots, x_history=x_history, chunk_rows=chunk_rows)
