"""Levenberg-Marquardt on the residuals, batched over every (run, start) point.

Not used by the five papers themselves; docs/models.md uses LM to check exact forward solutions
(mao2017's printed inputs, liu2008's case), and the ``*+lm`` hybrids polish a swarm's answer
with it. Minimises S(x) = sum_i r_i(x)^2 (any number of residuals >= 1) with Marquardt's
scaled damping, one trial step per point and iteration:

    (A + lambda D) d = -g,   A = J^T J,  g = J^T r,  D = diag(max(A_jj, 1e-12 max_k A_kk))
    x_try = clip(x + d);  accept if S(x_try) < S(x): lambda <- max(lambda * down, lambda_min)
                          otherwise:                   lambda <- lambda * up

Choices fkopt makes:

* Batched in numpy (scipy.optimize.least_squares works one point at a time): A and g are
  written as elementwise products summed over the residual axis (no matmul), and the dim x dim
  systems are solved with ``np.linalg.solve`` on the stacked matrices. numpy copies each
  matrix of the stack into its own buffer and calls LAPACK ``gesv`` once per matrix, so a
  point's numbers do not depend on the batch size or on its neighbours: bit-identical with one
  numpy/LAPACK build on one CPU (tested), but not across builds or CPUs (other kernels).
* Bounds by projection: the trial point is clipped onto the box (so LM can stall on a bound
  when the unconstrained step points outside; the 3-RPS solutions are interior).
* Jacobian: the problem's analytic one when it has one, else central differences, as in
  :mod:`fkopt.algorithms.nr` (``jac_step`` of the box width); recomputed only at accepted points.
* Start points as in :mod:`fkopt.algorithms.nr`: ``x0`` (one point, or one row per run id), or
  ``population`` uniform random starts per run when ``x0`` is None.
* A point stops (frozen, no more evaluations) when its fitness is 0, when an accepted step is
  below ``tol`` (max_j |d_j| / width_j), or when lambda exceeds ``lambda_max`` (no descent
  possible at working precision).
* ``state.f`` is ``problem.fitness`` (the reported objective); acceptance uses S(x). For the
  default squared objective they coincide.
* Evaluations: 1 + c per point at the start, then per active point and iteration 1 for the
  trial plus c when it is accepted (new Jacobian); c = 1 for an analytic Jacobian, 2*dim for
  central differences.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydantic import Field

from fkopt.algorithms.base import Algorithm, Params, State, clip, rows_of
from fkopt.algorithms.nr import jacobian, jacobian_cost, jacobian_steps, residuals_of, scaled_step, start_points


class LMParams(Params):
    damping: float = Field(1e-3, gt=0, description="initial Marquardt damping lambda")
    down: float = Field(0.1, gt=0, lt=1, description="lambda factor after an accepted step")
    up: float = Field(10.0, gt=1, description="lambda factor after a rejected step")
    lambda_min: float = Field(1e-12, ge=0, description="smallest damping")
    lambda_max: float = Field(1e16, gt=0, description="stop a point whose damping exceeds this")
    tol: float = Field(1e-14, ge=0, description="stop a point after an accepted step with "
                       "max_j |d_j| / width_j < tol")
    jac_step: float = Field(1e-6, gt=0, description="finite-difference step as a fraction of each "
                            "coordinate's box width")


@dataclass(eq=False, kw_only=True)
class LMState(State):
    """LM's points ``x``/``f`` (runs, n, dim) with residuals, Jacobians and damping."""

    r: np.ndarray                      # (runs, n, m) residuals
    s: np.ndarray                      # (runs, n) sum of squared residuals
    J: np.ndarray                      # (runs, n, m, dim) Jacobians
    h: np.ndarray                      # (dim,) finite-difference steps
    lam: np.ndarray                    # (runs, n) Marquardt damping
    active: np.ndarray                 # (runs, n) still stepping


def sum_squares(r: np.ndarray) -> np.ndarray:
    return (r * r).sum(axis=-1)


class LMCore:
    """The batched LM machinery on a flat set of points, shared by :class:`LM` and the hybrids."""

    def __init__(self, params: LMParams, algorithm: Algorithm):
        self.params = params
        self.algorithm = algorithm

    def start(self, problem, x: np.ndarray, f: np.ndarray | None = None) -> tuple[LMState, np.ndarray]:
        """LM state for points x (runs, n, dim); returns it and the evaluations used per run."""
        r = residuals_of(self.algorithm, problem, x, square=False)
        if f is None:
            f = problem.fitness(x)
        h = jacobian_steps(problem.bounds, self.params.jac_step)
        J = jacobian(problem, x, h)
        s = sum_squares(r)
        ok = np.isfinite(s) & np.all(np.isfinite(J), axis=(-2, -1))
        st = LMState(x=np.array(x, dtype=float), f=np.array(f, dtype=float), r=r, s=s, J=J, h=h,
                     lam=np.full(s.shape, self.params.damping), active=ok & (f > 0))
        return st, np.full(x.shape[0], x.shape[1] * (1 + jacobian_cost(problem)), dtype=np.int64)

    def step(self, st: LMState, problem) -> np.ndarray:
        """One trial step of every active point; returns evaluations used per run."""
        p = self.params
        act = st.active.copy()
        runs = act.shape[0]
        if not act.any():
            return np.zeros(runs, dtype=np.int64)
        J, r, x, lam = st.J[act], st.r[act], st.x[act], st.lam[act]
        A = (J[..., :, :, None] * J[..., :, None, :]).sum(axis=-3)       # (k, dim, dim)
        g = (J * r[..., :, None]).sum(axis=-2)                           # (k, dim)
        diag = np.diagonal(A, axis1=-2, axis2=-1)
        D = np.maximum(diag, 1e-12 * diag.max(axis=-1, keepdims=True))
        D = np.where(D > 0, D, 1.0)
        M = A + (lam[:, None] * D)[..., None] * np.eye(A.shape[-1])
        d = -np.linalg.solve(M, g[..., None])[..., 0]
        x_try = clip(x + d, problem.bounds)
        rows, cols = np.nonzero(act)
        r_try = np.asarray(rows_of(problem, rows).residuals(x_try), dtype=float)
        s_try = sum_squares(r_try)
        accept = np.isfinite(s_try) & (s_try < st.s[act])
        lam = np.where(accept, np.maximum(lam * p.down, p.lambda_min), lam * p.up)
        small = accept & (scaled_step(x_try - x, problem.bounds) < p.tol)
        evals = np.bincount(rows, minlength=runs).astype(np.int64)
        if accept.any():
            rows, cols = rows[accept], cols[accept]
            xa = x_try[accept]
            st.x[rows, cols] = xa
            st.r[rows, cols] = r_try[accept]
            st.s[rows, cols] = s_try[accept]
            sub = rows_of(problem, rows)
            st.f[rows, cols] = sub.fitness(xa)
            st.J[rows, cols] = jacobian(sub, xa, st.h)
            evals += np.bincount(rows, minlength=runs) * jacobian_cost(problem)
        st.lam[act] = lam
        finite_J = np.all(np.isfinite(st.J[act]), axis=(-2, -1))
        st.active[act] = ~small & (lam <= p.lambda_max) & (st.f[act] > 0) & finite_J
        return evals


class LM(Algorithm):
    name = "lm"
    Params = LMParams
    local = True
    evaluations_per_iteration = "1 (+2*dim if accepted) residual evaluations per active start point"

    def __init__(self, **params):
        super().__init__(**params)
        self.core = LMCore(self.params, self)

    def initialize(self, problem, population, streams, x0, iterations):
        x = start_points(self, problem, population, streams, x0)
        st, evals = self.core.start(problem, x)
        st.evaluations = evals
        return st

    def iterate(self, state, problem, streams):
        state.evaluations = state.evaluations + self.core.step(state, problem)
