"""The algorithm protocol and the shared iteration loop.

An algorithm implements two methods on a :class:`State` holding arrays shaped
(runs, population, dim):

* ``initialize(problem, population, streams, x0)`` sets ``state.x`` (the algorithm's memory:
  ABC food sources, PSO personal bests, ant positions ...), ``state.f`` (their fitness) and
  ``state.evaluations`` (fitness evaluations so far, per run);
* ``iterate(state, problem, streams)`` advances every run by one iteration of the method.

:meth:`Algorithm.minimize` owns everything else, identically for every algorithm: the
best-so-far point and fitness per run, the history arrays (runs x (iterations + 1)), counting
evaluations, stopping at a target, snapshots of the population. All runs advance together; a
run that reached the target (with ``stop_at_target``) is frozen in the records from that
iteration on, so its numbers do not depend on the other runs of the batch.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any, ClassVar

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationError

from ..errors import FkoptError
from ..streams import RunStreams


class Params(BaseModel):
    """Base of every algorithm's parameter model (unknown keys are rejected)."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class State:
    """Mutable per-batch state; algorithms attach whatever arrays they need."""

    x: np.ndarray
    f: np.ndarray
    evaluations: np.ndarray
    best_x: np.ndarray
    best_f: np.ndarray

    def __init__(self, **arrays: Any):
        self.__dict__.update(arrays)


@dataclass
class RunRecord:
    """What one batch of runs produced (before timing is attached by :func:`fkopt.solve`)."""

    best_x: np.ndarray                 # (runs, dim)
    best_f: np.ndarray                 # (runs,)
    history: np.ndarray                # (runs, iterations + 1) best-so-far fitness
    x_history: np.ndarray              # (runs, iterations + 1, dim) best-so-far point
    evaluation_history: np.ndarray     # (runs, iterations + 1) cumulative evaluations
    iterations_done: np.ndarray        # (runs,) iterations actually used (< iterations if stopped)
    extras: dict[str, np.ndarray] = field(default_factory=dict)       # name -> (runs, iterations + 1)
    snapshots: dict[int, np.ndarray] = field(default_factory=dict)    # iteration -> (runs, population, dim)


@lru_cache(maxsize=64)
def row_offsets(runs: int, population: int) -> np.ndarray:
    """``arange(runs) * population`` (read-only, cached): flat index of each run's first agent.

    ``row_offsets(R, P) + i`` turns per-run agent indices (R,) into indices of the flattened
    (R * P) arrays -- cheaper than fancy indexing with two index arrays.
    """
    out = np.arange(runs, dtype=np.intp) * population
    out.flags.writeable = False
    return out


def clip(x: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """Project onto the box (the bound handling of every swarm in fkopt unless it says otherwise)."""
    return np.clip(x, bounds[:, 0], bounds[:, 1])


def uniform_in(bounds: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Map uniforms in [0, 1) (..., dim) to points in the box."""
    return bounds[:, 0] + u * (bounds[:, 1] - bounds[:, 0])


class Algorithm:
    """Base of all algorithms. Subclasses set ``name``, ``Params`` and the two methods."""

    name: ClassVar[str]
    Params: ClassVar[type[Params]] = Params
    #: Deterministic local methods (Newton, LM) start from ``x0`` and ignore the population.
    local: ClassVar[bool] = False
    #: Rough evaluations per iteration as a function of population, for documentation.
    evaluations_per_iteration: ClassVar[str] = "population"

    def __init__(self, **params: Any):
        try:
            self.params = self.Params(**params)
        except ValidationError as err:
            first = err.errors()[0]
            loc = ".".join(str(p) for p in first["loc"])
            allowed = ", ".join(self.Params.model_fields) or "(none)"
            raise FkoptError(f"algorithm '{self.name}' parameter '{loc}': {first['msg']} "
                             f"(parameters: {allowed})") from None

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.model_dump().items())
        return f"{type(self).__name__}({args})"

    # -- to implement ------------------------------------------------------------------------
    def initialize(self, problem, population: int, streams: RunStreams, x0: np.ndarray | None) -> State:
        raise NotImplementedError

    def iterate(self, state: State, problem, streams: RunStreams) -> None:
        raise NotImplementedError

    def extras(self, state: State) -> dict[str, np.ndarray]:
        """Extra per-run scalars to record each iteration (e.g. ACO pheromone)."""
        return {}

    # -- shared --------------------------------------------------------------------------------
    @staticmethod
    def update_best(state: State) -> None:
        """Fold the memory ``state.x``/``state.f`` into the best-so-far of each run.

        The first minimum of each run wins; arrays are replaced (never written in place), and
        only when some run improved.
        """
        f = state.f
        runs, population = f.shape
        flat = f.argmin(axis=1)
        flat += row_offsets(runs, population)
        fb = f.ravel()[flat]
        better = fb < state.best_f
        if better.any():
            state.best_f = np.where(better, fb, state.best_f)
            xb = state.x.reshape(runs * population, -1)[flat]
            state.best_x = np.where(better[:, None], xb, state.best_x)

    def minimize(self, problem, *, population: int, iterations: int, streams: RunStreams,
                 target: float | None = None, stop_at_target: bool = False,
                 x0: np.ndarray | None = None, snapshots=()) -> RunRecord:
        runs, dim = streams.runs, problem.dim
        state = self.initialize(problem, population, streams, x0)
        state.best_f = np.full(runs, np.inf)
        state.best_x = np.full((runs, dim), np.nan)
        self.update_best(state)

        history = np.empty((runs, iterations + 1))
        x_history = np.empty((runs, iterations + 1, dim))
        evals = np.empty((runs, iterations + 1), dtype=np.int64)
        extra_hist: dict[str, np.ndarray] = {}
        snaps: dict[int, np.ndarray] = {}
        wanted = {int(s) for s in snapshots}
        done = np.zeros(runs, dtype=bool)
        done_at = np.full(runs, iterations)

        def record(t: int) -> None:
            if t == 0 or not frozen:
                history[:, t] = state.best_f
                x_history[:, t] = state.best_x
                evals[:, t] = state.evaluations
                for key, value in self.extras(state).items():
                    extra_hist.setdefault(key, np.empty((runs, iterations + 1)))[:, t] = value
            else:   # runs that reached the target keep their values
                history[:, t] = np.where(done, history[:, t - 1], state.best_f)
                x_history[:, t] = np.where(done[:, None], x_history[:, t - 1], state.best_x)
                evals[:, t] = np.where(done, evals[:, t - 1], state.evaluations)
                for key, value in self.extras(state).items():
                    arr = extra_hist[key]
                    arr[:, t] = np.where(done, arr[:, t - 1], value)
            if t in wanted:
                snaps[t] = np.array(state.x, copy=True)

        frozen = False   # does any run hold its records (reached the target)?
        record(0)
        last = iterations
        watch = stop_at_target and target is not None
        for t in range(1, iterations + 1):
            if watch:
                newly = ~done & (history[:, t - 1] < target)
                if newly.any():
                    done_at[newly] = t - 1
                    done |= newly
                    frozen = True
                    if done.all():
                        last = t - 1
                        break
            self.iterate(state, problem, streams)
            self.update_best(state)
            record(t)
        if stop_at_target and target is not None:
            newly = ~done & (history[:, last] < target)
            done_at[newly] = last
        if last < iterations:   # every run stopped early: hold the final values to the end
            history[:, last + 1:] = history[:, [last]]
            x_history[:, last + 1:] = x_history[:, [last]]
            evals[:, last + 1:] = evals[:, [last]]
            for arr in extra_hist.values():
                arr[:, last + 1:] = arr[:, [last]]
        return RunRecord(
            best_x=x_history[:, -1].copy(), best_f=history[:, -1].copy(), history=history,
            x_history=x_history, evaluation_history=evals, iterations_done=done_at,
            extras=extra_hist, snapshots=snaps,
        )
