"""Bounded damped least squares with seeded restarts (``dls``): the exact baseline with limits.

Not from the five papers. :mod:`fkopt.algorithms.lm` handles the bounds by clipping its trial
point, so a point whose step leaves the box stalls on the bound: on wang7dof's arm LM solves
about a third of random reachable poses from one start. ``dls`` is the same damped
Gauss-Newton iteration with the bounds handled by the method and stalled points restarted:

* step d = -(J^T J + mu I)^{-1} J^T r (= -J^T (J J^T + mu I)^{-1} r, the minimum-norm damped
  least-squares step of a redundant system), in coordinates scaled by the box widths,
  mu = lambda * trace(J^T J) / dim, lambda as in Levenberg-Marquardt (``damping``, times
  ``down`` after a step that decreases sum r^2, times ``up`` otherwise);
* saturation in the null space (Flacco, De Luca, Khatib 2012): a coordinate whose step would
  leave the box is fixed at the bound, its column removed and the others re-solved for the
  residual left over (up to 3 passes), so the remaining freedom absorbs the saturation;
* a point that has not reached ``tol`` after ``stall`` steps, or whose lambda exceeds
  ``lambda_max``, restarts from a uniform point of the box drawn from its run's stream. The
  stream draws one (population, dim) block every iteration whether or not a point restarts,
  so runs stay independent of each other (same numbers alone or in a batch).

Jacobian: ``problem.jacobian`` when analytic, else central differences (as nr/lm). Start
points as in nr/lm (``x0``, or ``population`` uniform starts per run). Evaluations: 1 (r) + c
(J; 1 analytic, 2*dim by differences) per point at the start, at every step and at every restart.
The function the iterations decrease is sum r^2; ``state.f`` is ``problem.fitness``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydantic import Field

from fkopt.algorithms.base import Algorithm, Params, State, rows_of, uniform_in
from fkopt.algorithms.nr import jacobian, jacobian_cost, jacobian_steps, residuals_of, start_points


class DLSParams(Params):
    damping: float = Field(0.3, gt=0, description="initial lambda (relative to trace(J^T J) / dim)")
    down: float = Field(0.1, gt=0, lt=1, description="lambda factor after a decreasing step")
    up: float = Field(10.0, gt=1, description="lambda factor after a rejected step")
    lambda_max: float = Field(1e6, gt=0, description="restart a point whose lambda exceeds this")
    stall: int = Field(12, ge=1, description="restart a point not at tol after this many steps")
    tol: float = Field(1e-20, ge=0, description="a point whose sum r^2 <= tol stops (solved)")
    jac_step: float = Field(1e-6, gt=0, description="finite-difference step (fallback only), "
                            "fraction of each coordinate's box width")


@dataclass(eq=False, kw_only=True)
class DLSState(State):
    """The points ``x``/``f`` (runs, n, dim) with their residuals, Jacobians and damping."""

    r: np.ndarray                      # (runs, n, m) residuals
    J: np.ndarray                      # (runs, n, m, dim) Jacobians
    S: np.ndarray                      # (runs, n) sum of squared residuals
    h: np.ndarray                      # (dim,) finite-difference steps (fallback only)
    lam: np.ndarray                    # (runs, n) damping
    age: np.ndarray                    # (runs, n) steps since the last (re)start


class DLS(Algorithm):
    name = "dls"
    Params = DLSParams
    local = True
    evaluations_per_iteration = "1 + c per active point (c = 1 analytic J, 2*dim differences)"

    def _eval(self, problem, x, h):
        r = residuals_of(self, problem, x, square=False)
        return r, jacobian(problem, x, h), (r * r).sum(axis=-1)

    def initialize(self, problem, population, streams, x0, iterations):
        x = start_points(self, problem, population, streams, x0)
        h = jacobian_steps(problem.bounds, self.params.jac_step)
        r, J, S = self._eval(problem, x, h)
        n = x.shape[1]
        return DLSState(x=x, f=problem.fitness(x), r=r, J=J, S=S, h=h,
                        lam=np.full(S.shape, self.params.damping), age=np.zeros(S.shape, dtype=np.int64),
                        evaluations=np.full(streams.runs, n * (1 + jacobian_cost(problem)), dtype=np.int64))

    def iterate(self, state, problem, streams):
        p = self.params
        lo, hi = problem.bounds[:, 0], problem.bounds[:, 1]
        width = hi - lo
        runs, pop, dim = state.x.shape
        u = streams.uniform(pop, dim)                      # drawn every iteration (run independence)
        cost = 1 + jacobian_cost(problem)
        evals = np.zeros(runs, dtype=np.int64)
        # restarts
        stuck = (state.S > p.tol) & ((state.age >= p.stall) | (state.lam > p.lambda_max))
        if stuck.any():
            rows, cols = np.nonzero(stuck)
            xs = uniform_in(problem.bounds, u[rows, cols])
            sub = rows_of(problem, rows)   # a target per batch row when solving several cases
            r, J, S = self._eval(sub, xs, state.h)
            state.x[rows, cols], state.r[rows, cols], state.J[rows, cols], state.S[rows, cols] = xs, r, J, S
            state.f[rows, cols] = sub.fitness(xs)
            state.lam[rows, cols], state.age[rows, cols] = p.damping, 0
            evals += np.bincount(rows, minlength=runs) * cost
        act = state.S > p.tol
        if act.any():
            rows, cols = np.nonzero(act)
            x, r, J, lam = state.x[rows, cols], state.r[rows, cols], state.J[rows, cols], state.lam[rows, cols]
            Js = J * width                                  # coordinates scaled by the box widths
            A = np.swapaxes(Js, -1, -2) @ Js
            mu = lam * np.trace(A, axis1=-2, axis2=-1) / dim
            eye = np.eye(dim)
            free = np.ones(x.shape)
            fixed = np.zeros(x.shape)                       # scaled steps of saturated coordinates
            for _ in range(3):
                Jf = Js * free[:, None, :]
                rr = r + (Js @ fixed[..., None])[..., 0]
                M = np.swapaxes(Jf, -1, -2) @ Jf + mu[:, None, None] * eye
                d = -np.linalg.solve(M, (np.swapaxes(Jf, -1, -2) @ rr[..., None]))[..., 0] * free + fixed
                xn = x + d * width
                out = ((xn < lo) | (xn > hi)) & (free > 0)
                if not out.any():
                    break
                fixed = np.where(out, (np.clip(xn, lo, hi) - x) / width, fixed)
                free = np.where(out, 0.0, free)
            xn = np.clip(x + d * width, lo, hi)
            sub = rows_of(problem, rows)
            rn, Jn, Sn = self._eval(sub, xn, state.h)
            ok = Sn < state.S[rows, cols]
            state.lam[rows, cols] = np.where(ok, np.maximum(lam * p.down, 1e-12), lam * p.up)
            state.age[rows, cols] += 1
            rk, ck = rows[ok], cols[ok]
            state.x[rk, ck], state.r[rk, ck], state.J[rk, ck], state.S[rk, ck] = xn[ok], rn[ok], Jn[ok], Sn[ok]
            state.f[rk, ck] = rows_of(problem, rk).fitness(xn[ok])
            evals += np.bincount(rows, minlength=runs) * cost
        state.evaluations = state.evaluations + evals
