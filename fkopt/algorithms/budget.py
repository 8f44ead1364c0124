"""The iteration budget, for algorithms whose schedule depends on it.

PSO's linearly decreasing inertia (liu2008), P-ABC's switch at a fraction of the iterations
(chang2024), the swarm phase of the ``*+lm`` hybrids and ACO's shrinking local step all need
the number of iterations the run will get. :meth:`Algorithm.minimize` (base.py) knows it but
does not pass it to ``initialize``; :class:`BudgetAware` overrides ``minimize`` to remember
it for the duration of the call, so base.py stays untouched. :func:`initialize_for` lets a
composite algorithm (P-ABC, hybrids) initialise an inner one with a budget of its choosing.
"""
from __future__ import annotations

from ..errors import FkoptError
from .base import Algorithm


class BudgetAware(Algorithm):
    """An algorithm that can read the iteration budget in ``initialize`` via :meth:`budget`."""

    _budget: int | None = None

    def minimize(self, problem, *, iterations: int, **kwargs):
        previous = self._budget
        self._budget = int(iterations)
        try:
            return super().minimize(problem, iterations=iterations, **kwargs)
        finally:
            self._budget = previous

    def budget(self) -> int:
        if self._budget is None:
            raise FkoptError(f"algorithm '{self.name}' needs the number of iterations: run it "
                             "through fkopt.solve() or Algorithm.minimize()")
        return self._budget


def initialize_for(algorithm: Algorithm, problem, population, streams, x0, iterations: int):
    """``algorithm.initialize(...)`` as if ``minimize`` had been called with ``iterations``."""
    if not isinstance(algorithm, BudgetAware):
        return algorithm.initialize(problem, population, streams, x0)
    previous = algorithm._budget
    algorithm._budget = int(iterations)
    try:
        return algorithm.initialize(problem, population, streams, x0)
    finally:
        algorithm._budget = previous
