"""EAIK (Ostermeier, Kuelz and Althoff, "Automatic Geometric Decomposition for Analytical Inverse
Kinematics", IEEE RA-L 2025, arXiv:2409.14815; ``pip install eaik``): analytic IK by subproblem
decomposition (the subproblems of Elias and Wen's IK-Geo), every solution of a pose, for the 1-6R
arms whose axes intersect or are parallel so that its decomposition applies.

Two calls:

* :meth:`EAIK.solve1` -- the board's one answer per query: the first of EAIK's exact (not
  least-squares) solutions inside fkopt's joint limits, ``None`` when none is;
* :meth:`EAIK.solutions` -- every solution EAIK returns for a pose (:class:`Solutions`: joints,
  its least-squares flags, and which lie inside the limits), for "every IK solution".

Quirks worked around -- how it reads the arm, as its README does: :class:`eaik.IK_URDF.UrdfRobot` on a URDF file. It
takes *every* actuated joint of the file (the Panda's fingers too), so it is given the URDF
written from fkopt's chain (:func:`fkopt.adapters.field.arm_urdf`): the
chain's joints only. Its end effector is the last joint's child link origin with the base's
orientation at q = 0 (its ``P``'s last column is zero, ``R6T`` the identity); the arm's tip is
rigidly attached to that link, so the tip frame is EAIK's frame times one constant transform
``C``, found once from fkopt's FK at the middle of the limits and checked at a second
configuration (a disagreement -- joints read in another order -- refuses the arm). A target T is
given to EAIK as ``T C^-1``. EAIK's angles are unbounded; a revolute joint's answer is shifted
by whole turns into the limits where one fits.

Not applicable (:class:`~fkopt.adapters.field.NotApplicable`, a "not applicable: why" cell on
the board, never a zero): more than 6 joints (EAIK solves 1-6R chains; a redundant joint must be
locked at a value, which answers only the poses reachable at that value), a prismatic joint, or
a 6R chain with no known decomposition (``hasKnownDecomposition()`` False).

Settings: none to choose (analytic); one call, no restarts, no timeout; the decomposition is
made when the wrapper is made, outside the clock.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fkopt.errors import FkoptError
from fkopt.adapters.field import FieldIK, NotApplicable, arm_urdf


@dataclass
class Solutions:
    """Every solution EAIK gives for one pose: ``joints`` (k, dof) in fkopt's public units (deg,
    m; revolute joints shifted by whole turns into the limits where one fits), ``least_squares``
    (k,): EAIK's flag for a least-squares (not exact) solution, ``in_limits`` (k,)."""
    joints: np.ndarray
    least_squares: np.ndarray
    in_limits: np.ndarray


class EAIK(FieldIK):
    name = "eaik"
    package = "eaik"

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        import eaik
        from eaik.IK_URDF import UrdfRobot
        if arm.dof > 6:
            raise NotApplicable(f"{arm.dof} joints: EAIK solves 1-6R chains (a redundant joint must be locked "
                                "at a value, which answers only the poses reachable at that value)")
        prismatic = [n for n, u in zip(arm.unknown_names, arm.unknown_units) if u != "deg"]
        if prismatic:
            raise NotApplicable(f"prismatic joint {prismatic[0]}: EAIK's URDF robots are revolute chains")
        urdf = arm_urdf(arm)
        with urdf.as_file() as path:
            self._robot = UrdfRobot(str(path))
        if not self._robot.hasKnownDecomposition():
            raise NotApplicable(f"EAIK knows no decomposition of this {arm.dof}R chain "
                                f"(its family: {self._robot.getKinematicFamily()})")
        mid = arm.bounds.mean(axis=1)
        self._C = np.linalg.solve(self._robot.fwdKin(mid * arm._to_si), arm.fk_matrix(mid[None])[0])
        other = arm.bounds[:, 0] + 0.3 * (arm.bounds[:, 1] - arm.bounds[:, 0])
        if np.abs(self._robot.fwdKin(other * arm._to_si) @ self._C - arm.fk_matrix(other[None])[0]).max() > 1e-9:
            raise FkoptError(f"eaik: its FK of {urdf.source} differs from fkopt's (joints read in another order?)")
        self._Cinv = np.linalg.inv(self._C)
        self._revolute = np.asarray(arm.unknown_units) == "deg"
        self.settings.update(urdf=urdf.source, family=self._robot.getKinematicFamily(),
                             version=getattr(eaik, "__version__", "1.2.2"),
                             answer="the first exact (not least-squares) solution inside the limits",
                             wall_clock_limit=False, restarts="none (analytic)")

    def solutions(self, T: np.ndarray) -> Solutions:
        """Every solution EAIK returns for the tip frame ``T`` (4x4, m, in the arm's base frame)."""
        sol = self._robot.IK(np.asarray(T, float) @ self._Cinv)
        Q = np.asarray(sol.Q, dtype=float).reshape(-1, self.arm.dof)
        ls = np.asarray(sol.is_LS, dtype=bool).reshape(len(Q))
        Q = self._into_limits(Q)
        inside = np.all((Q >= self.lo_rad) & (Q <= self.hi_rad), axis=1)
        return Solutions(np.array([self.public(q) for q in Q]).reshape(len(Q), self.arm.dof), ls, inside)

    def _into_limits(self, Q: np.ndarray) -> np.ndarray:
        """Revolute joints shifted by whole turns towards the limits (the nearest turn that fits)."""
        two_pi = 2 * np.pi
        k = np.ceil((self.lo_rad - Q) / two_pi)                   # fewest turns up to reach lo
        k = np.where(Q > self.hi_rad, -np.ceil((Q - self.hi_rad) / two_pi), np.where(Q < self.lo_rad, k, 0.0))
        return np.where(self._revolute, Q + k * two_pi, Q)

    def solve1(self, T):
        sol = self._robot.IK(np.asarray(T, float) @ self._Cinv)
        Q = np.asarray(sol.Q, dtype=float).reshape(-1, self.arm.dof)
        if not len(Q):
            return None, False
        exact = ~np.asarray(sol.is_LS, dtype=bool).reshape(len(Q))
        Q = self._into_limits(Q[exact])
        inside = np.flatnonzero(np.all((Q >= self.lo_rad) & (Q <= self.hi_rad), axis=1))
        if not len(inside):
            return None, False
        return self.public(Q[inside[0]]), True
