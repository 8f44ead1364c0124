"""The one restart loop of fkopt's solvers, after roboticstoolbox's ``IKSolver._solve`` (Corke and
Haviland 2021, "Not your grandmother's toolbox"): a solver supplies its j-th start, a local search
from a start (its step, iterated) and a stopping test; the loop runs starts in order, keeps the
best answer, and stops at the first answer that meets the test, or when the budget or the
solver's give-up test (a deadline) is spent.

* :func:`restart` -- one problem, starts one after another: ``fkopt.inverse``'s one-pose loop
  (:func:`fkopt.numerics.damped_least_squares.inverse_candidates`), ``all_solutions`` of a
  parallel mechanism (a start is a round of starts, the test its stopping rule), and the outside
  packages without a restart loop of their own (pinocchio's CLIK, ikpy, pink, the black-box
  optimisers: :mod:`fkopt.adapters.field.restarts`).
* :func:`restart_rows` -- the same loop for the rows of a batch side by side: every row not yet
  done takes its next start, all rows in one call of the solver's vectorised search (numpy's
  per-call cost is paid once per start, not once per row): ``fkopt.forward``'s starts (the given
  one, the start table's, the deterministic ones, then the global search).

The compiled twin is :func:`fkopt.numerics.compiled_ik._inverse_one` (the one-pose loop of
``fkopt.inverse``, a local search :func:`fkopt.numerics.compiled_ik._dls_candidate` per start); the
all-solutions and path kernels of serial arms run that candidate search one start at a time.
``fkopt.inverse``'s batched numpy loop restarts candidates in place among the rows of a batch
(:mod:`fkopt.kinematics.inverse_batch`): its starts are the ones of this loop, in the same order.
"""
from __future__ import annotations

import math
from typing import Any, Callable


def restart(start: Callable[[int], Any], search: Callable[[Any], Any], met: Callable[[Any], bool], *,
            merit: Callable[[Any], float] | None = None, budget: int | None = None,
            give_up: Callable[[], bool] | None = None) -> tuple[Any, bool, int]:
    """Starts ``start(j)``, j = 0, 1, ..., each searched (``search(x0)`` -> an answer) until an
    answer meets the stopping test ``met``: (that answer, True, starts used). Otherwise, after
    ``budget`` starts, or as soon as ``give_up()`` holds after a start (a deadline): (the answer of
    smallest ``merit``, False, starts used). The first answer is kept whatever its merit (a merit
    that is not a number counts as infinite), so there is always one; ties keep the earlier one.
    Without ``merit`` the last answer is returned."""
    best, best_m, j = None, math.inf, 0
    while budget is None or j < budget:
        got = search(start(j))
        j += 1
        if met(got):
            return got, True, j
        if merit is None:
            best = got
        else:
            m = merit(got)
            if best is None or m < best_m:
                best, best_m = got, (m if m == m else math.inf)
        if give_up is not None and give_up():
            break
    return best, False, j


def restart_rows(rows, search: Callable[[int, Any], Any]):
    """:func:`restart` for the rows of a batch: ``search(j, rows)`` runs start j of every row in
    ``rows`` (an index array) at once, keeps each row's best answer itself, and returns the mask
    of the rows that are done (met the stopping test) -- or None when there is no start j. Rows
    done leave; the loop ends when no row is left or no start is. Returns the rows left."""
    j = 0
    while len(rows):
        done = search(j, rows)
        if done is None:
            break
        rows = rows[~done]
        j += 1
    return rows
