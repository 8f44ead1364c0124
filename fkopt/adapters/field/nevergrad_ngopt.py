"""Nevergrad's NGOpt (Rapin and Teytaud, Meunier et al. 2021: a wizard choosing among CMA,
DE, PSO, Cobyla... by dimension and budget) on :func:`fkopt.adapters.field.pose_objective`.

Settings: ``ng.p.Array`` initialised at a random in-limit start with the joint limits as
bounds, ``budget`` = 40 x dof per start (NGOpt picks its sub-optimiser from this number: Cobyla
for 6-7 joints at budgets up to 300, measured),
``num_workers`` = 1, the parametrization's ``random_state`` seeded from the wrapper's generator
per start, ask/tell one point at a time until FTARGET, the budget or the deadline; then a new
start. The answer of a start is its best point told (not the recommendation, which for some
sub-optimisers is a mean never evaluated).

Quirks: at budgets of 600 to 3000 on 6-7 joints NGOpt picks a ``MetaModel`` (CMA on a
quadratic surrogate) whose surrogate step fails under numpy 2.4 with nevergrad 1.0.12
(``TypeError: only 0-dimensional arrays can be converted to Python scalars`` in
``metamodel.learn_on_k_best``) and, raised in nevergrad's worker thread, once hung a test; so
the budget per start is kept below that, and restarts spend the rest of the timeout. Nevergrad's per-point overhead (measured: 240 points of Cobyla
in 0.47 s on the UR5, ~2 ms each, against ~0.15 ms for fkopt's FK) dominates here, so within
1-20 ms it evaluates a handful of points; that is its cost as people run it.
"""
from __future__ import annotations

import time
import warnings

import numpy as np

from fkopt.adapters.field import BlackBoxIK


class NGOpt(BlackBoxIK):
    name = "nevergrad-ngopt"
    package = "nevergrad"
    BUDGET_PER_DOF = 40

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import nevergrad as ng
        self._ng = ng
        # NGOpt's Cobyla runs scipy in nevergrad's worker thread, outside any catch_warnings here
        warnings.filterwarnings("ignore", message="COBYLA: Invalid RHOEND")
        self.settings.update(version=ng.__version__, budget=f"{self.BUDGET_PER_DOF} x dof per start", num_workers=1)

    def search(self, f, x0, deadline):
        ng = self._ng
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            param = ng.p.Array(init=x0).set_bounds(self.lo_rad, self.hi_rad)
            param.random_state = np.random.RandomState(int(self.rng.integers(1, 2**31 - 1)))
            opt = ng.optimizers.NGOpt(parametrization=param, budget=self.BUDGET_PER_DOF * self.arm.dof, num_workers=1)
            best_x, best_f = x0, np.inf
            for _ in range(opt.budget):
                cand = opt.ask()
                fx = float(f(cand.value)[0])
                opt.tell(cand, fx)
                if fx < best_f:
                    best_x, best_f = np.array(cand.value), fx
                if best_f <= self.FTARGET or time.perf_counter() > deadline:
                    break
        return best_x, best_f
