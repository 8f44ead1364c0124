"""fkopt's exact solvers as kinbench entries, with the interface of the field's solvers, so the one
solver registry (:mod:`fkopt.registry`) lists them beside TRAC-IK, roboticstoolbox and EAIK:

* the clock track (:mod:`fkopt.kinbench.clock`): one query per call (:class:`fkopt.adapters.field.FieldIK`:
  ``name``, ``package``, ``settings``, ``solve1``), timed alike -- ``fkopt.inverse``, ``fkopt.forward``;
* the ``all-solutions`` and ``paths`` tracks (:mod:`fkopt.kinbench.solution_sets`, :mod:`fkopt.kinbench.paths`;
  the field's side is :mod:`fkopt.adapters.field.track_entries`: ``solutions`` or ``path``) --
  ``fkopt.inverse-all``, ``fkopt.inverse_path``.
"""
from __future__ import annotations

import numpy as np

from fkopt.kinematics.branches import inverse_all, inverse_path
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

# -- the all-solutions and paths tracks ------------------------------------------------------------
# fkopt's entries of kinbench's ``all-solutions`` and ``paths`` tracks (:mod:`fkopt.kinbench.solution_sets`,
# :mod:`fkopt.kinbench.paths`), with the interface of the field's entries there
# (:mod:`fkopt.adapters.field.track_entries`: ``name``, ``package``, ``settings``, ``solutions`` or
# ``path``), so that the one solver registry (:mod:`fkopt.registry`) lists them beside EAIK, rtb and
# TRAC-IK.
#
# * ``fkopt.inverse-all`` -- ``fkopt.inverse(arm, T, solutions="all")`` (:func:`fkopt.kinematics.branches.inverse_all`)
#   with its defaults, ``fixed=`` the track's locked joint on a 7-joint arm (the locked joint's column
#   dropped from the answers, so every entry answers on the same 6-joint chain), its seed per pose from
#   the wrapper's generator;
# * ``fkopt.inverse_path`` -- ``fkopt.inverse_path(arm, T, start=q0)`` with its defaults (one call per
#   path; its ``breaks`` are not looked at: the track judges the joints).
#
# The compiled kernels are loaded when the wrapper is made (one call on a pose at the middle of the
# limits), outside the clock, as the field's packages parse their URDF outside it.


class FkoptAllSolutions:
    name = "fkopt.inverse-all"
    package = "fkopt"

    def __init__(self, arm, *, timeout: float, rng: np.random.Generator, fixed=None):
        self.arm, self.timeout, self.rng = arm, float(timeout), rng
        self.fixed = dict(fixed or {})
        self._free = [k for k, n in enumerate(arm.unknown_names) if n not in self.fixed]
        mid = arm.bounds.mean(axis=1)
        for k, n in enumerate(arm.unknown_names):
            if n in self.fixed:
                mid[k] = self.fixed[n]
        inverse_all(arm, arm.fk_matrix(mid[None])[0], fixed=self.fixed or None)      # kernels loaded
        self.settings = {"call": 'fkopt.inverse(arm, T, solutions="all")', "defaults": "fkopt.inverse's",
                         "tol": "1e-9 m, 1e-9 rad (its default)", "seed": "per pose from the wrapper's generator",
                         "wall_clock_limit": False, **({"fixed": self.fixed} if self.fixed else {})}

    def solutions(self, T) -> np.ndarray:
        r = inverse_all(self.arm, T, fixed=self.fixed or None, seed=int(self.rng.integers(2**31 - 1)))
        return np.asarray(r.solutions, dtype=float).reshape(-1, self.arm.dof)[:, self._free]


class FkoptPath:
    name = "fkopt.inverse_path"
    package = "fkopt"

    def __init__(self, arm, *, timeout: float, rng: np.random.Generator, fixed=None):
        self.arm, self.timeout, self.rng = arm, float(timeout), rng
        mid = arm.bounds.mean(axis=1)
        inverse_path(arm, arm.fk_matrix(np.stack([mid, mid])), start=mid)            # kernels loaded
        self.settings = {"call": "fkopt.inverse_path(arm, T, start=q0)", "defaults": "fkopt.inverse_path's",
                         "max_step": "0.05 rad (its default)", "wall_clock_limit": False}

    def path(self, T: np.ndarray, start: np.ndarray) -> np.ndarray:
        return np.asarray(inverse_path(self.arm, T, start=start).joints, dtype=float)
