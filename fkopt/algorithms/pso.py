"""Global-best particle swarm optimisation (PSO) with inertia weight.

Used by chang2024 (its PSO baseline and the first phase of P-ABC: w = 0.8, c1 = c2 = 2),
liu2008 (Sec. 3, eqs. 7-8: inertia linear from w_max = 0.5 to w_min = 0.1 over the k_max
iterations, c1 = c2 = 1.8, v_max = 1, 80 particles) and wang7dof (population 300). docs/models.md
"chang2024", "liu2008", "wang7dof". Per particle i and coordinate j, synchronously:

    v_ij <- w v_ij + c1 r1_ij (p_ij - x_ij) + c2 r2_ij (g_j - x_ij),  r1, r2 ~ U[0, 1)
    x_ij <- x_ij + v_ij

with p_i the particle's personal best and g the best personal best of the run (gbest, read
once per iteration). Linear inertia (liu2008 eq. 8): w_k = w_max - (w_max - w_min) k / k_max
for iteration k = 1 .. k_max (k_max = the iterations of the run).

Choices fkopt makes where the papers are silent:

* Defaults (w = 0.7298, c1 = c2 = 1.49618, constant inertia) are Clerc & Kennedy's constriction
  equivalent, which converges on its own; the papers' settings are parameters (configs set them).
  Note that chang2024's w = 0.8, c1 = c2 = 2 lies outside the convergence region
  (c1 + c2 < 2 (1 + w)), so that PSO only stalls thanks to the velocity clamp.
* Velocity clamp per coordinate: ``v_max`` (absolute, in the variable's own unit, the same value
  for every coordinate: liu2008's "v_max = 1") if set, otherwise ``v_max_fraction`` times the
  box width of that coordinate (default 0.2); both None means no clamp.
* Initial positions uniform in the box, initial velocities zero (Engelbrecht 2012).
* Bounds: a position leaving the box is clipped onto it and the velocity component that hit
  the bound is set to zero.
* Memory: ``state.x``/``state.f`` are the personal bests (what :meth:`Algorithm.update_best`
  reads); current positions/velocities are ``state.pos``/``state.vel``. One iteration costs
  ``population`` fitness evaluations.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import Field

from fkopt.algorithms.base import Algorithm, Params, State, clip, compiled_step, evaluated, log_arrays, log_kept, uniform_in


class PSOParams(Params):
    inertia: Literal["constant", "linear"] = Field(
        "constant", description="constant weight w, or linear from w_max to w_min over the iterations")
    w: float = Field(0.7298, ge=0, description="inertia weight when inertia='constant'")
    w_max: float = Field(0.9, ge=0, description="first inertia weight when inertia='linear'")
    w_min: float = Field(0.4, ge=0, description="last inertia weight when inertia='linear'")
    c1: float = Field(1.49618, ge=0, description="cognitive (personal best) acceleration")
    c2: float = Field(1.49618, ge=0, description="social (global best) acceleration")
    v_max: float | None = Field(None, gt=0, description="absolute velocity clamp per coordinate "
                                "(variable units); overrides v_max_fraction")
    v_max_fraction: float | None = Field(0.2, gt=0, description="velocity clamp as a fraction of "
                                         "each coordinate's box width (used when v_max is None)")


@dataclass(eq=False, kw_only=True)
class PSOState(State):
    """PSO's personal bests ``x``/``f``, current positions and velocities, iteration counter."""

    pos: np.ndarray                    # (runs, population, dim) current positions
    vel: np.ndarray                    # (runs, population, dim) velocities
    t: int = 0                         # iterations done
    span: int | None = None            # iterations of the linear inertia schedule
    clamp_box: tuple | None = None     # (velocity clamp, bounds) of the compiled iteration, made once


def _compiled_iteration(fitness):
    """:func:`fkopt.algorithms.pso_kernels.pso_iteration` on a mechanism's compiled fitness."""
    from fkopt.algorithms.pso_kernels import pso_iteration   # lazy: imports numba: only once the compiled path runs
    return pso_iteration(fitness)


class PSO(Algorithm):
    name = "pso"
    blas_free = True          # elementwise numpy only: no BLAS kernel decides its bits
    Params = PSOParams
    evaluations_per_iteration = "population"

    def velocity_limit(self, bounds: np.ndarray) -> np.ndarray:
        """Per-coordinate clamp (dim,), inf when unclamped."""
        p = self.params
        width = bounds[:, 1] - bounds[:, 0]
        if p.v_max is not None:
            return np.full(width.shape, float(p.v_max))
        if p.v_max_fraction is not None:
            return p.v_max_fraction * width
        return np.full(width.shape, np.inf)

    def initialize(self, problem, population, streams, x0, iterations):
        x = uniform_in(problem.bounds, streams.uniform(population, problem.dim))
        f = problem.fitness(x)
        span = int(iterations) if self.params.inertia == "linear" else None
        return PSOState(x=x, f=f, pos=x.copy(), vel=np.zeros_like(x), span=span,
                        evaluations=np.full(streams.runs, population, dtype=np.int64))

    def inertia_weight(self, state) -> float:
        p = self.params
        if p.inertia == "constant":
            return p.w
        return p.w_max - (p.w_max - p.w_min) * min(state.t, state.span) / state.span

    @staticmethod
    def _compiled_step(problem):
        """:func:`fkopt.algorithms.base.compiled_step` for PSO (:func:`_compiled_iteration`)."""
        return compiled_step(problem, _compiled_iteration)

    def iterate(self, state, problem, streams):
        p = self.params
        state.t += 1
        runs, population, dim = state.x.shape
        r = streams.uniform(2, population, dim)     # a fresh view: ours to overwrite
        fused = self._compiled_step(problem)
        if fused is not None:                      # a built-in fitness with a compiled iteration
            step, absolute = fused
            if problem.cases is not None:
                problem._check_cases(state.pos)
            J = problem._joint_rows(state.pos.shape[:-1])     # the fitness' target rows
            if state.clamp_box is None:            # the clamp and box as the kernel reads them, once
                state.clamp_box = (np.ascontiguousarray(self.velocity_limit(problem.bounds), dtype=float),
                               np.ascontiguousarray(problem.bounds, dtype=float))
            # the evaluation log's bookkeeping and update_best run in the same pass
            state.x, state.f, state.pos, state.vel, state.best_x, state.best_f, kept = step(
                state.x, state.f, state.pos, state.vel, state.best_x, state.best_f, r, self.inertia_weight(state),
                p.c1, p.c2, *state.clamp_box, J, absolute, log_arrays(state, runs))
            state.best_folded = True
            log_kept(state, kept)
            state.evaluations = state.evaluations + population
            return
        g = state.best_x[:, None, :]
        # w v + c1 r1 (p - x) + c2 r2 (g - x), the same operations in the same order, in place
        cognitive, social = r[:, 0], r[:, 1]
        cognitive *= p.c1
        diff = np.subtract(state.x, state.pos)
        cognitive *= diff
        vel = np.multiply(state.vel, self.inertia_weight(state))
        vel += cognitive
        social *= p.c2
        np.subtract(g, state.pos, out=diff)
        social *= diff
        vel += social
        limit = self.velocity_limit(problem.bounds)
        np.clip(vel, -limit, limit, out=vel)
        moved = state.pos + vel
        pos = clip(moved, problem.bounds)
        state.vel = np.where(pos != moved, 0.0, vel)
        state.pos = pos
        f = problem.fitness(pos)
        evaluated(state, f)
        better = f < state.f
        state.x = np.where(better[..., None], pos, state.x)
        state.f = np.where(better, f, state.f)
        state.evaluations = state.evaluations + population
