"""The evaluation budget of a suite and the measures of a run at that budget (used by the
runner for fkopt's solvers and by :mod:`fkopt.kinbench.outside` for imported runs alike)."""
from __future__ import annotations

import numpy as np


def target_column(t: float) -> str:
    return f"evals_to_{t:.0e}"


def budget_of(config, dim: int) -> int:
    """Evaluations a run of a problem of dimension ``dim`` may spend: budget_per_dim x dim."""
    return int(config.budget_per_dim) * int(dim)


def last_within(evals: np.ndarray, budget: int) -> np.ndarray:
    """Per run, the index of the last record (iteration) whose cumulative evaluations are within
    ``budget`` (-1: none is), from ``evals`` (..., T + 1): where every measure of a run is read."""
    within = np.asarray(evals) <= budget
    return np.where(within.any(axis=-1), within.shape[-1] - 1 - np.argmax(within[..., ::-1], axis=-1), -1)


def at_budget(history: np.ndarray, evals: np.ndarray, budget: int, targets) -> dict:
    """Measures of runs from their best-so-far fitness and cumulative evaluations per iteration
    (``(..., T + 1)`` each), cut at ``budget`` evaluations: evaluations used (the budget itself for
    a run with no record within it), final fitness and, per target, the evaluations when the
    target was first reached (NaN: not within the budget)."""
    within = evals <= budget
    last = last_within(evals, budget)
    ok = last >= 0
    li = np.maximum(last, 0)[..., None]
    # a run with no record within the budget (an exact solver whose answer cost more than B) spent
    # the whole budget without an answer: it counts B toward ERT, not 0
    used = np.where(ok, np.take_along_axis(evals, li, axis=-1)[..., 0], budget).astype(float)
    final = np.where(ok, np.take_along_axis(history, li, axis=-1)[..., 0], np.inf)
    out = {"evaluations": used, "fitness": final}
    for t in targets:
        hit = (history < t) & within
        first = np.argmax(hit, axis=-1)[..., None]
        ev = np.take_along_axis(evals, first, axis=-1)[..., 0].astype(float)
        out[target_column(t)] = np.where(hit.any(axis=-1), ev, np.nan)
    return out
