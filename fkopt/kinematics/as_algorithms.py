"""fkopt's exact solvers as algorithms: ``forward`` (:func:`fkopt.forward`, FK of a parallel
mechanism), ``inverse`` (:func:`fkopt.inverse`, IK of a frame arm) and ``exact`` (whichever of
the two the problem's mechanism needs: one solver for a suite's FK and IK problems), so a suite or an
experiment runs them on the same batched problems, seeds and evaluation counting as the swarms.

Each row (case x run) of the batch is solved alone by the exact solver with the row's integer
seed (the first word of ``SeedSequence(case seed, spawn_key=(run,))``, as the adapters), so a
row's numbers do not depend on the rest of the batch; the solver's own numbers are those of
:func:`fkopt.forward` / :func:`fkopt.inverse` on that one pose, unchanged. Its evaluations are
what the solver reports, ``residual + jacobian`` (one analytic Jacobian counts as one
evaluation, as everywhere in fkopt). The answer is scored by the problem's own fitness (one more
evaluation, counted). An exact solver has no iterations: every record t = 0..iterations holds
the answer's fitness at the evaluations used, so a budget cut below them (a suite's ``B``)
leaves the run with no answer -- the solver did not finish within the budget.

This module sits beside :mod:`fkopt.kinematics.solvers` (which it wraps), not in :mod:`fkopt.algorithms`:
an algorithm knows only the problem interface (docs/ARCHITECTURE: floor 1), and these know
mechanisms. The registry names them like every algorithm.
"""
from __future__ import annotations

import numpy as np
from pydantic import Field

from fkopt.algorithms.base import Algorithm, Params, RunRecord
from fkopt.errors import FkoptError
from fkopt.kinematics.solvers import forward, inverse
from fkopt.progress import tick
from fkopt.numerics.streams import RunStreams, run_seed_sequence


def row_seeds(streams: RunStreams) -> list[int]:
    """One integer seed per row of ``streams`` (its own run stream's first word)."""
    return [int(run_seed_sequence(s, k).generate_state(1)[0]) for s, k in zip(streams.seeds, streams.run_ids)]


class ExactSolver(Algorithm):
    """An exact solver's one-shot records (module docstring); subclasses give ``solve_row``."""

    #: the mechanism family the solver takes ("parallel": FK, "serial": IK; None: both)
    family: str | None = None

    def solve_row(self, problem, row: int, seed: int) -> tuple[np.ndarray, int]:
        """The answer for row ``row`` of ``problem`` and the evaluations it cost."""
        raise NotImplementedError

    def minimize(self, problem, *, population: int, iterations: int, streams: RunStreams,
                 target: float | None = None, stop_at_target: bool = False,
                 x0: np.ndarray | None = None, snapshots=(), x_history: bool = True) -> RunRecord:
        mech = getattr(problem, "mechanism", None)
        if mech is None or getattr(mech, "kind", None) not in ((self.family,) if self.family else ("parallel", "serial")):
            what = {"parallel": "forward kinematics of a parallel mechanism",
                    "serial": "inverse kinematics of a serial arm"}.get(self.family, "FK or IK of a mechanism")
            raise FkoptError(f"algorithm '{self.name}' solves {what} only; this problem is not one "
                             "(use 'exact', which picks forward or inverse by the mechanism's kind)")
        runs = streams.runs
        rows = problem.repeat(runs)        # an experiment's one target: one row per run
        xs = np.empty((runs, problem.dim))
        used = np.empty(runs, dtype=np.int64)
        for r, seed in enumerate(row_seeds(streams)):
            xs[r], used[r] = self.solve_row(rows, r, seed)
            tick(r + 1, runs)
        f = rows.fitness(xs[:, None, :])[:, 0]          # the problem's own score of each answer
        used += 1
        T = iterations + 1
        hist = np.repeat(f[:, None], T, axis=1)
        ev = np.repeat(used[:, None], T, axis=1)
        done = np.full(runs, iterations)
        if stop_at_target and target is not None:
            done = np.where(f < target, 0, iterations)
        return RunRecord(best_x=xs, best_f=f, history=hist,
                         x_history=np.repeat(xs[:, None, :], T, axis=1) if x_history else None,
                         evaluation_history=ev, iterations_done=done,
                         snapshots={int(t): xs[:, None, :].copy() for t in snapshots},
                         events=(np.arange(runs), used.copy(), f.copy()))


class ForwardParams(Params):
    tol: float = Field(1e-9, gt=0, description="largest accepted max |ik(pose) - joints|, joint units")
    global_search: bool = Field(True, description="fall back to fkopt.forward's global stage")
    # 0 by default: the stored paper and kinbench results were made without the start table
    table: int = Field(0, ge=0, description="fkopt.forward's start table size (0: none, the stored results' "
                                            "setting; fkopt.forward's own default is 4096)")


def _forward(problem, row: int, seed: int, p) -> tuple[np.ndarray, int]:
    out = forward(problem.mechanism, problem.joints[row], tol=p.tol, seed=seed, global_search=p.global_search,
                  table=p.table)
    return out.pose, int(out.evaluations["residual"]) + int(out.evaluations["jacobian"])


def _inverse(problem, row: int, seed: int, p) -> tuple[np.ndarray, int]:
    out = inverse(problem.mechanism, problem.target[row], tol=(p.position_tol, p.rotation_tol), seed=seed,
                  restarts=p.restarts)
    return out.joints, int(out.evaluations["residual"]) + int(out.evaluations["jacobian"])


class Forward(ExactSolver):
    """:func:`fkopt.forward` on each row's joints (start: the centre of the bounds; ``table`` 0
    unless the config sets it: the stored results' setting, without forward's start table)."""

    name = "forward"
    Params = ForwardParams
    family = "parallel"

    def solve_row(self, problem, row: int, seed: int) -> tuple[np.ndarray, int]:
        return _forward(problem, row, seed, self.params)


class InverseParams(Params):
    position_tol: float = Field(1e-6, gt=0, description="position tolerance (arm's length unit)")
    rotation_tol: float = Field(1e-6, gt=0, description="orientation tolerance (rad)")
    restarts: int = Field(200, ge=0, description="most random restarts per pose")


class Inverse(ExactSolver):
    """:func:`fkopt.inverse` on each row's target pose (start: mid-range)."""

    name = "inverse"
    Params = InverseParams
    family = "serial"

    def solve_row(self, problem, row: int, seed: int) -> tuple[np.ndarray, int]:
        return _inverse(problem, row, seed, self.params)


class ExactParams(ForwardParams, InverseParams):
    pass


class Exact(ExactSolver):
    """The exact solver of the problem's kind: :class:`Forward` for a parallel mechanism,
    :class:`Inverse` for a serial arm (one solver over a suite's FK and IK problems)."""

    name = "exact"
    Params = ExactParams

    def solve_row(self, problem, row: int, seed: int) -> tuple[np.ndarray, int]:
        solve = _forward if problem.mechanism.kind == "parallel" else _inverse
        return solve(problem, row, seed, self.params)
