"""``solve(problem, algorithm, ...)``: run an algorithm on a problem for several seeded runs.

Runs advance together as one batch (arrays shaped (runs, population, dim)) by default; with
``batch=False`` each run is solved on its own, one after the other -- the reference mode that
proves batching never changes the numbers (run k uses the same stream either way, see
:mod:`fkopt.streams`).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .algorithms.base import Algorithm, RunRecord
from .errors import FkoptError
from .registry import algorithm_class
from .streams import RunStreams


@dataclass
class Result:
    """Outcome of ``runs`` independent runs of one algorithm on one problem.

    Arrays are indexed by run first. ``history[k, t]`` is run k's best-so-far fitness after
    iteration t (t = 0 is the initial population), ``evaluation_history`` the matching
    cumulative count of fitness evaluations. ``time_per_run`` is the wall time of the batch
    divided by the number of runs (amortised) in batch mode, the run's own time otherwise.
    """

    algorithm: str
    params: dict[str, Any]
    variable_names: tuple[str, ...]
    seed: int
    run_ids: np.ndarray
    population: int
    iterations: int
    x: np.ndarray
    fitness: np.ndarray
    history: np.ndarray
    x_history: np.ndarray
    evaluation_history: np.ndarray
    iterations_done: np.ndarray
    time_per_run: np.ndarray
    target: float | None = None
    extras: dict[str, np.ndarray] = field(default_factory=dict)
    snapshots: dict[int, np.ndarray] = field(default_factory=dict)

    @property
    def runs(self) -> int:
        return len(self.run_ids)

    @property
    def evaluations(self) -> np.ndarray:
        """Fitness evaluations used per run (up to the stop, when stopping at a target)."""
        return self.evaluation_history[np.arange(self.runs), self.iterations_done]

    def iterations_to(self, threshold: float) -> np.ndarray:
        """First iteration at which each run's best fitness was below ``threshold`` (NaN: never)."""
        hit = self.history < threshold
        first = np.argmax(hit, axis=1).astype(float)
        first[~hit.any(axis=1)] = np.nan
        return first

    def evaluations_to(self, threshold: float) -> np.ndarray:
        """Evaluations used when each run first went below ``threshold`` (NaN: never)."""
        it = self.iterations_to(threshold)
        out = np.full(self.runs, np.nan)
        ok = ~np.isnan(it)
        out[ok] = self.evaluation_history[np.flatnonzero(ok), it[ok].astype(int)]
        return out

    def success(self, threshold: float) -> np.ndarray:
        return self.fitness < threshold

    @property
    def best_run(self) -> int:
        return int(np.argmin(self.fitness))

    @property
    def median_run(self) -> int:
        """The run whose final fitness is the (lower) median over all runs."""
        order = np.argsort(self.fitness, kind="stable")
        return int(order[(self.runs - 1) // 2])

    def __repr__(self) -> str:
        return (f"Result({self.algorithm}, runs={self.runs}, median fitness="
                f"{np.median(self.fitness):.3g}, best={self.fitness.min():.3g})")


def make_algorithm(algorithm: str | Algorithm, params: dict[str, Any] | None = None) -> Algorithm:
    if isinstance(algorithm, Algorithm):
        if params:
            raise FkoptError("pass parameters either to the algorithm object or to solve(), not both")
        return algorithm
    return algorithm_class(algorithm)(**(params or {}))


def validate_budget(population: int, iterations: int, runs: int, local: bool = False) -> None:
    if int(population) < (1 if local else 2):
        raise FkoptError(f"population must be at least {1 if local else 2}, got {population}")
    if int(iterations) < 1:
        raise FkoptError(f"iterations must be at least 1, got {iterations}")
    if int(runs) < 1:
        raise FkoptError(f"runs must be at least 1, got {runs}")


def solve(problem, algorithm: str | Algorithm, *, population: int = 10, iterations: int = 100,
          runs: int = 1, seed: int = 0, target: float | None = None, stop_at_target: bool = False,
          x0=None, run_ids=None, batch: bool = True, snapshots=(), params: dict[str, Any] | None = None,
          ) -> Result:
    """Minimise ``problem.fitness`` with ``algorithm`` over ``runs`` seeded runs.

    ``algorithm`` is a registered name (with ``params``) or an :class:`Algorithm` instance.
    ``target`` is a fitness threshold: iterations/evaluations to reach it are reported, and
    with ``stop_at_target`` each run stops there. ``x0`` is the start point of local methods
    (``nr``, ``lm``); ``run_ids`` selects which runs of the seed to compute (default 0..runs-1).
    """
    algo = make_algorithm(algorithm, params)
    validate_budget(population, iterations, runs, algo.local)
    ids = np.arange(runs) if run_ids is None else np.asarray(run_ids, dtype=int)
    if x0 is not None:
        x0 = np.asarray(x0, dtype=float)
        if x0.shape[-1] != problem.dim:
            raise FkoptError(f"start point has {x0.shape[-1]} values, the problem has {problem.dim} "
                             f"({', '.join(problem.variable_names)})")
    kwargs = dict(population=int(population), iterations=int(iterations), target=target,
                  stop_at_target=stop_at_target, x0=x0, snapshots=snapshots)
    if batch:
        start = time.perf_counter()
        record = algo.minimize(problem, streams=RunStreams(seed, ids), **kwargs)
        elapsed = time.perf_counter() - start
        times = np.full(len(ids), elapsed / len(ids))
    else:
        parts: list[RunRecord] = []
        times = np.empty(len(ids))
        for n, k in enumerate(ids):
            start = time.perf_counter()
            parts.append(algo.minimize(problem, streams=RunStreams(seed, [k]), **kwargs))
            times[n] = time.perf_counter() - start
        record = _concatenate(parts)
    return Result(
        algorithm=algo.name, params=algo.params.model_dump(), variable_names=tuple(problem.variable_names),
        seed=int(seed), run_ids=ids, population=int(population), iterations=int(iterations),
        x=record.best_x, fitness=record.best_f, history=record.history, x_history=record.x_history,
        evaluation_history=record.evaluation_history, iterations_done=record.iterations_done,
        time_per_run=times, target=target, extras=record.extras, snapshots=record.snapshots,
    )


def _concatenate(parts: list[RunRecord]) -> RunRecord:
    cat = lambda name: np.concatenate([getattr(p, name) for p in parts])  # noqa: E731
    return RunRecord(
        best_x=cat("best_x"), best_f=cat("best_f"), history=cat("history"), x_history=cat("x_history"),
        evaluation_history=cat("evaluation_history"), iterations_done=cat("iterations_done"),
        extras={k: np.concatenate([p.extras[k] for p in parts]) for k in parts[0].extras},
        snapshots={k: np.concatenate([p.snapshots[k] for p in parts]) for k in parts[0].snapshots},
    )
