"""Differential evolution (DE/rand/1/bin, Storn & Price 1997) as an fkopt algorithm plug-in.

fkopt's Algorithm protocol: ``initialize`` fills the state's arrays shaped (runs, population,
dim) and ``iterate`` advances every run by one generation; ``Algorithm.minimize`` does the
rest (best-so-far, histories, evaluation counts, stopping at a target). All random numbers
come from ``streams`` (one stream per run), so run k gives the same numbers alone or in a batch.

Per generation and run: for each target vector i, three distinct indices r1, r2, r3 != i
(the first three of a uniform random ordering that are not i), the mutant
v = x_r1 + F (x_r2 - x_r3), binomial crossover with rate CR and one forced coordinate,
projection onto the box, and greedy selection (the trial replaces i if it is not worse).
Evaluations: ``population`` per generation (plus ``population`` for the initial one).
"""
from __future__ import annotations

import numpy as np
from pydantic import Field

from fkopt.algorithms.base import Algorithm, Params, State


class DEParams(Params):
    F: float = Field(0.5, gt=0, le=2, description="differential weight")
    CR: float = Field(0.9, ge=0, le=1, description="crossover rate")


class DE(Algorithm):
    """DE/rand/1/bin."""

    name = "de"
    Params = DEParams
    evaluations_per_iteration = "population"

    def initialize(self, problem, population, streams, x0=None, *args, **kwargs) -> State:
        if population < 4:
            from fkopt.errors import FkoptError
            raise FkoptError("algorithm 'de' needs a population of at least 4")
        b = problem.bounds
        x = b[:, 0] + streams.uniform(population, problem.dim) * (b[:, 1] - b[:, 0])
        x = np.array(x)   # the stream hands out a view of its buffer: keep our own copy
        f = problem.fitness(x)
        return State(x=x, f=f, evaluations=np.full(streams.runs, population, dtype=np.int64))

    def iterate(self, state: State, problem, streams) -> None:
        x, f = state.x, state.f
        runs, pop, dim = x.shape
        order = np.argsort(streams.uniform(pop, pop), axis=-1)[..., :4]        # (runs, pop, 4)
        not_i = order != np.arange(pop)[None, :, None]
        pick = np.argsort(~not_i, axis=-1, kind="stable")[..., :3]             # first three != i
        r = np.take_along_axis(order, pick, axis=-1)                           # (runs, pop, 3)
        take = lambda k: np.take_along_axis(x, r[..., k][..., None], axis=1)   # noqa: E731
        mutant = take(0) + self.params.F * (take(1) - take(2))
        cross = streams.uniform(pop, dim) < self.params.CR
        forced = streams.integers(dim, pop)
        cross |= np.arange(dim)[None, None, :] == forced[..., None]
        trial = np.clip(np.where(cross, mutant, x), problem.bounds[:, 0], problem.bounds[:, 1])
        ft = problem.fitness(trial)
        better = ft <= f
        state.x = np.where(better[..., None], trial, x)
        state.f = np.where(better, ft, f)
        state.evaluations = state.evaluations + pop
