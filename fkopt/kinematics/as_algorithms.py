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

**Every solution** (``params: {solutions: all}``): ``inverse`` (and ``exact`` on a serial arm)
searches every IK solution of a pose (:func:`fkopt.kinematics.branches.inverse_all`, with ``fixed``
/ ``spread`` for a redundant arm), ``forward`` (and ``exact`` on a parallel mechanism) every real
assembly mode (:func:`fkopt.kinematics.assembly_modes.all_solutions`): once per pose, not once
per run, so such an entry is no optimiser: :meth:`ExactSolver.solution_set` gives the set
(an experiment file writes it to ``solutions.csv``), and ``minimize`` refuses it.

This module sits beside :mod:`fkopt.kinematics.solvers` (which it wraps), not in :mod:`fkopt.algorithms`:
an algorithm knows only the problem interface (docs/ARCHITECTURE: floor 1), and these know
mechanisms. The registry names them like every algorithm.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from pydantic import Field, field_validator

from fkopt.algorithms.base import Algorithm, Params, RunRecord
from fkopt.errors import FkoptError
from fkopt.kinematics.assembly_modes import all_solutions as assembly_modes, prepare
from fkopt.kinematics.branches import ALL_TOL, inverse_all, locked_sets
from fkopt.kinematics.solvers import forward, inverse
from fkopt.progress import tick
from fkopt.numerics.streams import RunStreams, run_seed_sequence


def row_seeds(streams: RunStreams) -> list[int]:
    """One integer seed per row of ``streams`` (its own run stream's first word)."""
    return [int(run_seed_sequence(s, k).generate_state(1)[0]) for s, k in zip(streams.seeds, streams.run_ids)]


@dataclass
class SolutionSet:
    """Every solution an exact solver found for one pose (``params: {solutions: all}``), in one
    shape for both kinds: ``names`` of the unknowns and ``values`` (k, n) in the mechanism's public
    units (an arm's joints, a parallel mechanism's pose); ``per_solution`` one column per solution
    (an arm's position and geodesic rotation error; a parallel mechanism's residual and hits);
    ``search`` how the search decided it had them all (scalars: its stopping rule's settings and
    counts; no times, so the set is the same bits on every rerun)."""

    names: tuple[str, ...]
    values: np.ndarray
    per_solution: dict = field(default_factory=dict)
    search: dict = field(default_factory=dict)


#: The all-solutions search's options in :class:`InverseParams`, passed on as given.
BRANCH_OPTIONS = ("fixed", "spread", "spread_joints", "patience", "max_starts")


def _branch_options(p) -> dict:
    return {k: getattr(p, k) for k in BRANCH_OPTIONS if getattr(p, k, None) is not None}


#: What a parallel mechanism's solution set says its search stopped on: a stopping rule, except a
#: 6-6 platform's homotopy (all_solutions' method "homotopy"), which is complete by its certificate.
#: (A serial arm's search states its own: ``search["rule"]``, a certificate or its stopping rule.)
STOPPING_RULE = {"parallel": "rounds without a new solution",
                 "homotopy": "complete: 40 homotopy paths at 40 distinct nonsingular roots"}


def _checked_kind(solver, mech) -> None:
    if mech is None or getattr(mech, "kind", None) not in ((solver.family,) if solver.family else ("parallel", "serial")):
        what = {"parallel": "forward kinematics of a parallel mechanism",
                "serial": "inverse kinematics of a serial arm"}.get(solver.family, "FK or IK of a mechanism")
        raise FkoptError(f"algorithm '{solver.name}' solves {what} only; this problem is not one "
                         "(use 'exact', which picks forward or inverse by the mechanism's kind)")


class ExactSolver(Algorithm):
    """An exact solver's one-shot records (module docstring); subclasses give ``solve_row``."""

    #: the mechanism family the solver takes ("parallel": FK, "serial": IK; None: both)
    family: str | None = None

    @property
    def every_solution(self) -> bool:
        """Does this entry ask for every solution of a pose (``solutions: all``)?"""
        return getattr(self.params, "solutions", "one") == "all"

    def solve_row(self, problem, row: int, seed: int) -> tuple[np.ndarray, int]:
        """The answer for row ``row`` of ``problem`` and the evaluations it cost."""
        raise NotImplementedError

    def check_solution_set(self, mech) -> None:
        """Refuse, without searching, what :meth:`solution_set` would refuse on ``mech``: the
        wrong kind of mechanism, ``fixed``/``spread`` naming joints it does not have or leaving a
        redundant arm's solutions infinite, ``fixed``/``spread`` on a parallel mechanism."""
        _checked_kind(self, mech)
        p = self.params
        options = _branch_options(p)
        if mech.kind == "parallel":
            if options:
                raise FkoptError(f"{', '.join(options)}: options of a serial arm's search; '{mech.name}' is a "
                                 "parallel mechanism, whose search of every assembly mode takes tol only")
            return
        locked_sets(mech, **{k: v for k, v in options.items() if k in ("fixed", "spread", "spread_joints")})

    def prepare_solution_set(self, mech) -> None:
        """Load what :meth:`solution_set` runs on ``mech`` before its searches are timed: a 6-6
        platform's compiled homotopy tracker and start system (a serial arm's kernels load on its
        first search, as before)."""
        if mech.kind == "parallel":
            prepare(mech)

    def solution_set(self, mech, inputs: np.ndarray, seed: int) -> SolutionSet:
        """Every solution of one case: a serial arm's pose ``inputs`` (x, y, z, Z-Y-Z angles) by
        ``fkopt.inverse(arm, pose, solutions="all")``, a parallel mechanism's joints by
        :func:`fkopt.kinematics.assembly_modes.all_solutions`, with ``seed`` and the entry's
        options; tolerances not given in ``params`` are the search's own defaults."""
        self.check_solution_set(mech)
        p = self.params
        if mech.kind == "serial":
            set_ = p.model_fields_set
            tol = (p.position_tol if "position_tol" in set_ else ALL_TOL[0],
                   p.rotation_tol if "rotation_tol" in set_ else ALL_TOL[1])
            r = inverse_all(mech, np.asarray(inputs, dtype=float), tol=tol, seed=int(seed), **_branch_options(p))
            search = r.search
            # spread: one search per locked set; the fewest starts since a new solution is the
            # least evidence any of them stopped on
            since = search["since_last_new"]
            return SolutionSet(tuple(r.names), np.asarray(r.solutions, dtype=float).reshape(-1, len(r.names)),
                               {"position_error": np.asarray(r.position_error, dtype=float),
                                "rotation_error": np.asarray(r.rotation_error, dtype=float)},
                               {"stopping_rule": str(search["rule"]), "patience": int(search["patience"]),
                                "max_starts": int(search["max_starts"]), "starts": int(search["starts"]),
                                "converged": int(search["converged"]),
                                "since_last_new": int(min(since) if isinstance(since, list) else since),
                                "evaluations": int(search["evaluations"]), "distinct": int(search["distinct"]),
                                "out_of_limits": int(search["out_of_limits"]),
                                "unverified": int(search["unverified"])})
        given = {"tol": p.tol} if "tol" in p.model_fields_set else {}
        found = assembly_modes(mech, np.asarray(inputs, dtype=float), seed=int(seed), **given)
        poses = found.poses()
        order = np.lexsort(poses.T[::-1]) if len(poses) else np.arange(0)     # sorted by pose, as kind: assembly
        return SolutionSet(tuple(found.names), poses[order],
                           {"residual": np.array([s.residual for s in found], dtype=float)[order],
                            "hits": np.array([s.hits for s in found], dtype=np.int64)[order]},
                           {"stopping_rule": STOPPING_RULE["homotopy" if found.method == "homotopy" else "parallel"],
                            "patience": int(found.settings["patience"]),
                            "round_size": int(found.settings["round_size"]), "starts": int(found.starts),
                            "outside_bounds": int(found.outside)})

    def minimize(self, problem, *, population: int, iterations: int, streams: RunStreams,
                 target: float | None = None, stop_at_target: bool = False,
                 x0: np.ndarray | None = None, snapshots=(), x_history: bool = True) -> RunRecord:
        mech = getattr(problem, "mechanism", None)
        _checked_kind(self, mech)
        if self.every_solution:
            raise FkoptError(f"algorithm '{self.name}' with solutions: all gives every solution of a pose, not one "
                             "answer per run: it runs in experiment files (solutions.csv) or as "
                             "fkopt.inverse(arm, pose, solutions='all'); use solutions: one here")
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


#: ``solutions``: one answer per run, or every solution of each pose once (module docstring).
SOLUTIONS_FIELD = Field("one", description="one: one answer per run; all: every solution of each case "
                                           "once (experiment files: solutions.csv)")


class ForwardParams(Params):
    tol: float = Field(1e-9, gt=0, description="largest accepted max |ik(pose) - joints|, joint units "
                                               "(solutions: all: relative to max(1, |joint|), the search's)")
    solutions: Literal["one", "all"] = SOLUTIONS_FIELD
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
    position_tol: float = Field(1e-6, gt=0, description="position tolerance (arm's length unit; solutions: "
                                                        "all: 1e-9 unless given)")
    rotation_tol: float = Field(1e-6, gt=0, description="orientation tolerance (rad; solutions: all: 1e-9 "
                                                        "unless given)")
    restarts: int = Field(200, ge=0, description="most random restarts per pose")
    solutions: Literal["one", "all"] = SOLUTIONS_FIELD
    # the all-solutions search's own options (fkopt.inverse(..., solutions="all"))
    fixed: dict[str, float] | None = Field(None, description="solutions: all: joints locked at values "
                                                             "(public units), a redundant arm's finite set")
    spread: int | None = Field(None, ge=1, description="solutions: all: samples per locked joint of a "
                                                       "redundant arm's self-motion")
    spread_joints: list[str] | None = Field(None, min_length=1, description="solutions: all with spread: "
                                                                            "the locked joints")
    patience: int | None = Field(None, ge=1, description="solutions: all: consecutive starts without a new "
                                                         "solution before the search stops (default 128 on a "
                                                         "6R chain with Pieper's bound, else 32)")
    max_starts: int | None = Field(None, ge=1, description="solutions: all: most starts per pose "
                                                           "(default 400)")

    @field_validator(*BRANCH_OPTIONS)
    @classmethod
    def _only_with_all(cls, value, info):
        if value is not None and info.data.get("solutions", "one") != "all":
            raise ValueError("only with solutions: all (the search of every solution)")
        return value


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
