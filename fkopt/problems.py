"""Problems: a mechanism paired with what was measured, as a bounded minimisation.

A problem exposes ``dim``, ``bounds`` (dim, 2), ``variable_names``, ``residuals(x[..., dim])``
and ``fitness(x[..., dim]) -> [...]``, all vectorised over any leading batch shape, and knows
nothing of algorithms. Algorithms see only this interface.
"""
from __future__ import annotations

from typing import Literal

import numpy as np

from .errors import FkoptError
from . import rotations
from .mechanisms.base import Mechanism, ParallelMechanism, SerialMechanism
from .rotations import wrap_degrees

#: Objectives built from residuals r: "squared" = sum r_i^2 (mao2017 eq. 12, wu2015, chang2024),
#: "absolute" = sum |r_i| (liu2008 as printed).
OBJECTIVES = ("squared", "absolute")


class Problem:
    """Bounded minimisation of ``fitness`` over ``dim`` variables."""

    variable_names: tuple[str, ...]
    variable_units: tuple[str, ...]
    bounds: np.ndarray

    @property
    def dim(self) -> int:
        return len(self.variable_names)

    def fitness(self, x) -> np.ndarray:
        raise NotImplementedError

    def residuals(self, x) -> np.ndarray:
        raise NotImplementedError

    #: True when :meth:`jacobian` is analytic (solvers use it instead of central differences).
    has_jacobian: bool = False

    def jacobian(self, x) -> np.ndarray:
        """d(residuals)/dx (..., m, dim); NotImplementedError when the mechanism has no analytic
        Jacobian (solvers then fall back to central differences)."""
        raise NotImplementedError


class FKProblem(Problem):
    """Forward kinematics of a parallel mechanism: find the pose whose inverse map gives ``joints``.

    Residuals are ``ik(x) - joints`` (angle-valued joints wrapped to [-180, 180) degrees);
    fitness is their sum of squares (default) or of absolute values.
    """

    def __init__(self, mechanism: Mechanism, joints, *, objective: Literal["squared", "absolute"] = "squared",
                 bounds=None):
        if not isinstance(mechanism, ParallelMechanism):
            raise FkoptError(f"fk_problem needs a parallel mechanism; '{mechanism.name}' is {mechanism.kind} "
                             "(use ik_problem for a serial arm)")
        joints = mechanism.as_values(joints, mechanism.joint_names, "joints")
        if objective not in OBJECTIVES:
            raise FkoptError(f"objective '{objective}' unknown; allowed: {', '.join(OBJECTIVES)}")
        self.mechanism = mechanism
        self.joints = joints
        self.objective = objective
        self.variable_names = mechanism.pose_names
        self.variable_units = mechanism.pose_units
        self.bounds = mechanism.bounds if bounds is None else np.asarray(bounds, dtype=float)
        self._angle = mechanism.angle_mask(mechanism.joint_units)
        self.has_jacobian = hasattr(mechanism, "jacobian")

    def residuals(self, x) -> np.ndarray:
        r = self.mechanism.ik(x) - self.joints
        if self._angle.any():
            r = np.where(self._angle, wrap_degrees(r), r)
        return r

    def jacobian(self, x) -> np.ndarray:
        """d(residuals)/d(pose) (..., m, dim) = the mechanism's analytic ``jacobian`` (the
        wrap of angle-valued joints has derivative 1 wherever it is continuous)."""
        if not hasattr(self.mechanism, "jacobian"):
            raise NotImplementedError
        return self.mechanism.jacobian(x)

    def fitness(self, x) -> np.ndarray:
        r = self.residuals(x)
        if self.objective == "absolute":
            return np.abs(r).sum(axis=-1)
        return (r * r).sum(axis=-1)


def fk_problem(mechanism: Mechanism, joints, **kwargs) -> FKProblem:
    """Pair a parallel mechanism with measured joint values (dict by name or array)."""
    return FKProblem(mechanism, joints, **kwargs)


#: Orientation errors of :class:`IKProblem`: "paper" = Euclidean norm of the wrapped Z-Y-Z Euler
#: differences (wang7dof), "geodesic" = rotation angle of R_target^T R.
IK_OBJECTIVES = ("paper", "geodesic")


def so3_right_jacobian_inverse(e) -> np.ndarray:
    """J_r^{-1}(e) (..., 3, 3) of rotation vectors e (..., 3): d log(M) = J_r^{-1} (M^T dM)^vee."""
    e = np.asarray(e, dtype=float)
    th2 = (e * e).sum(-1)
    th = np.sqrt(th2)
    small = th2 < 1e-8
    ths = np.where(small, 1.0, th)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(small, 1.0 / 12.0 + th2 / 720.0,
                     1.0 / (ths * ths) - (1.0 + np.cos(ths)) / (2.0 * ths * np.sin(ths)))
    K = np.zeros(e.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -e[..., 2], e[..., 1], -e[..., 0]
    K[..., 1, 0], K[..., 2, 0], K[..., 2, 1] = e[..., 2], -e[..., 1], e[..., 0]
    return np.eye(3) + 0.5 * K + c[..., None, None] * (K @ K)


def _norm3(a, b, c):
    return np.sqrt(a * a + b * b + c * c)


class IKProblem(Problem):
    """Inverse kinematics of a serial arm: find joints whose end-effector pose is ``pose``.

    SPEC.md "wang7dof": fitness f = w_p * dP + w_r * dR, dP the distance between the tool
    point and the target position (mm), dR in radians, w_p = 1 and w_r = 180/pi by default (so
    f reads "mm + degrees"). ``objective`` chooses dR:

    * ``"paper"`` (wang7dof as printed): Euclidean norm of the differences of the Z-Y-Z Euler
      angles (alpha, beta, gamma), each wrapped to [-180, 180) deg. Singular where
      sin(beta) = 0 (alpha, gamma undefined), at the target or along the way;
    * ``"geodesic"``: the rotation angle of R_target^T R, in [0, pi], well defined everywhere.

    ``residuals(x)`` is the 6-vector (w_p dx, w_p dy, w_p dz, w_r e1, w_r e2, w_r e3), with
    e = the wrapped Euler differences (paper) or the rotation vector of R_target^T R
    (geodesic), so ``fitness = |r[:3]| + |r[3:]|`` exactly (a sum of two norms, not of
    squares); a least-squares solver on the residuals has the same zeros.

    The target's Euler angles are normalised to the range the extraction produces (beta in
    [0, 180]: (alpha, -beta, gamma) becomes (alpha + 180, beta, gamma + 180)), so the paper
    objective is zero at every exact solution; ``self.target`` holds the normalised pose.
    A target position farther from the base origin than the arm's reach (``mechanism.reach``,
    sum of sqrt(a_i^2 + d_i^2) for a DH arm) is rejected.
    """

    def __init__(self, mechanism: Mechanism, pose, *, objective: Literal["paper", "geodesic"] = "paper",
                 w_p: float = 1.0, w_r: float = 180.0 / np.pi, bounds=None):
        if not isinstance(mechanism, SerialMechanism):
            raise FkoptError(f"ik_problem needs a serial arm; '{mechanism.name}' is {mechanism.kind} "
                             "(use fk_problem for a parallel mechanism)")
        pose = mechanism.as_values(pose, mechanism.pose_names, "target pose")   # serial arms: 6 values
        if objective not in IK_OBJECTIVES:
            raise FkoptError(f"objective '{objective}' unknown; allowed: {', '.join(IK_OBJECTIVES)}")
        for key, w in (("w_p", w_p), ("w_r", w_r)):
            if not (np.isfinite(w) and w >= 0):
                raise FkoptError(f"{key} must be a finite weight >= 0, got {w}")
        if w_p == 0 and w_r == 0:
            raise FkoptError("w_p and w_r cannot both be 0")
        reach = getattr(mechanism, "reach", None)
        distance = float(np.sqrt(pose[0] ** 2 + pose[1] ** 2 + pose[2] ** 2))
        if reach is not None and distance > reach * (1.0 + 1e-12):
            unit = mechanism.pose_units[0]
            raise FkoptError(f"{mechanism.name} target ({pose[0]:g}, {pose[1]:g}, {pose[2]:g}) unreachable "
                             f"(distance {distance:.1f} {unit} > reach {reach:.1f} {unit})")
        a, b, g = wrap_degrees(pose[3:])
        if b < 0:
            a, b, g = wrap_degrees(a + 180.0), -b, wrap_degrees(g + 180.0)
        self.mechanism = mechanism
        self.target = np.array([*pose[:3], a, b, g])
        self.objective = objective
        self.w_p, self.w_r = float(w_p), float(w_r)
        self.variable_names = mechanism.joint_names
        self.variable_units = mechanism.joint_units
        self.bounds = mechanism.bounds if bounds is None else np.asarray(bounds, dtype=float)
        self._euler_target = np.radians(self.target[3:])
        self._R_target = rotations.zyz(*self._euler_target)
        self.has_jacobian = hasattr(mechanism, "frame_jacobian")

    # -- pieces ------------------------------------------------------------------------------
    def _frame(self, x):
        """(p, R) of the candidates: the mechanism's own frame when it has one, else from fk."""
        if hasattr(self.mechanism, "frame"):
            return self.mechanism.frame(x)
        pose = self.mechanism.fk(x)
        return (pose[..., 0], pose[..., 1], pose[..., 2]), rotations.zyz(*np.radians(np.moveaxis(pose[..., 3:], -1, 0)))

    def _position_diff(self, p):
        return tuple(p[i] - self.target[i] for i in range(3))

    def _euler_diff(self, R):
        """Wrapped Z-Y-Z Euler differences in radians."""
        euler = rotations.zyz_angles(R)
        return tuple((euler[i] - self._euler_target[i] + np.pi) % (2.0 * np.pi) - np.pi for i in range(3))

    # -- problem interface -------------------------------------------------------------------
    def residuals(self, x) -> np.ndarray:
        p, R = self._frame(x)
        dp = self._position_diff(p)
        e = self._euler_diff(R) if self.objective == "paper" else rotations.rotation_vector(self._R_target, R)
        return np.stack([self.w_p * dp[0], self.w_p * dp[1], self.w_p * dp[2],
                         self.w_r * e[0], self.w_r * e[1], self.w_r * e[2]], axis=-1)

    def jacobian(self, x) -> np.ndarray:
        """d(residuals)/d(joints) (..., 6, n) from the arm's frame Jacobian (``frame_jacobian``).

        Position rows: w_p dp/dq. Orientation rows: paper objective, w_r times the Z-Y-Z
        Euler rates (:meth:`DHArm.euler_rates`, infinite at sin(beta) = 0); geodesic, w_r times
        d log(R_t^T R) = J_r^{-1}(e) R^T omega with the inverse right Jacobian of SO(3)
        J_r^{-1}(e) = I + [e]x / 2 + (1/theta^2 - (1 + cos theta) / (2 theta sin theta)) [e]x^2.
        """
        if not hasattr(self.mechanism, "frame_jacobian"):
            raise NotImplementedError
        x = np.asarray(x, dtype=float)
        _, R, J = self.mechanism.frame_jacobian(x)
        out = np.empty(J.shape)
        out[..., :3, :] = self.w_p * J[..., :3, :]
        if self.objective == "paper":
            out[..., 3:, :] = self.w_r * self.mechanism.euler_rates(R, J[..., 3:, :])
            return out
        body = np.swapaxes(R, -1, -2) @ J[..., 3:, :]               # R^T omega
        Rs = tuple(tuple(R[..., i, j] for j in range(3)) for i in range(3))
        e = np.stack(rotations.rotation_vector(self._R_target, Rs), axis=-1)
        out[..., 3:, :] = self.w_r * (so3_right_jacobian_inverse(e) @ body)
        return out

    def fitness(self, x) -> np.ndarray:
        p, R = self._frame(x)
        dP = _norm3(*self._position_diff(p))
        if self.objective == "paper":
            dR = _norm3(*self._euler_diff(R))
        else:
            dR = rotations.geodesic_angle(self._R_target, R)
        return self.w_p * dP + self.w_r * dR

    # -- reports -----------------------------------------------------------------------------
    def position_error(self, x) -> np.ndarray:
        """Distance from the tool point to the target position (length unit of the arm)."""
        p, _ = self._frame(x)
        return _norm3(*self._position_diff(p))

    def rotation_error(self, x, kind: str | None = None) -> np.ndarray:
        """Orientation error in degrees: Euler-difference norm (``"paper"``) or geodesic angle
        (``"geodesic"``); default the problem's own objective."""
        kind = kind or self.objective
        if kind not in IK_OBJECTIVES:
            raise FkoptError(f"rotation error kind '{kind}' unknown; allowed: {', '.join(IK_OBJECTIVES)}")
        _, R = self._frame(x)
        if kind == "paper":
            return np.degrees(_norm3(*self._euler_diff(R)))
        return np.degrees(rotations.geodesic_angle(self._R_target, R))


def ik_problem(mechanism: Mechanism, pose, objective: Literal["paper", "geodesic"] = "paper",
               w_p: float = 1.0, w_r: float = 180.0 / np.pi, **kwargs) -> IKProblem:
    """Pair a serial arm with a target pose (x, y, z, alpha, beta, gamma: Z-Y-Z Euler in deg)."""
    return IKProblem(mechanism, pose, objective=objective, w_p=w_p, w_r=w_r, **kwargs)
