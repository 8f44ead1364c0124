"""Swarm + Levenberg-Marquardt hybrids: ``abc+lm``, ``gabc+lm``, ``pso+lm``.

Not from the five papers: fkopt's own combination of a global swarm (mao2017's ABC/GABC,
chang2024/liu2008's PSO) with the local :mod:`fkopt.algorithms.lm` polish, to show what the
swarms' slow final convergence costs. :class:`SwarmLM` is generic over the swarm's registry
name; the registered classes only fix it.

* Iterations 1 .. S run the swarm unchanged (its own evaluations per iteration), with
  S = ``swarm_iterations`` if given, else round(``swarm_fraction`` * iterations) (default 0.2:
  on the 3-RPS case ABC/GABC are well inside the solution's basin after ~100 iterations, and
  LM then needs a handful of steps). A PSO with linear inertia runs its schedule over S.
* At iteration S + 1 LM starts from the best-so-far point of each run (r and J cost 1 + 2*dim
  evaluations) and takes one LM step per iteration until the end, or until it stops (see lm.py).
  The LM point replaces the best memory slot of the swarm, so ``state.x`` keeps its
  (runs, population, dim) shape (snapshots show the frozen swarm plus the polished point) and
  the recorded best-so-far stays monotone (LM only accepts decreasing steps).
* Parameters: the swarm's own, LM's (``damping``, ``tol``, ... unprefixed) and the two above.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from pydantic import Field

from fkopt.algorithms.abc import ABC, ABCParams
from fkopt.algorithms.base import Algorithm, Params, State
from fkopt.algorithms.gabc import GABC, GABCParams
from fkopt.algorithms.lm import LMCore, LMParams, LMState
from fkopt.algorithms.pso import PSO, PSOParams


def _swarm_field(name: str) -> property:
    def get(self):
        return getattr(self.swarm, name)

    def set(self, value):
        setattr(self.swarm, name, value)
    return property(get, set, doc=f"the swarm state's ``{name}``")


@dataclass(eq=False, kw_only=True)
class HybridState:
    """The swarm's own state, then LM's; ``x``, ``f``, ``evaluations`` and the best-so-far are
    the swarm state's (the LM point is written into its best memory slot)."""

    swarm: State                       # the swarm algorithm's state
    iteration: int = 0                 # iterations done
    switch: int = 0                    # last swarm iteration
    lm: LMState | None = None          # LM state, from the first LM iteration on
    lm_slot: np.ndarray | None = None  # (runs,) memory slot holding the LM point

    x = _swarm_field("x")
    f = _swarm_field("f")
    evaluations = _swarm_field("evaluations")
    best_x = _swarm_field("best_x")
    best_f = _swarm_field("best_f")
    log = _swarm_field("log")
    best_folded = _swarm_field("best_folded")


class HybridParams(Params):
    swarm_fraction: float = Field(0.2, ge=0, le=1, description="fraction of the iterations run by "
                                  "the swarm before LM polishes (used when swarm_iterations is None)")
    swarm_iterations: int | None = Field(None, ge=0, description="iterations run by the swarm "
                                         "before LM polishes; overrides swarm_fraction")


class SwarmLM(Algorithm):
    """Generic swarm-then-LM hybrid; subclasses set ``swarm`` (the swarm's class) and ``Params``."""

    swarm: ClassVar[type[Algorithm]]
    evaluations_per_iteration = "the swarm's, then 1 (+2*dim if accepted) per run"

    def __init__(self, **params):
        super().__init__(**params)
        values = self.params.model_dump()
        cls = self.swarm
        self.swarm_algorithm = cls(**{k: values[k] for k in cls.Params.model_fields})
        self.lm = LMCore(LMParams(**{k: values[k] for k in LMParams.model_fields}), self)

    def swarm_phase(self, iterations: int) -> int:
        p = self.params
        if p.swarm_iterations is not None:
            return min(p.swarm_iterations, iterations)
        return int(round(p.swarm_fraction * iterations))

    def initialize(self, problem, population, streams, x0, iterations):
        S = self.swarm_phase(iterations)
        swarm = self.swarm_algorithm.initialize(problem, population, streams, x0, max(S, 1))
        return HybridState(swarm=swarm, switch=S)

    def iterate(self, state, problem, streams):
        state.iteration += 1
        if state.iteration <= state.switch:
            self.swarm_algorithm.iterate(state.swarm, problem, streams)
            return
        runs = state.f.shape[0]
        rows = np.arange(runs)
        if state.lm is None:
            state.lm_slot = np.argmin(state.f, axis=1)
            state.lm, evals = self.lm.start(problem, state.best_x[:, None, :].copy(),
                                            state.best_f[:, None].copy())
            state.evaluations = state.evaluations + evals
        st = state.lm
        state.evaluations = state.evaluations + self.lm.step(st, problem)
        state.x[rows, state.lm_slot] = st.x[:, 0]
        state.f[rows, state.lm_slot] = st.f[:, 0]


class ABCLMParams(ABCParams, LMParams, HybridParams):
    pass


class GABCLMParams(GABCParams, LMParams, HybridParams):
    pass


class PSOLMParams(PSOParams, LMParams, HybridParams):
    pass


class ABCLM(SwarmLM):
    name = "abc+lm"
    swarm = ABC
    Params = ABCLMParams


class GABCLM(SwarmLM):
    name = "gabc+lm"
    swarm = GABC
    Params = GABCLMParams


class PSOLM(SwarmLM):
    name = "pso+lm"
    swarm = PSO
    Params = PSOLMParams
