"""Serial arms from a standard Denavit-Hartenberg table; the 7-DOF arm of wang7dof.

docs/models.md "wang7dof" (7-DOF redundant arm, inverse kinematics by ABC vs PSO). Standard DH:
T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i), theta_i = q_i + theta_offset_i, and the
end-effector frame T = T_1 T_2 ... T_n = [n o a p]. The pose is (x, y, z) = p in the length
unit of the table (mm) and the Z-Y-Z Euler angles printed by wang7dof, in degrees:

    beta = atan2(sqrt(n_z^2 + o_z^2), a_z),  alpha = atan2(a_y, a_x),  gamma = atan2(o_z, -n_z),

so beta is in [0, 180] and the angles are singular at sin(beta) = 0 (see
:func:`fkopt.numerics.rotations.zyz_angles`); :meth:`DHArm.frame` gives the rotation matrix itself for
the geodesic error of :class:`fkopt.problems.IKProblem`.

``dh-arm`` takes any table as geometry (``a``, ``alpha`` [deg], ``d``, ``theta_offset`` [deg],
``limits`` [[lo, hi] deg per joint]); without overrides it is wang7dof's table, which the preset
``7dof-arm`` fixes: a = (0, 200, 250, 300, 200, 200, 100) mm, alpha = (-90, 90, -90, 90, -90,
0, 0) deg (printed as "rad" but they are degrees), d = (500, 0, 0, 0, 0, 0, 50) mm, limits
(-180, 180), (-90, 30), (-90, 120), (-90, 90) x 3, (-30, 90) (the last printed "900", a typo).
Products are written elementwise (no matmul), so results are bit-identical for any batch shape.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from fkopt.errors import FkoptError
from fkopt.mechanisms.base import FrameArm, geometry_base, lazy_model, validate_geometry
from fkopt.numerics.chain import from_dh

#: Batch size from which :meth:`DHArm.frame_jacobian` works on the frame's columns rather than
#: by batched 4x4 products (those cost about 1 µs per matrix, the columns a fixed ~20 array
#: operations per joint).
_COLUMNS_MIN = 64

WANG7DOF = dict(
    a=[0.0, 200.0, 250.0, 300.0, 200.0, 200.0, 100.0],
    alpha=[-90.0, 90.0, -90.0, 90.0, -90.0, 0.0, 0.0],
    d=[500.0, 0.0, 0.0, 0.0, 0.0, 0.0, 50.0],
    limits=[(-180.0, 180.0), (-90.0, 30.0), (-90.0, 120.0), (-90.0, 90.0), (-90.0, 90.0),
            (-90.0, 90.0), (-30.0, 90.0)],
)


def _dh_geometry():
    from pydantic import Field, model_validator

    class DHGeometry(geometry_base()):
        a: list[float] = Field(default_factory=lambda: list(WANG7DOF["a"]),
                               description="link lengths a_i (mm)")
        alpha: list[float] = Field(default_factory=lambda: list(WANG7DOF["alpha"]),
                                   description="link twists alpha_i (deg)")
        d: list[float] = Field(default_factory=lambda: list(WANG7DOF["d"]), description="link offsets d_i (mm)")
        theta_offset: list[float] | None = Field(None, description="joint angle offsets (deg), default 0")
        limits: list[tuple[float, float]] = Field(default_factory=lambda: list(WANG7DOF["limits"]),
                                                  description="joint limits [lower, upper] per joint (deg)")

        @model_validator(mode="after")
        def _consistent(self):
            n = len(self.a)
            if n < 1:
                raise ValueError("the DH table needs at least 1 joint (a is empty)")
            lengths = {"a": n, "alpha": len(self.alpha), "d": len(self.d), "limits": len(self.limits)}
            if self.theta_offset is not None:
                lengths["theta_offset"] = len(self.theta_offset)
            if len(set(lengths.values())) > 1:
                raise ValueError("DH table columns must have equal lengths, got "
                                 + ", ".join(f"{k}={v}" for k, v in lengths.items()))
            for i, (lo, hi) in enumerate(self.limits):
                if not lo < hi:
                    raise ValueError(f"limits[{i}] (joint q{i + 1}): lower {lo:g} must be below upper {hi:g}")
            values = [*self.a, *self.alpha, *self.d, *(self.theta_offset or []),
                      *(v for pair in self.limits for v in pair)]
            if not np.all(np.isfinite(values)):
                raise ValueError("DH table values must be finite")
            return self

    DHGeometry.__module__ = __name__
    return DHGeometry


def __getattr__(name: str):
    if name == "DHGeometry":                           # built on first use (pydantic)
        return DHArm.Geometry
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class DHArm(FrameArm):
    """Serial arm with revolute joints q1..qn (deg) described by a standard DH table."""

    name = "dh-arm"
    blas_free_fitness = True   # elementwise map (module docstring): no BLAS on the fitness path
    pose_units = ("mm", "mm", "mm", "deg", "deg", "deg")
    Geometry = lazy_model(_dh_geometry)                # pydantic model, built on first use
    geometry_defaults = {"a": list(WANG7DOF["a"]), "alpha": list(WANG7DOF["alpha"]), "d": list(WANG7DOF["d"]),
                         "theta_offset": None, "limits": list(WANG7DOF["limits"])}
    # Class-level values describe the default (wang7dof) table; each instance sets its own.
    joint_names = tuple(f"q{i + 1}" for i in range(len(WANG7DOF["a"])))
    joint_units = ("deg",) * len(WANG7DOF["a"])
    default_bounds = dict(zip(joint_names, WANG7DOF["limits"]))

    def __init__(self, bounds: dict[str, Any] | None = None, **geometry: Any):
        # The joint names and default bounds depend on the table: validate it first, then set
        # them on the instance before the base class builds the bounds from joint_names.
        if geometry:
            table = validate_geometry(self.Geometry, geometry, self.name, lambda m: m.replace("Value error, ", ""))
        else:                                          # the default table: valid, no pydantic needed
            table = self.geometry_values()
        n = len(table.a)
        self.joint_names = tuple(f"q{i + 1}" for i in range(n))
        self.joint_units = ("deg",) * n
        self.default_bounds = {f"q{i + 1}": tuple(lim) for i, lim in enumerate(table.limits)}
        super().__init__(bounds, **geometry)
        g = self.geometry_values()
        self._a = tuple(float(v) for v in g.a)
        self._d = tuple(float(v) for v in g.d)
        self._ca = tuple(float(np.cos(np.radians(v))) for v in g.alpha)
        self._sa = tuple(float(np.sin(np.radians(v))) for v in g.alpha)
        self._offset = tuple(float(v) for v in (g.theta_offset or [0.0] * n))
        self._offset_rad = tuple(math.radians(v) for v in self._offset)

    @property
    def reach(self) -> float:
        """Upper bound of the distance from the base origin to the tool point: sum sqrt(a^2 + d^2)."""
        return float(sum(np.hypot(a, d) for a, d in zip(self._a, self._d)))

    def frame(self, joints):
        """End-effector frame as (p, R): p = (px, py, pz) and R a :data:`rotations.Matrix`
        (nested tuples of arrays shaped like the batch), computed elementwise."""
        joints = np.asarray(joints, dtype=float)
        if joints.shape[-1] != self.dof:
            raise FkoptError(f"{self.name} joints: expected {self.dof} values "
                             f"({', '.join(self.joint_names)}), got shape {joints.shape}")
        R = None
        p = None
        for i in range(self.dof):
            t = np.radians(joints[..., i] + self._offset[i])
            ct, st = np.cos(t), np.sin(t)
            ca, sa, a, d = self._ca[i], self._sa[i], self._a[i], self._d[i]
            # A_i = Rz(t) Tz(d) Tx(a) Rx(alpha)
            Ai = ((ct, -st * ca, st * sa), (st, ct * ca, -ct * sa), (0.0, sa, ca))
            pi = (a * ct, a * st, d)
            if R is None:
                R = tuple(tuple(np.broadcast_to(v, ct.shape) * 1.0 for v in row) for row in Ai)
                p = tuple(np.broadcast_to(v, ct.shape) * 1.0 for v in pi)
                continue
            p = tuple(R[r][0] * pi[0] + R[r][1] * pi[1] + R[r][2] * pi[2] + p[r] for r in range(3))
            R = tuple(tuple(R[r][0] * Ai[0][c] + R[r][1] * Ai[1][c] + R[r][2] * Ai[2][c]
                            for c in range(3)) for r in range(3))
        return p, R

    def frame_jacobian(self, joints) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """End-effector position (..., 3), rotation (..., 3, 3) and frame Jacobian (..., 6, n).

        Rows 0-2 of the Jacobian are d(position)/dq (length unit per degree), rows 3-5 the
        angular velocity in the base frame per degree of joint motion (rad/deg): column i is
        (z_{i-1} x (p - p_{i-1}), z_{i-1}) * pi/180, z_{i-1} and p_{i-1} the axis and origin of
        joint i (standard DH: the frame before T_i). The Z-Y-Z Euler angles of the pose are
        singular at sin(beta) = 0, so the frame (angular velocity) is the well-defined derivative;
        :meth:`euler_rates` turns it into Euler-angle rates away from the singularity.
        Batched 4x4 products (one matmul per joint) for small batches, elementwise on the
        frame's columns from ``_COLUMNS_MIN`` rows on (see :meth:`_frame_jacobian_columns`).
        """
        q = np.asarray(joints, dtype=float)
        if q.shape[-1] != self.dof:
            raise FkoptError(f"{self.name} joints: expected {self.dof} values "
                             f"({', '.join(self.joint_names)}), got shape {q.shape}")
        shape = q.shape[:-1]
        n = self.dof
        t = np.radians(q.reshape(-1, n) + self._offset)
        if len(t) >= _COLUMNS_MIN:
            p, R, J = self._frame_jacobian_columns(t)
            return p.reshape(shape + (3,)), R.reshape(shape + (3, 3)), J.reshape(shape + (6, n))
        # A_i = C0_i + cos(t_i) C1_i + sin(t_i) C2_i (constant 4x4 parts of the DH transform)
        C0, C1, C2 = self._dh_parts()
        A = C0 + np.cos(t)[..., None, None] * C1 + np.sin(t)[..., None, None] * C2
        Ts = np.empty(t.shape + (4, 4))                            # frame before joint i+1 ... after
        Ts[:, 0] = A[:, 0]
        for i in range(1, n):
            np.matmul(Ts[:, i - 1], A[:, i], out=Ts[:, i])
        T = Ts[:, -1]
        p, R = T[:, :3, 3], T[:, :3, :3]
        J = np.empty((len(t), 6, n))
        # joint i's axis z_{i-1} and origin o_{i-1}: base frame for i = 0, else frame i-1
        zx, zy, zz = np.empty((len(t), n)), np.empty((len(t), n)), np.empty((len(t), n))
        zx[:, 0], zy[:, 0], zz[:, 0] = 0.0, 0.0, 1.0
        zx[:, 1:], zy[:, 1:], zz[:, 1:] = Ts[:, :-1, 0, 2], Ts[:, :-1, 1, 2], Ts[:, :-1, 2, 2]
        dx, dy, dz = np.empty((len(t), n)), np.empty((len(t), n)), np.empty((len(t), n))
        dx[:, 0], dy[:, 0], dz[:, 0] = p[:, 0], p[:, 1], p[:, 2]
        dx[:, 1:] = p[:, 0, None] - Ts[:, :-1, 0, 3]
        dy[:, 1:] = p[:, 1, None] - Ts[:, :-1, 1, 3]
        dz[:, 1:] = p[:, 2, None] - Ts[:, :-1, 2, 3]
        J[:, 0] = zy * dz - zz * dy
        J[:, 1] = zz * dx - zx * dz
        J[:, 2] = zx * dy - zy * dx
        J[:, 3], J[:, 4], J[:, 5] = zx, zy, zz
        J *= np.pi / 180.0
        return p.reshape(shape + (3,)), R.reshape(shape + (3, 3)), J.reshape(shape + (6, n))

    def frame_jacobian1(self, t) -> tuple[list[float], list[list[float]], list[list[float]]]:
        """:meth:`frame_jacobian` of one configuration on Python floats, joint angles ``t`` in
        **radians** (n floats, offsets added here): position (3), rotation (3 rows of 3) and
        the frame Jacobian per **radian** (6 rows of n), the recursion of
        :meth:`_frame_jacobian_columns`. For one configuration numpy's per-call overhead is
        most of the cost; ``fkopt.inverse`` on one pose uses this."""
        x0, x1, x2, y0, y1, y2, z0, z1, z2 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
        p0 = p1 = p2 = 0.0
        axes, origins = [], []
        for ti, off, ca, sa, a, d in zip(t, self._offset_rad, self._ca, self._sa, self._a, self._d):
            c, s_ = math.cos(ti + off), math.sin(ti + off)
            axes.append((z0, z1, z2))
            origins.append((p0, p1, p2))
            u0, u1, u2 = x0 * c + y0 * s_, x1 * c + y1 * s_, x2 * c + y2 * s_
            v0, v1, v2 = y0 * c - x0 * s_, y1 * c - x1 * s_, y2 * c - x2 * s_
            p0, p1, p2 = p0 + (u0 * a + z0 * d), p1 + (u1 * a + z1 * d), p2 + (u2 * a + z2 * d)
            x0, x1, x2 = u0, u1, u2
            y0, y1, y2, z0, z1, z2 = (v0 * ca + z0 * sa, v1 * ca + z1 * sa, v2 * ca + z2 * sa,
                                      z0 * ca - v0 * sa, z1 * ca - v1 * sa, z2 * ca - v2 * sa)
        J = [[], [], [], [], [], []]
        for (a0, a1, a2), (o0, o1, o2) in zip(axes, origins):
            d0, d1, d2 = p0 - o0, p1 - o1, p2 - o2
            J[0].append(a1 * d2 - a2 * d1)
            J[1].append(a2 * d0 - a0 * d2)
            J[2].append(a0 * d1 - a1 * d0)
            J[3].append(a0)
            J[4].append(a1)
            J[5].append(a2)
        return [p0, p1, p2], [[x0, y0, z0], [x1, y1, z1], [x2, y2, z2]], J

    def _dh_parts(self):
        """Constant (n, 4, 4) parts C0, C1, C2 with A_i = C0 + cos(theta) C1 + sin(theta) C2."""
        if getattr(self, "_parts", None) is None:
            n = self.dof
            C0, C1, C2 = np.zeros((n, 4, 4)), np.zeros((n, 4, 4)), np.zeros((n, 4, 4))
            for i in range(n):
                ca, sa, a, d = self._ca[i], self._sa[i], self._a[i], self._d[i]
                C0[i, 2, 1], C0[i, 2, 2], C0[i, 2, 3], C0[i, 3, 3] = sa, ca, d, 1.0
                C1[i, 0, 0], C1[i, 1, 1], C1[i, 1, 2], C1[i, 0, 3] = 1.0, ca, -sa, a
                C2[i, 1, 0], C2[i, 0, 1], C2[i, 0, 2], C2[i, 1, 3] = 1.0, -ca, sa, a
            self._parts = (C0, C1, C2)
        return self._parts

    def _frame_jacobian_columns(self, t):
        """:meth:`frame_jacobian` of rows (k, n) of joint angles in radians, elementwise on the
        frame's columns as (3, k) arrays: with x, y, z the columns of R before joint i,
        u = c x + s y, v = c y - s x, the frame after it has columns (u, ca v + sa z,
        ca z - sa v) and origin p + a u + d z. About 20 array operations per joint whatever k
        (4x4 products of tiny matrices cost about 1 µs each in numpy)."""
        k, n = t.shape
        tt = t.T
        C, S = np.cos(tt), np.sin(tt)
        Z = np.empty((3, n, k))                 # joint axes z_{i-1}
        O = np.empty((3, n, k))                 # joint origins p_{i-1}
        x = np.zeros((3, k))
        y = np.zeros((3, k))
        z = np.zeros((3, k))
        x[0], y[1], z[2] = 1.0, 1.0, 1.0
        p = np.zeros((3, k))
        for i in range(n):
            c, s_ = C[i], S[i]
            ca, sa, a, d = self._ca[i], self._sa[i], self._a[i], self._d[i]
            Z[:, i] = z
            O[:, i] = p
            u = x * c + y * s_
            v = y * c - x * s_
            p = p + (u * a + z * d)
            x, y, z = u, v * ca + z * sa, z * ca - v * sa
        D = p[:, None, :] - O
        J = np.empty((6, n, k))
        J[0] = Z[1] * D[2] - Z[2] * D[1]
        J[1] = Z[2] * D[0] - Z[0] * D[2]
        J[2] = Z[0] * D[1] - Z[1] * D[0]
        J[3:] = Z
        J *= np.pi / 180.0
        R = np.stack([x, y, z], axis=-1)        # (3 rows, k, 3 columns)
        return (np.ascontiguousarray(p.T), np.ascontiguousarray(R.transpose(1, 0, 2)),
                np.ascontiguousarray(J.transpose(2, 0, 1)))

    def chain(self):
        """The DH table as a :class:`fkopt.numerics.chain.Chain` (same numbers as :meth:`frame_jacobian1`)."""
        got = self.__dict__.get("_chain_arrays")
        if got is None:
            got = self.__dict__["_chain_arrays"] = from_dh(self._a, self._d, self._ca, self._sa, self._offset_rad)
        return got

    def kinematic_key(self) -> tuple:
        """The DH table's numbers (no pydantic model needed)."""
        return (self.name, self._a, self._d, self._ca, self._sa, self._offset)


class SevenDofArm(DHArm):
    """The 7-DOF redundant arm of wang7dof (docs/models.md "wang7dof"); the table can still be overridden."""

    name = "7dof-arm"
    paper = "wang7dof"
