"""P-ABC of chang2024 (Sec. 3.2): PSO first, then ABC seeded with the particles' memories.

The paper's equations (34)-(40) were lost in extraction; docs/models.md "chang2024" reconstructs the
method, and fkopt follows that reconstruction:

* iterations 1 .. p run :class:`fkopt.algorithms.pso.PSO` (p = round(switch * iterations),
  chang2024: p = half of the iterations);
* iterations p + 1 .. end run :class:`fkopt.algorithms.abc.ABC`, whose food sources are the
  particles' personal bests at the switch (one source per particle, "one-to-one", trial
  counters zero), with ABC's greedy selection;
* the best-so-far point is shared by both phases (PSO's gbest, then the record).

Linear PSO inertia (if chosen) runs from w_max to w_min over the PSO phase (p iterations).
Evaluations per iteration: ``population`` in the PSO phase, about ``2 * population`` (+1 per
scout) in the ABC phase; ``state.evaluations`` counts each phase exactly.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
from pydantic import Field

from fkopt.algorithms.abc import ABC, ABCParams, ABCState
from fkopt.algorithms.base import Algorithm
from fkopt.algorithms.pso import PSO, PSOParams, PSOState


class PABCParams(PSOParams, ABCParams):
    switch: float = Field(0.5, ge=0, le=1, description="fraction of the iterations run as PSO "
                          "before switching to ABC (chang2024: 0.5)")


@dataclass(eq=False, kw_only=True)
class PABCState(PSOState, ABCState):
    """Both a PSO and an ABC state: PSO advances it first, ABC (trial counters) after the switch."""

    iteration: int = 0                 # iterations done
    switch: int = 0                    # last PSO iteration


class PABC(Algorithm):
    name = "pabc"
    blas_free = True          # elementwise numpy only: no BLAS kernel decides its bits
    Params = PABCParams
    reconstruction = ("chang2024's P-ABC equations were lost in extraction; PSO then ABC seeded "
                      "with the personal bests, as reconstructed in docs/models.md")
    evaluations_per_iteration = "population (PSO phase), 2*population (+1 per scout) (ABC phase)"
    #: The convergence figure marks where the search changes phase (fkopt.kinds.experiment.reports).
    phase_change = "switch PSO → ABC"

    @staticmethod
    def phase_iteration(params: dict, last: int) -> int:
        """The iteration (0..last) at which the PSO phase hands over to ABC."""
        return int(round(float(params.get("switch", 0.5)) * last))

    def __init__(self, **params):
        super().__init__(**params)
        values = self.params.model_dump()
        self.pso = PSO(**{k: values[k] for k in PSOParams.model_fields})
        self.abc = ABC(**{k: values[k] for k in ABCParams.model_fields})

    def switch_iteration(self, iterations: int) -> int:
        return int(round(self.params.switch * iterations))

    def initialize(self, problem, population, streams, x0, iterations):
        p = self.switch_iteration(iterations)
        pso = self.pso.initialize(problem, population, streams, x0, max(p, 1))
        return PABCState(**{f.name: getattr(pso, f.name) for f in fields(pso)}, switch=p,
                         trial=np.zeros(pso.f.shape, dtype=np.int64),
                         limit=self.abc.params.limit or population * problem.dim)

    def iterate(self, state, problem, streams):
        state.iteration += 1
        if state.iteration <= state.switch:
            self.pso.iterate(state, problem, streams)
        else:
            self.abc.iterate(state, problem, streams)
