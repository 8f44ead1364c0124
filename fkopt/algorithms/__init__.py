"""Algorithms: minimisers over arrays shaped (runs, population, dim).

One module per algorithm, registered in :mod:`fkopt.registry`. An algorithm sees only the
problem interface (``fitness``, ``bounds``, ``dim``; ``residuals`` for the exact methods) and
knows nothing of mechanisms.
"""
from fkopt.algorithms.base import Algorithm, RunRecord, State

__all__ = ["Algorithm", "RunRecord", "State"]
