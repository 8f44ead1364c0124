"""Problems: a mechanism paired with what was measured, as a bounded minimisation.

A problem exposes ``dim``, ``bounds`` (dim, 2), ``variable_names``, ``residuals(x[..., dim])``
and ``fitness(x[..., dim]) -> [...]``, all vectorised over any leading batch shape, and knows
nothing of algorithms. Algorithms see only this interface.

Case axis. A problem built from several targets (``fk_problem(m, joints)`` with joints
(cases, m), ``ik_problem(arm, poses)`` with poses (cases, 6)) has ``cases`` = their number
(``None`` for one target). Its ``fitness``/``residuals`` take points (cases, ..., dim): the
first axis selects the target, the other leading axes broadcast as before. ``take(index)``
returns the problem of the targets ``index`` (repeats allowed) -- :func:`fkopt.solve` uses it
to give every row of a batch (case x run) its own target, so algorithms see an ordinary
problem whose first axis happens to be per row.
"""
from __future__ import annotations

import copy
from typing import Literal

import numpy as np

from fkopt.errors import FkoptError
from fkopt.numerics import rotations
from fkopt.mechanisms.base import Mechanism, ParallelMechanism, SerialMechanism
from fkopt.numerics.rotations import so3_right_jacobian_inverse, wrap_degrees

#: Version of the fitness definitions below (residuals, objectives, the IK pose error and its
#: weights). Every released kinbench version records the one it was ranked with
#: (:mod:`fkopt.kinbench.releases`); a change that alters any fitness value is a new number here
#: and a new kinbench version, said in CHANGES.md (tests/test_releases.py holds fitness values of
#: each released problem, so an unannounced change fails).
FITNESS_VERSION = 1

#: Objectives built from residuals r: "squared" = sum r_i^2 (mao2017 eq. 12, wu2015, chang2024),
#: "absolute" = sum |r_i| (liu2008 as printed).
OBJECTIVES = ("squared", "absolute")


def _row_sum(a: np.ndarray) -> np.ndarray:
    """``a.sum(axis=-1)``, the same numbers: for fewer than 8 terms numpy adds them left to right,
    and so do these column additions -- about 7x faster than numpy's reduction over a short last
    axis (measured on (1000, 10, 3))."""
    m = a.shape[-1]
    if m < 2 or m >= 8:
        return a.sum(axis=-1)
    out = a[..., 0] + a[..., 1]
    for j in range(2, m):
        out += a[..., j]
    return out


class Problem:
    """Bounded minimisation of ``fitness`` over ``dim`` variables."""

    variable_names: tuple[str, ...]
    variable_units: tuple[str, ...]
    bounds: np.ndarray
    #: Number of targets along the first axis of the points, or None for a single target.
    cases: int | None = None
    #: Names of the per-case target arrays (first axis = case), for :meth:`take`.
    _case_arrays: tuple[str, ...] = ()

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
    def take(self, index) -> "Problem":
        """The problem of targets ``index`` (a batched problem, even for one index)."""
        if self.cases is None:
            raise FkoptError(f"{type(self).__name__} has a single target (no case axis to take from)")
        index = np.asarray(index, dtype=np.intp)
        out = copy.copy(self)
        for name in self._case_arrays:
            setattr(out, name, getattr(self, name)[index])
        out.cases = len(index)
        out._shapes = {}
        return out

    def repeat(self, n: int) -> "Problem":
        """A single-target problem as a batched one of ``n`` copies of its target (the inverse
        of :meth:`case`); a batched problem is returned unchanged."""
        if self.cases is not None:
            return self
        out = copy.copy(self)
        for name in self._case_arrays:
            a = np.asarray(getattr(self, name))
            setattr(out, name, np.broadcast_to(a, (int(n),) + a.shape).copy())
        out.cases = int(n)
        out._shapes = {}
        return out

    def case(self, i: int) -> "Problem":
        """Target ``i`` as a single-target problem (today's shapes)."""
        if self.cases is None:
            raise FkoptError(f"{type(self).__name__} has a single target (no case axis)")
        out = self.take([i])
        for name in self._case_arrays:
            setattr(out, name, getattr(out, name)[0])
        out.cases = None
        return out

    def _along(self, a: np.ndarray, ndim: int) -> np.ndarray:
        """Per-case array ``a`` (cases, *k) shaped to broadcast against a batch of ``ndim`` axes
        (the case axis first): (cases, 1, ..., 1, *k). Unchanged for a single target."""
        if self.cases is None:
            return a
        key = (id(a), ndim)
        out = self._shapes.get(key)
        if out is None:
            out = self._shapes[key] = a.reshape((a.shape[0],) + (1,) * (ndim - 1) + a.shape[1:])
        return out

    def _check_cases(self, x: np.ndarray) -> None:
        if self.cases is not None and (x.ndim < 2 or x.shape[0] != self.cases):
            raise FkoptError(f"{type(self).__name__} with {self.cases} cases needs points shaped "
                             f"(cases, ..., {self.dim}), got {x.shape}")


def _targets(mechanism: Mechanism, values, names: tuple[str, ...], what: str) -> tuple[np.ndarray, int | None]:
    """One target (values by name or in order) or a stack (cases, len(names)); (array, cases)."""
    if not isinstance(values, dict):
        arr = np.asarray(values, dtype=float)
        if arr.ndim == 2:
            if arr.shape[0] < 1 or arr.shape[1] != len(names):
                raise FkoptError(f"{mechanism.name} {what}: expected (cases, {len(names)}) values "
                                 f"({', '.join(names)}), got shape {arr.shape}")
            if not np.all(np.isfinite(arr)):
                row = int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])
                raise FkoptError(f"{mechanism.name} {what}: values must be finite, case {row} is "
                                 f"{arr[row].tolist()}")
            return arr, arr.shape[0]
    return mechanism.as_values(values, names, what), None


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
        joints, self.cases = _targets(mechanism, joints, mechanism.joint_names, "joints")
        self._case_arrays = ("joints",)
        self._shapes = {}
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
        self._angle_idx = np.flatnonzero(self._angle)

    def residuals(self, x) -> np.ndarray:
        if self.cases is None:
            r = self.mechanism.ik(x) - self.joints
        else:
            x = np.asarray(x, dtype=float)
            self._check_cases(x)
            r = self.mechanism.ik(x) - self._along(self.joints, x.ndim - 1)
        if self._angle.all():
            r = wrap_degrees(r)
        elif self._angle.any():   # wrap only the angle columns (the same numbers, less work)
            r[..., self._angle_idx] = wrap_degrees(r[..., self._angle_idx])
        return r

    def jacobian(self, x) -> np.ndarray:
        """d(residuals)/d(pose) (..., m, dim) = the mechanism's analytic ``jacobian`` (the
        wrap of angle-valued joints has derivative 1 wherever it is continuous)."""
        if not hasattr(self.mechanism, "jacobian"):
            raise NotImplementedError
        return self.mechanism.jacobian(x)

    def fitness(self, x) -> np.ndarray:
        columns = getattr(self.mechanism, "ik_columns", None)
        m = len(self._angle)
        if columns is None or m >= 8:
            r = self.residuals(x)
            return _row_sum(np.abs(r) if self.objective == "absolute" else r * r)
        # The same operations on the residuals as rows (m, n): contiguous arrays, fewer passes.
        x = np.asarray(x, dtype=float)
        if self.cases is not None:
            self._check_cases(x)
        lead = x.shape[:-1]
        compiled = getattr(self.mechanism, "compiled_fitness", None)
        if compiled is not None and not self._angle_idx.size:   # FKOPT_NUMERICS=compiled only
            got = compiled(x.reshape(-1, x.shape[-1]), self._joint_rows(lead), self.objective == "absolute")
            if got is not None:
                return got.reshape(lead)
        r = columns(x)
        np.subtract(r, self._joint_rows(lead), out=r)
        if self._angle_idx.size:
            r[self._angle_idx] = wrap_degrees(r[self._angle_idx])
        if self.objective == "absolute":
            np.abs(r, out=r)
        else:
            np.multiply(r, r, out=r)
        if m == 1:
            return r[0].reshape(lead)
        out = np.add(r[0], r[1])
        for k in range(2, m):
            out += r[k]
        return out.reshape(lead)

    def _joint_rows(self, lead: tuple[int, ...]) -> np.ndarray:
        """The target joints against the residual rows of points shaped ``lead``: (m, 1) for one
        target; (m, n) for a case axis, each case's joints repeated over its points (cached)."""
        if self.cases is None:
            return self.joints[:, None]
        key = ("rows", lead)
        rows = self._shapes.get(key)
        if rows is None:
            stale = [k for k in self._shapes if k[0] == "rows"]
            if len(stale) >= 4:                          # a few shapes at a time (memory stays bounded)
                for k in stale:
                    del self._shapes[k]
            per_case = int(np.prod(lead[1:], dtype=np.int64))
            rows = self._shapes[key] = np.repeat(self.joints.T, per_case, axis=1)
        return rows


def fk_problem(mechanism: Mechanism, joints, **kwargs) -> FKProblem:
    """Pair a parallel mechanism with measured joint values (dict by name or array (m,)), or
    with several sets of them (array (cases, m)): a problem with a case axis."""
    return FKProblem(mechanism, joints, **kwargs)


#: Orientation errors of :class:`IKProblem`: "paper" = Euclidean norm of the wrapped Z-Y-Z Euler
#: differences (wang7dof), "geodesic" = rotation angle of R_target^T R.
IK_OBJECTIVES = ("paper", "geodesic")


def _norm3(a, b, c):
    return np.sqrt(a * a + b * b + c * c)


class IKProblem(Problem):
    """Inverse kinematics of a serial arm: find joints whose end-effector pose is ``pose``.

    docs/models.md "wang7dof": fitness f = w_p * dP + w_r * dR, dP the distance between the tool
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
        pose, self.cases = _targets(mechanism, pose, mechanism.pose_names, "target pose")   # serial arms: 6 values
        self._case_arrays = ("target", "_euler_target", "_R_target")
        self._shapes = {}
        if objective not in IK_OBJECTIVES:
            raise FkoptError(f"objective '{objective}' unknown; allowed: {', '.join(IK_OBJECTIVES)}")
        for key, w in (("w_p", w_p), ("w_r", w_r)):
            if not (np.isfinite(w) and w >= 0):
                raise FkoptError(f"{key} must be a finite weight >= 0, got {w}")
        if w_p == 0 and w_r == 0:
            raise FkoptError("w_p and w_r cannot both be 0")
        reach = getattr(mechanism, "reach", None)
        for i, row in enumerate(np.atleast_2d(pose)):
            distance = float(np.sqrt(row[0] ** 2 + row[1] ** 2 + row[2] ** 2))
            if reach is not None and distance > reach * (1.0 + 1e-12):
                unit = mechanism.pose_units[0]
                which = "" if self.cases is None else f" (case {i})"
                raise FkoptError(f"{mechanism.name} target ({row[0]:g}, {row[1]:g}, {row[2]:g}){which} unreachable "
                                 f"(distance {distance:.1f} {unit} > reach {reach:.1f} {unit})")
        a, b, g = wrap_degrees(np.moveaxis(pose[..., 3:], -1, 0))
        flip = b < 0
        a, b, g = (np.where(flip, wrap_degrees(a + 180.0), a), np.where(flip, -b, b),
                   np.where(flip, wrap_degrees(g + 180.0), g))
        self.mechanism = mechanism
        self.target = np.concatenate([pose[..., :3], np.stack([a, b, g], axis=-1)], axis=-1)
        self.objective = objective
        self.w_p, self.w_r = float(w_p), float(w_r)
        self.variable_names = mechanism.joint_names
        self.variable_units = mechanism.joint_units
        self.bounds = mechanism.bounds if bounds is None else np.asarray(bounds, dtype=float)
        self._euler_target = np.radians(self.target[..., 3:])
        R = rotations.zyz(*np.moveaxis(self._euler_target, -1, 0))
        # (3, 3) per target; rotations take nested tuples, see _rotation_target
        self._R_target = np.array([[np.asarray(v, dtype=float) for v in row] for row in R])
        if self.cases is not None:
            self._R_target = np.moveaxis(self._R_target, -1, 0)      # (cases, 3, 3)
        self.has_jacobian = hasattr(mechanism, "frame_jacobian")

    def _rotation_target(self, ndim: int):
        """R_target as the nested tuples :mod:`fkopt.numerics.rotations` works on, broadcastable."""
        R = self._along(self._R_target, ndim)
        return tuple(tuple(R[..., r, c] for c in range(3)) for r in range(3))

    # -- pieces ------------------------------------------------------------------------------
    def _frame(self, x):
        """(p, R) of the candidates: the mechanism's own frame when it has one, else from fk."""
        if hasattr(self.mechanism, "frame"):
            return self.mechanism.frame(x)
        pose = self.mechanism.fk(x)
        return (pose[..., 0], pose[..., 1], pose[..., 2]), rotations.zyz(*np.radians(np.moveaxis(pose[..., 3:], -1, 0)))

    def _position_diff(self, p):
        t = self._along(self.target, np.ndim(p[0]))
        return tuple(p[i] - t[..., i] for i in range(3))

    def _euler_diff(self, R):
        """Wrapped Z-Y-Z Euler differences in radians."""
        euler = rotations.zyz_angles(R)
        t = self._along(self._euler_target, np.ndim(euler[0]))
        return tuple((euler[i] - t[..., i] + np.pi) % (2.0 * np.pi) - np.pi for i in range(3))

    # -- problem interface -------------------------------------------------------------------
    def residuals(self, x) -> np.ndarray:
        p, R = self._frame(self._points(x))
        dp = self._position_diff(p)
        e = (self._euler_diff(R) if self.objective == "paper"
             else rotations.rotation_vector(self._rotation_target(np.ndim(p[0])), R))
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
        x = self._points(np.asarray(x, dtype=float))
        _, R, J = self.mechanism.frame_jacobian(x)
        out = np.empty(J.shape)
        out[..., :3, :] = self.w_p * J[..., :3, :]
        if self.objective == "paper":
            out[..., 3:, :] = self.w_r * self.mechanism.euler_rates(R, J[..., 3:, :])
            return out
        body = np.swapaxes(R, -1, -2) @ J[..., 3:, :]               # R^T omega
        Rs = tuple(tuple(R[..., i, j] for j in range(3)) for i in range(3))
        e = np.stack(rotations.rotation_vector(self._rotation_target(x.ndim - 1), Rs), axis=-1)
        out[..., 3:, :] = self.w_r * (so3_right_jacobian_inverse(e) @ body)
        return out

    def _points(self, x):
        if self.cases is None:
            return x
        x = np.asarray(x, dtype=float)
        self._check_cases(x)
        return x

    def fitness(self, x) -> np.ndarray:
        p, R = self._frame(self._points(x))
        dP = _norm3(*self._position_diff(p))
        if self.objective == "paper":
            dR = _norm3(*self._euler_diff(R))
        else:
            dR = rotations.geodesic_angle(self._rotation_target(np.ndim(p[0])), R)
        return self.w_p * dP + self.w_r * dR

    # -- reports -----------------------------------------------------------------------------
    def position_error(self, x) -> np.ndarray:
        """Distance from the tool point to the target position (length unit of the arm)."""
        p, _ = self._frame(self._points(x))
        return _norm3(*self._position_diff(p))

    def rotation_error(self, x, kind: str | None = None) -> np.ndarray:
        """Orientation error in degrees: Euler-difference norm (``"paper"``) or geodesic angle
        (``"geodesic"``); default the problem's own objective."""
        kind = kind or self.objective
        if kind not in IK_OBJECTIVES:
            raise FkoptError(f"rotation error kind '{kind}' unknown; allowed: {', '.join(IK_OBJECTIVES)}")
        _, R = self._frame(self._points(x))
        if kind == "paper":
            return np.degrees(_norm3(*self._euler_diff(R)))
        return np.degrees(rotations.geodesic_angle(self._rotation_target(np.ndim(R[0][0])), R))


def ik_problem(mechanism: Mechanism, pose, objective: Literal["paper", "geodesic"] = "paper",
               w_p: float = 1.0, w_r: float = 180.0 / np.pi, **kwargs) -> IKProblem:
    """Pair a serial arm with a target pose (x, y, z, alpha, beta, gamma: Z-Y-Z Euler in deg),
    or with several (array (cases, 6)): a problem with a case axis."""
    return IKProblem(mechanism, pose, objective=objective, w_p=w_p, w_r=w_r, **kwargs)


class BoxedProblem(Problem):
    """``problem`` searched in one box per case, through the unit box: the variables y in
    [0, 1]^dim map to x = lo_c + y (hi_c - lo_c) for case c.

    Algorithms take one box (dim, 2) for a whole batch; this lets rows of one batch search
    different boxes -- tracking's swarm around each run's previous solution. ``to_x(y)`` maps
    answers back. Width-relative settings (PSO's ``v_max_fraction``, LM's ``jac_step`` and
    ``tol``, ACO's steps) mean the same in both coordinates; absolute ones (PSO ``v_max``) do not.
    """

    def __init__(self, problem: Problem, lo, hi):
        lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
        cases = problem.cases
        if cases is None or lo.shape != (cases, problem.dim) or hi.shape != lo.shape:
            raise FkoptError(f"BoxedProblem needs a problem with cases and boxes (cases, {problem.dim})")
        if not np.all(hi > lo):
            raise FkoptError("BoxedProblem: every box needs hi > lo")
        self.problem = problem
        self.lo, self.width = lo, hi - lo
        self.cases = cases
        self._case_arrays = ("lo", "width")
        self._shapes = {}
        self.variable_names = problem.variable_names
        self.variable_units = ("1",) * problem.dim
        self.bounds = np.array([[0.0, 1.0]] * problem.dim)

    def take(self, index) -> "BoxedProblem":
        out = super().take(index)
        out.problem = self.problem.take(index)
        return out

    def to_x(self, y) -> np.ndarray:
        """Points y (cases, ..., dim) in the unit box as points of the problem."""
        y = np.asarray(y, dtype=float)
        self._check_cases(y)
        return self._along(self.lo, y.ndim - 1) + y * self._along(self.width, y.ndim - 1)

    def fitness(self, y) -> np.ndarray:
        return self.problem.fitness(self.to_x(y))

    def residuals(self, y) -> np.ndarray:
        return self.problem.residuals(self.to_x(y))
