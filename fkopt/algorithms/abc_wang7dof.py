"""The ABC as wang7dof prints it: its eq. (7) neighbour move and its quality 1/f.

fkopt's :class:`~fkopt.algorithms.abc.ABC` follows Karaboga (phi ~ U[-1, 1], quality 1/(1 + f)).
wang7dof writes the move v_ij = x_ij + phi (x_ij - x_kj) with phi = rand(0, 1) (eq. 7), which only
ever steps away from the neighbour, and the quality fit_i = 1/f_i (eq. 8). This class runs exactly
that, to judge the paper's claims on the ABC it printed beside fkopt's (issue 41), with everything
else (population = food sources, limit = population x dim, the order of the draws) as
:class:`~fkopt.algorithms.abc.ABC`:

* phi = (phi' + 1) / 2 of ABC's own draw phi' = 2u - 1, i.e. phi = u ~ U[0, 1): the same draws;
* the onlooker roulette on 1/f (a source of f = 0 holds every onlooker: the first such source);
  the greedy selection and the best-so-far compare raw f, which 1/f orders the same way.
"""
from __future__ import annotations

import numpy as np

from fkopt.algorithms.abc import ABC, roulette


class ABCWang7dof(ABC):
    name = "abc-wang7dof"
    uses_best = False        # the move reads no best-so-far point

    def move(self, state, xs, xk, j, phi, streams):
        """eq. (7): xs + u (xs - xk), u = (phi + 1) / 2 ~ U[0, 1) from ABC's own phi = 2u - 1."""
        u = np.add(phi, 1.0)
        u *= 0.5
        out = np.subtract(xs, xk)
        out *= u
        return np.add(xs, out, out=out)

    def _choose_sources(self, state, aux, streams) -> np.ndarray:
        """The onlookers' roulette on the paper's quality 1/f (eq. 8): SN uniforms per run, as ABC."""
        f = state.f
        with np.errstate(divide="ignore"):
            q = np.where(f > 0, 1.0 / np.where(f > 0, f, 1.0), np.inf)
        zero = np.isinf(q)
        if zero.any():      # f = 0 (or below): infinite quality, that source takes every onlooker
            q = np.where(zero, 1.0, 0.0) + np.where(zero.any(axis=1, keepdims=True), 0.0, np.where(zero, 0.0, q))
        cdf = q.cumsum(axis=1)
        u = streams.uniform(f.shape[1]) * cdf[:, -1:]
        return roulette(cdf, u)
