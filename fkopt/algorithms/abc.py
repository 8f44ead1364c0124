"""Artificial bee colony (ABC) of Karaboga (2005), as used by mao2017 (Sec. 2.1) and wang7dof.

SPEC.md "mao2017": fitness-to-quality map fit = 1/(1+f) for f >= 0 (1+|f| otherwise),
onlooker roulette p_i = fit_i / sum(fit), greedy selection, and a scout that replaces a
source whose trial counter exceeds ``limit``.

Choices fkopt makes where the papers are silent (documented, each a named parameter or here):

* ``population`` is the number of food sources SN = employed bees = onlooker bees; one
  iteration is an employed phase (SN evaluations), an onlooker phase (SN evaluations) and at
  most one scout (Karaboga & Basturk's reference code): about 2*SN evaluations, twice a PSO
  iteration of the same population -- compare algorithms at equal evaluations too.
* The neighbour move changes one random coordinate j: v_ij = x_ij + phi (x_ij - x_kj),
  phi ~ U[-1, 1], k != i random, then clipped to the bounds.
* Onlookers of one phase act synchronously (vectorised): a source chosen by several onlookers
  keeps the best of their candidates if it beats the source; each failed attempt adds one to
  its trial counter. Karaboga's sequential loop lets a later onlooker see an earlier one's
  improvement within the phase; the difference is immaterial to convergence and lets every
  run and every bee advance in a handful of array operations.
* ``limit`` defaults to SN * dim (Karaboga & Basturk 2007).
* The best-so-far solution is memorised before the scout phase, so abandoning a stale best
  source never loses it.
"""
from __future__ import annotations

import numpy as np
from pydantic import Field

from .base import Algorithm, Params, State, clip, uniform_in


class ABCParams(Params):
    limit: int | None = Field(None, ge=1, description="trials without improvement before a source "
                              "is abandoned by a scout; default population * dim")


def quality(f: np.ndarray) -> np.ndarray:
    """Karaboga's fit(f): 1/(1+f) for f >= 0, 1+|f| otherwise."""
    return np.where(f >= 0, 1.0 / (1.0 + np.abs(f)), 1.0 + np.abs(f))


class ABC(Algorithm):
    name = "abc"
    Params = ABCParams
    evaluations_per_iteration = "2*population (+1 per scout)"

    # -- phases ------------------------------------------------------------------------------
    def initialize(self, problem, population, streams, x0):
        x = uniform_in(problem.bounds, streams.uniform(population, problem.dim))
        f = problem.fitness(x)
        runs = streams.runs
        limit = self.params.limit or population * problem.dim
        return State(x=x, f=f, trial=np.zeros(f.shape, dtype=np.int64), limit=limit,
                     evaluations=np.full(runs, population, dtype=np.int64))

    def iterate(self, state, problem, streams):
        self.employed_phase(state, problem, streams)
        self.update_best(state)
        self.onlooker_phase(state, problem, streams)
        self.update_best(state)
        self.scout_phase(state, problem, streams)

    def step(self, state, xs, xk, phi, streams):
        """The move added to the chosen coordinate (overridden by GABC)."""
        return phi * (xs - xk)

    def candidates(self, state, sources, problem, streams):
        """Neighbour candidates of ``sources`` (runs, n): one coordinate moved towards/away from k."""
        x = state.x
        population, dim = x.shape[1], x.shape[2]
        j = streams.integers(dim, sources.shape[1])
        k = streams.index_other_than(population, sources)
        phi = 2.0 * streams.uniform(sources.shape[1]) - 1.0
        xs = np.take_along_axis(x, sources[..., None], axis=1)
        xk = np.take_along_axis(x, k[..., None], axis=1)
        moved = xs + self.step(state, xs, xk, phi[..., None], streams)
        v = np.where(np.arange(dim) == j[..., None], moved, xs)
        return clip(v, problem.bounds)

    def employed_phase(self, state, problem, streams):
        runs, population = state.f.shape
        sources = np.broadcast_to(np.arange(population), (runs, population))
        v = self.candidates(state, sources, problem, streams)
        fv = problem.fitness(v)
        better = fv < state.f
        state.x = np.where(better[..., None], v, state.x)
        state.f = np.where(better, fv, state.f)
        state.trial = np.where(better, 0, state.trial + 1)
        state.evaluations = state.evaluations + population

    def onlooker_phase(self, state, problem, streams):
        runs, population = state.f.shape
        fit = quality(state.f)
        cdf = np.cumsum(fit, axis=1)
        u = streams.uniform(population) * cdf[:, -1:]
        sources = np.minimum((cdf[:, None, :] <= u[:, :, None]).sum(axis=2), population - 1)
        v = self.candidates(state, sources, problem, streams)
        fv = problem.fitness(v).ravel()
        # Resolve onlookers that chose the same source: keep the best candidate per source.
        flat = (np.arange(runs)[:, None] * population + sources).ravel()
        order = np.lexsort((fv, flat))
        grouped = flat[order]
        first = np.ones(grouped.size, dtype=bool)
        first[1:] = grouped[1:] != grouped[:-1]
        win = order[first]
        target = flat[win]
        f = state.f.reshape(-1).copy()
        x = state.x.reshape(runs * population, -1).copy()
        trial = state.trial.reshape(-1) + np.bincount(flat, minlength=runs * population)
        ok = fv[win] < f[target]
        target, win = target[ok], win[ok]
        f[target] = fv[win]
        x[target] = v.reshape(runs * population, -1)[win]
        trial[target] = 0
        state.f = f.reshape(runs, population)
        state.x = x.reshape(state.x.shape)
        state.trial = trial.reshape(runs, population)
        state.evaluations = state.evaluations + population

    def scout_phase(self, state, problem, streams):
        runs = state.f.shape[0]
        worst = np.argmax(state.trial, axis=1)
        rows = np.arange(runs)
        scout = state.trial[rows, worst] > state.limit
        # Draw for every run so each run's stream advances the same way whatever the others do.
        fresh = uniform_in(problem.bounds, streams.uniform(problem.dim))
        if scout.any():
            ff = problem.fitness(fresh)
            state.x[rows[scout], worst[scout]] = fresh[scout]
            state.f[rows[scout], worst[scout]] = ff[scout]
            state.trial[rows[scout], worst[scout]] = 0
            state.evaluations = state.evaluations + scout
