"""Improved continuous ant colony (ACO) of wu2015 (Sec. 4.2, eqs. 16-19); mao2017's "ACO".

docs/models.md "wu2015". Ants are points in the box; one iteration ("sweep") moves every ant once:

1. pheromone tau = -f (eq. 16), initially of the random start positions; the best pheromone
   tau_b is the largest (least negative) of the run, the mean tau_m = mean(tau) (eq. 17);
2. transfer probability of ant j (eq. 18) P_j = (tau_b - tau_j) / |tau_b|;
3. if P_j < P0 the ant makes a local search, otherwise a global search;
4. the ant moves only if the move improves its fitness (step 5, greedy);
5. after the sweep every ant's pheromone becomes tau <- rho * tau_old + tau_new (eq. 19), with
   tau_new = -f at the ant's (possibly unchanged) position.

Reading of eq. (18). As printed, P = (tau_b - tau_j) / tau_b with tau = -f <= 0 has a negative
denominator, so P <= 0 < P0 always and no ant would ever search globally. The formula comes
from the continuous ACO for *maximising* a positive function (the common MATLAB example,
Tau = F(X), P = (Tau_best - Tau_i) / Tau_best in [0, 1]), where P is the relative shortfall of
ant i from the best. fkopt keeps that meaning with the printed signs and divides by |tau_b|:
P_j = (tau_b - tau_j)/|tau_b| >= 0, zero for the best ant, i.e. (for rho = 0) f_j / f_b - 1.
Ants within a factor 1 + P0 of the best pheromone search locally, the others globally.
(The bounded variant (tau_b - tau_j)/|tau_j| = 1 - f_b/f_j in [0, 1) orders ants identically
and corresponds to P0' = P0 / (1 + P0).) If tau_b = 0 (an exact zero of f), P_j = 0 for ants
at pheromone 0 and +inf for the others.

Step sizes (not printed by wu2015; named parameters here). A move adds (2u - 1) * h_j to each
coordinate j (u ~ U[0, 1) per coordinate), then the point is clipped onto the box:

* global search: h_j = ``global_step`` * width_j (default 0.5: a jump uniform over +- half the
  box around the ant, as the MATLAB example's (upper - lower)(rand - 0.5)), constant;
* local search: h_j = s * L_j, with
  - L_j (``local_scale``): "common" (default) = the mean box width, the same length in every
    coordinate (like the MATLAB example's absolute radius lambda), or "width" = width_j;
  - s (``step_rule``): "schedule" (default) = ``local_step`` * ``shrink``^((t - 1)/(T - 1)) at
    iteration t of T, a geometric decay from ``local_step`` (0.1) at the first iteration to
    ``local_step * shrink`` (shrink = 1e-7) at the last -- the MATLAB example's shrinking radius
    lambda = 1/t, made budget-relative so every budget ends at a fine resolution; or
    "adaptive" = a per-ant radius starting at ``local_step``, multiplied by ``expand`` (1.5)
    after a successful local move and by ``contract`` (0.9036 = 1.5^(-1/4), Rechenberg's 1/5
    success rule) after a failed one -- not in the paper, offered because it is much stronger.

Defaults: rho = 0.1 (the MATLAB example's 1 - Rho with Rho = 0.9), P0 = 10 (an ant searches
locally while its pheromone is within a factor 11 of the best's; with the accumulated
pheromone most ants search globally after the first iterations, ~3 % locally at the end).
Tuned on a 3-D sphere (30 ants, 1000 iterations: < 1e-14), the 3-RPS case of mao2017 (10 ants,
600 iterations, 200 runs: median 2e-12, all < 2e-11) and the 3-PPR case of wu2015 (30 ants, 1000
iterations, 200 runs: median 9e-12, 6.5 % above 1e-6). Why: per-coordinate box-width scaling
makes the 3-PPR valley ~5x worse conditioned than common scaling (condition of f 246 vs 50),
so ants creep and the schedule outruns them (median 5e-3 with "width", 98 % above 1e-6); a faster decay
(shrink 1e-9) or a smaller P0 (MATLAB's 0.2) strands more runs in those narrow valleys. With
step_rule="adaptive": 3-PPR median 5e-12 (none above 1e-7), 3-RPS median 2e-19.

Each iteration costs ``population`` evaluations (one per ant), so "after 500 moves" (wu2015
Fig. 5) is iteration 500. ``state.x`` are the ant positions; the extras ``pheromone_best``
(tau_b) and ``pheromone_mean`` (tau_m, of the accumulated pheromone of eq. 19) are recorded per
run and iteration (wu2015 Fig. 7).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import Field

from fkopt.algorithms.base import Algorithm, Params, State, clip, evaluated, uniform_in


class ACOParams(Params):
    P0: float = Field(10.0, ge=0, description="transfer probability constant: P < P0 -> local search")
    rho: float = Field(0.1, ge=0, lt=1, description="pheromone residue in tau <- rho tau_old + tau_new")
    global_step: float = Field(0.5, gt=0, description="global search half-width, fraction of each "
                               "coordinate's box width")
    local_scale: Literal["common", "width"] = Field(
        "common", description="length unit of local moves: the mean box width in every coordinate, "
        "or each coordinate's own width")
    local_step: float = Field(0.1, gt=0, description="local half-width at the first iteration "
                              "(schedule) or initial per-ant half-width (adaptive), in local_scale units")
    step_rule: Literal["schedule", "adaptive"] = Field(
        "schedule", description="local half-width: geometric decay over the iterations, or per-ant "
        "1/5 success rule")
    shrink: float = Field(1e-7, gt=0, le=1, description="schedule: local half-width at the last "
                          "iteration divided by local_step")
    expand: float = Field(1.5, ge=1, description="adaptive: factor after a successful local move")
    contract: float = Field(0.9036, gt=0, le=1, description="adaptive: factor after a failed local move")


@dataclass(eq=False, kw_only=True)
class ACOState(State):
    """The ants ``x``/``f``, their accumulated pheromone and local step sizes."""

    tau: np.ndarray                    # (runs, population) pheromone (eq. 19)
    step: np.ndarray                   # (runs, population) adaptive local half-widths
    t: int = 0                         # iterations done
    span: int = 1                      # iterations of the run (the schedule's length)


class ACO(Algorithm):
    name = "aco"
    blas_free = True          # elementwise numpy only: no BLAS kernel decides its bits
    Params = ACOParams
    evaluations_per_iteration = "population"

    def initialize(self, problem, population, streams, x0, iterations):
        x = uniform_in(problem.bounds, streams.uniform(population, problem.dim))
        f = problem.fitness(x)
        return ACOState(x=x, f=f, tau=-f, span=int(iterations),
                        step=np.full(f.shape, self.params.local_step),
                        evaluations=np.full(streams.runs, population, dtype=np.int64))

    def local_half_width(self, state) -> float:
        p = self.params
        frac = (state.t - 1) / (state.span - 1) if state.span > 1 else 0.0
        return p.local_step * p.shrink ** min(frac, 1.0)

    @staticmethod
    def transfer_probability(tau: np.ndarray) -> np.ndarray:
        """P_j = (tau_b - tau_j) / |tau_b| per run (see the module docstring), shape like tau."""
        best = tau.max(axis=1, keepdims=True)
        gap = best - tau
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            P = gap / np.abs(best)
        return np.where(gap == 0, 0.0, P)

    def iterate(self, state, problem, streams):
        p = self.params
        state.t += 1
        runs, population, dim = state.x.shape
        local = self.transfer_probability(state.tau) < p.P0
        width = problem.bounds[:, 1] - problem.bounds[:, 0]
        unit = width if p.local_scale == "width" else np.full(dim, width.mean())
        s = state.step if p.step_rule == "adaptive" else self.local_half_width(state)
        h = np.where(local[..., None], np.asarray(s)[..., None] * unit, p.global_step * width)
        u = streams.uniform(population, dim)
        cand = clip(state.x + (2.0 * u - 1.0) * h, problem.bounds)
        fc = problem.fitness(cand)
        evaluated(state, fc)
        better = fc < state.f
        if p.step_rule == "adaptive":
            state.step = np.where(local, state.step * np.where(better, p.expand, p.contract), state.step)
        state.x = np.where(better[..., None], cand, state.x)
        state.f = np.where(better, fc, state.f)
        state.tau = p.rho * state.tau - state.f
        state.evaluations = state.evaluations + population

    def extras(self, state):
        return {"pheromone_best": state.tau.max(axis=1), "pheromone_mean": state.tau.mean(axis=1)}
