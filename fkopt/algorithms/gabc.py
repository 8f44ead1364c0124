"""Gbest-guided ABC (GABC): ABC whose neighbour move is also pulled by the best-so-far source.

Two update rules, selected by the ``rule`` parameter (docs/models.md "mao2017"):

* ``"mao2017"`` (default) -- mao2017 eq. (19) as printed:
  v_ij = x_ij + phi_ij (x_ij - x_kj) + phi_ij (x_best,j - x_kj), phi_ij ~ U[-1, 1].
  The paper writes the same symbol phi_ij in both terms; fkopt reads it literally as one draw.
* ``"zhu2010"`` -- the original of Zhu & Kwong (2010), Appl. Math. Comput. 217:
  v_ij = x_ij + phi_ij (x_ij - x_kj) + psi_ij (x_best,j - x_ij), psi_ij ~ U[0, C], C = 1.5.

Everything else (onlookers, scouts, limit, bounds) is :mod:`fkopt.algorithms.abc`.
"""
from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from fkopt.algorithms.abc import ABC, ABCParams
from fkopt.algorithms.base import row_offsets


class GABCParams(ABCParams):
    rule: Literal["mao2017", "zhu2010"] = Field("mao2017", description="update rule: mao2017 eq. 19 "
                                               "as printed, or Zhu & Kwong 2010")
    C: float = Field(1.5, gt=0, description="psi ~ U[0, C] for rule zhu2010 (ignored by mao2017)")


class GABC(ABC):
    name = "gabc"
    Params = GABCParams
    uses_best = True

    def compiled_rule(self) -> int | None:
        if type(self) is not GABC or self.params.selection != "raw":
            return None
        return 1 if self.params.rule == "mao2017" else 2

    def step(self, state, xs, xk, phi, streams):
        best = state.best_x[:, None, :]
        if self.params.rule == "mao2017":
            return phi * (xs - xk) + phi * (best - xk)
        psi = self.params.C * streams.uniform(xs.shape[1])[..., None]
        return phi * (xs - xk) + psi * (best - xs)

    def move(self, state, xs, xk, j, phi, streams):
        """:meth:`step` on the chosen coordinate only (same numbers, same draws)."""
        bx = state.best_x
        aux = getattr(state, "aux", None)
        rows = aux.row_d if aux is not None and aux.row_d.shape == j.shape else row_offsets(*bx.shape)[:, None]
        best = bx.reshape(-1).take(j + rows)
        out = np.subtract(xs, xk)
        out *= phi                                           # phi (xs - xk)
        if self.params.rule == "mao2017":
            best -= xk
            best *= phi                                      # phi (best - xk)
        else:
            best -= xs
            best *= self.params.C * streams.uniform(xs.shape[1])   # psi (best - xs)
        out += best
        return np.add(xs, out, out=out)
