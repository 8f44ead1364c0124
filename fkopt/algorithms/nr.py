"""Newton-Raphson on the residuals, the classical numerical method wu2015 compares with (Tab. 2).

docs/models.md "wu2015": Newton-Raphson from five start points for the 3-PPR case. Each iteration is
one Newton step on the square system r(x) = 0 (``problem.residuals``, as many residuals as
unknowns):

    J(x_k) d_k = -r(x_k),   x_{k+1} = clip(x_k + d_k)

Choices fkopt makes (the paper prints none of them):

* Jacobian: ``problem.jacobian`` when the problem has an analytic one (``has_jacobian``: every
  built-in mechanism), charged as 1 evaluation. Otherwise (fallback) central differences,
  vectorised over every (run, start) point at once: the 2*dim perturbed points x +- h_j e_j
  of all points are evaluated in one ``residuals`` call, h_j = ``jac_step`` * (box width of
  coordinate j) (default 1e-6 of the width: central
  differences err by O(h^2), rounding by O(eps |r| / h), both far below what Newton needs).
* Start points: ``x0`` given as one point (dim,) is used by every run; as (runs, dim) row k is
  the start of row k of the batch (:func:`fkopt.solve` maps run ids and cases to rows, so batch
  and one-run-at-a-time modes agree).
  With ``x0`` the population is ignored (one point per run). Without ``x0`` every run starts
  from ``population`` points drawn uniformly in the box from its stream (a seeded multi-start;
  the run's answer is its best point). A start outside ``problem.bounds`` is an FkoptError.
* Steps are clipped to the box (``clip=True``, default); ``clip=False`` gives the unprojected
  iteration (the fitness is still defined outside the box for most mechanisms).
* Every step is taken (Newton is not a descent method); the recorded best-so-far is monotone
  anyway because :meth:`Algorithm.update_best` keeps the best point seen.
* A point stops stepping (is frozen, and costs no more evaluations) when its fitness is 0,
  when its scaled step max_j |d_j| / width_j falls below ``tol``, when its Jacobian is singular
  (smallest/largest singular value <= ``rcond``, or not finite), or when a step produced
  non-finite residuals (the step is then undone).
* Singular Jacobian: the point is kept where it is, and the extra ``singular`` (recorded per
  run and iteration) is 1 while some point of the run sits frozen at a singular Jacobian. If at
  the start *every* point of some run has a singular Jacobian (and none is already a solution),
  ``initialize`` raises FkoptError("... singular Jacobian at start point ...") -- that is a bad
  start chosen by the user, so the API and the CLI both report it.
* Evaluations: 1 (r) + 1 (analytic J) or 2*dim (central differences) per point at the start and
  per step (r and J at the new point); frozen points cost nothing.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydantic import Field

from fkopt.errors import FkoptError
from fkopt.algorithms.base import Algorithm, Params, State, clip, rows_of, uniform_in


# -- helpers shared with lm.py and hybrid.py -------------------------------------------------
def start_points(algorithm: Algorithm, problem, population: int, streams, x0) -> np.ndarray:
    """Start points (runs, n, dim) of a local method, checked against the bounds."""
    dim, bounds = problem.dim, problem.bounds
    if x0 is None:
        return uniform_in(bounds, streams.uniform(population, dim))
    x0 = np.asarray(x0, dtype=float)
    if x0.ndim == 1:
        x = np.broadcast_to(x0, (streams.runs, dim))
    elif x0.ndim == 2:   # one start per row of the batch (fkopt.solve maps run ids/cases to rows)
        if x0.shape[0] != streams.runs:
            raise FkoptError(f"{algorithm.name}: x0 has {x0.shape[0]} start points for a batch of "
                             f"{streams.runs} runs")
        x = x0
    else:
        raise FkoptError(f"{algorithm.name}: x0 must be one point ({dim},) or one per run (runs, {dim}); "
                         f"got shape {x0.shape}")
    if not np.all(np.isfinite(x)):
        raise FkoptError(f"{algorithm.name}: start point must be finite, got {x[~np.isfinite(x).all(-1)][0].tolist()}")
    outside = (x < bounds[:, 0]) | (x > bounds[:, 1])
    if outside.any():
        row = int(np.flatnonzero(outside.any(axis=1))[0])
        names = problem.variable_names
        j = int(np.flatnonzero(outside[row])[0])
        box = ", ".join(f"{n} [{lo:g}, {hi:g}]" for n, (lo, hi) in zip(names, bounds.tolist()))
        point = "(" + ", ".join(f"{n}={v:g}" for n, v in zip(names, x[row].tolist())) + ")"
        raise FkoptError(f"{algorithm.name}: start point {point} is outside the bounds ({names[j]}); "
                         f"bounds: {box}")
    return np.array(x[:, None, :], dtype=float)


def residuals_of(algorithm: Algorithm, problem, x: np.ndarray, square: bool) -> np.ndarray:
    """``problem.residuals(x)`` with clear errors when the problem has none (or not dim of them)."""
    try:
        r = np.asarray(problem.residuals(x), dtype=float)
    except NotImplementedError:
        raise FkoptError(f"{algorithm.name} needs a problem with residuals; "
                         f"{type(problem).__name__} only defines a fitness") from None
    if r.shape[:-1] != x.shape[:-1]:
        raise FkoptError(f"{algorithm.name}: residuals of shape {r.shape} for points of shape {x.shape}")
    if square and r.shape[-1] != problem.dim:
        raise FkoptError(f"{algorithm.name} needs as many residuals as unknowns; the problem has "
                         f"{r.shape[-1]} residuals for {problem.dim} unknowns "
                         f"({', '.join(problem.variable_names)}); use 'lm' instead")
    return r


def jacobian_steps(bounds: np.ndarray, jac_step: float) -> np.ndarray:
    return jac_step * (bounds[:, 1] - bounds[:, 0])


def analytic_jacobian(problem) -> bool:
    """Does the problem supply its own (analytic) ``jacobian``? Else central differences."""
    return bool(getattr(problem, "has_jacobian", False))


def jacobian_cost(problem) -> int:
    """Evaluations charged for one Jacobian: 1 when analytic (one call of ``problem.jacobian``,
    costing about one residual evaluation), 2*dim residual evaluations by central differences."""
    return 1 if analytic_jacobian(problem) else 2 * problem.dim


def jacobian(problem, x: np.ndarray, h: np.ndarray) -> np.ndarray:
    """``problem.jacobian(x)`` when the problem has one, else central differences (below)."""
    if analytic_jacobian(problem):
        return np.asarray(problem.jacobian(x), dtype=float)
    return fd_jacobian(problem, x, h)


def fd_jacobian(problem, x: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Central-difference Jacobian (..., m, dim) of the residuals at points x (..., dim)."""
    dim = x.shape[-1]
    e = np.eye(dim) * h
    xp = np.concatenate([x[..., None, :] + e, x[..., None, :] - e], axis=-2)   # (..., 2dim, dim)
    r = np.asarray(problem.residuals(xp), dtype=float)                      # (..., 2dim, m)
    return np.swapaxes((r[..., :dim, :] - r[..., dim:, :]) / (2.0 * h[:, None]), -1, -2)


def scaled_step(d: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    return np.max(np.abs(d) / (bounds[:, 1] - bounds[:, 0]), axis=-1)


# -- Newton-Raphson ------------------------------------------------------------------------
@dataclass(eq=False, kw_only=True)
class NRState(State):
    """Newton's points ``x``/``f`` (runs, n, dim) with their residuals and Jacobians."""

    r: np.ndarray                      # (runs, n, m) residuals
    J: np.ndarray                      # (runs, n, m, dim) Jacobians
    h: np.ndarray                      # (dim,) finite-difference steps
    active: np.ndarray                 # (runs, n) still stepping
    singular: np.ndarray               # (runs, n) frozen at a singular Jacobian


class NRParams(Params):
    tol: float = Field(1e-12, ge=0, description="stop a point when max_j |step_j| / width_j < tol")
    jac_step: float = Field(1e-6, gt=0, description="finite-difference step as a fraction of each "
                            "coordinate's box width")
    rcond: float = Field(1e-12, ge=0, description="Jacobian is singular when its smallest singular "
                         "value <= rcond * largest")
    clip: bool = Field(True, description="project each step onto the bounds")


class NR(Algorithm):
    name = "nr"
    Params = NRParams
    local = True
    evaluations_per_iteration = "(1 + 2*dim) residual evaluations per active start point"

    def _singular(self, J: np.ndarray) -> np.ndarray:
        ok = np.all(np.isfinite(J), axis=(-2, -1))
        s = np.linalg.svd(np.where(ok[..., None, None], J, 0.0), compute_uv=False)
        return ~ok | ~(s[..., -1] > self.params.rcond * s[..., 0])

    def initialize(self, problem, population, streams, x0, iterations):
        x = start_points(self, problem, population, streams, x0)
        r = residuals_of(self, problem, x, square=True)
        f = problem.fitness(x)
        h = jacobian_steps(problem.bounds, self.params.jac_step)
        J = jacobian(problem, x, h)
        singular = self._singular(J) & (f > 0)
        stuck = singular.all(axis=1) & (f > 0).all(axis=1)
        if stuck.any():
            k = int(np.flatnonzero(stuck)[0])
            point = ", ".join(f"{n}={v:g}" for n, v in zip(problem.variable_names, x[k, 0].tolist()))
            raise FkoptError(f"nr: singular Jacobian at start point ({point}) of run "
                             f"{streams.run_ids[k]}; choose another x0")
        active = (f > 0) & ~singular & np.isfinite(f)
        n = x.shape[1]
        return NRState(x=x, f=f, r=r, J=J, h=h, active=active, singular=singular,
                       evaluations=np.full(streams.runs, n * (1 + jacobian_cost(problem)), dtype=np.int64))

    def extras(self, state):
        return {"singular": state.singular.any(axis=1).astype(float)}

    def iterate(self, state, problem, streams):
        act = state.active.copy()
        if not act.any():
            return
        J, r = state.J[act], state.r[act]
        d = -np.linalg.solve(J, r[..., None])[..., 0]
        x_old = state.x[act]
        x_new = x_old + d
        if self.params.clip:
            x_new = clip(x_new, problem.bounds)
        sub = rows_of(problem, np.nonzero(act)[0])
        r_new = np.asarray(sub.residuals(x_new), dtype=float)
        f_new = sub.fitness(x_new)
        J_new = jacobian(sub, x_new, state.h)
        ok = np.isfinite(f_new) & np.all(np.isfinite(r_new), axis=-1)
        singular = self._singular(J_new) & ok & (f_new > 0)
        small = scaled_step(x_new - x_old, problem.bounds) < self.params.tol
        keep = ok[:, None]
        state.x[act] = np.where(keep, x_new, x_old)
        state.r[act] = np.where(keep, r_new, r)
        state.f[act] = np.where(ok, f_new, state.f[act])
        state.J[act] = np.where(keep[..., None], J_new, J)
        state.singular[act] = singular
        state.active[act] = ok & ~singular & ~small & (f_new > 0)
        state.evaluations = state.evaluations + act.sum(axis=1) * (1 + jacobian_cost(problem))
