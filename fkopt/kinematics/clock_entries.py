"""fkopt's exact solvers as entries of kinbench's clock track: one query per call, the interface of
the field's solvers (:class:`fkopt.adapters.field.FieldIK`: ``name``, ``package``, ``settings``,
``solve1``), so the one solver registry (:mod:`fkopt.registry`) lists them beside TRAC-IK and
roboticstoolbox, and the clock (:mod:`fkopt.kinbench.clock`) times them alike."""
from __future__ import annotations

import numpy as np

from fkopt.kinematics.solvers import FORWARD_TABLE, InverseSolver, forward
from fkopt.kinematics.start_tables import _forward_table


class FkoptInverse:
    """The organiser's entry: :func:`fkopt.kinematics.solvers.inverse` with its defaults and
    ``tol`` = (1e-9 m, 1e-9 rad), tight enough for every rung of the ladder, given the 4x4 target
    frame itself (no Euler angles: the conversion cost as much as the compiled solve), through a
    prepared :class:`fkopt.kinematics.solvers.InverseSolver` (``inverse``'s answers bit for bit; per query
    only the target is checked and the compiled loop runs). The solver -- its options checked, the
    start table (4096 FK evaluations) and the kernel's arguments -- is made when the wrapper is
    made, outside the clock, as the field's packages parse their URDF outside it. No wall-clock
    limit (it runs to its restart limit); its seed per query comes from the wrapper's generator."""

    name = "fkopt.inverse"
    package = "fkopt"
    TOL = (1e-9, 1e-9)

    def __init__(self, arm, *, timeout: float, rng: np.random.Generator):
        self.arm, self.timeout, self.rng = arm, float(timeout), rng
        self._solve = InverseSolver(arm, tol=self.TOL)
        self._solve(arm.fk_matrix(arm.bounds.mean(axis=1)))         # compiled code loaded, outside the clock
        self.settings = {"timeout_s": self.timeout, "tol": list(self.TOL), "wall_clock_limit": False,
                         "seed": "per query from the wrapper's generator", "defaults": "fkopt.inverse's"}

    def solve1(self, T):
        r = self._solve(T, seed=int(self.rng.integers(2**31 - 1)))
        return r.joints, bool(r.solved)

    def solve_batch(self, T: np.ndarray) -> np.ndarray:
        r = self._solve(T, seed=int(self.rng.integers(2**31 - 1)))
        return np.asarray(r.joints, dtype=float)


class FkoptForward:
    """The organiser's FK entry: :func:`fkopt.kinematics.solvers.forward` (local Newton, the start
    table's nearest poses, deterministic restarts, global search) with its defaults and ``tol`` =
    1e-10 on max |ik(pose) - legs| (joint units); its seed per query from the wrapper's
    generator; no wall-clock limit. One call and the start table (4096 closed-form evaluations)
    before the clock, as :class:`FkoptInverse`'s table and the field's URDF parsing."""

    name = "fkopt.forward"
    package = "fkopt"
    TOL = 1e-10

    def __init__(self, mechanism, *, timeout: float, rng: np.random.Generator):
        self.mechanism, self.timeout, self.rng, self._forward = mechanism, float(timeout), rng, forward
        forward(mechanism, mechanism.ik(mechanism.bounds.mean(axis=1)[None])[0], tol=self.TOL)
        _forward_table(mechanism, FORWARD_TABLE)                           # start table, outside the clock
        self.settings = {"timeout_s": self.timeout, "tol": self.TOL, "wall_clock_limit": False,
                         "seed": "per query from the wrapper's generator", "defaults": "fkopt.forward's"}

    def solve1(self, legs):
        r = self._forward(self.mechanism, legs, tol=self.TOL, seed=int(self.rng.integers(2**31 - 1)))
        return np.asarray(r.pose, dtype=float), bool(r.solved)

    def solve_batch(self, legs: np.ndarray) -> np.ndarray:
        r = self._forward(self.mechanism, legs, tol=self.TOL, seed=int(self.rng.integers(2**31 - 1)))
        return np.asarray(r.pose, dtype=float)
