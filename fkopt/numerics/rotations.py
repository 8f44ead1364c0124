"""fkopt's one rotation module: every rotation helper of the library, once.

* Structure of arrays (the mechanisms' and problems' batched maps): matrices as nested tuples of
  arrays (``R[i][j]``) rather than (..., 3, 3) stacks: elementwise products avoid BLAS, so results
  are bit-identical whatever the batch size (a matmul may reorder its sums by batch size) and are
  faster for small 3x3 maps. Angles in radians.
* Stacked rows (``*_rows``): (k, 3, 3) arrays for the batched solvers (``fkopt.inverse``'s
  targets and residual, ``all_solutions``' 6-SPS states).
* One rotation on Python floats (``*1``): the one-pose paths and file readers, no numpy call
  per element. Their compiled twins (numba) are in :mod:`fkopt.numerics.compiled`'s rotation
  section, operation for operation.
"""
from __future__ import annotations

import math

import numpy as np

Matrix = tuple[tuple[np.ndarray, np.ndarray, np.ndarray], ...]


def zyx(alpha, beta, gamma) -> Matrix:
    """R = Rz(gamma) Ry(beta) Rx(alpha) (Z-Y-X Euler, active, right-handed).

    mao2017 eq. (2) and liu2008; docs/models.md "Rotation matrix used by mao2017 and liu2008".
    """
    ca, sa = np.cos(alpha), np.sin(alpha)
    cb, sb = np.cos(beta), np.sin(beta)
    cg, sg = np.cos(gamma), np.sin(gamma)
    return (
        (cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa),
        (sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa),
        (-sb, cb * sa, cb * ca),
    )


def apply(R: Matrix, v) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """R @ v for a constant or batched vector v = (vx, vy, vz)."""
    vx, vy, vz = v
    return tuple(R[i][0] * vx + R[i][1] * vy + R[i][2] * vz for i in range(3))


def to_array(R: Matrix) -> np.ndarray:
    """Stack a structure-of-arrays matrix into a (..., 3, 3) array."""
    rows = [np.stack(np.broadcast_arrays(*row), axis=-1) for row in R]
    return np.stack(rows, axis=-2)


def wrap_degrees(d):
    """Map angle differences in degrees to [-180, 180): 179 - (-179) is -2, not 358."""
    return (np.asarray(d) + 180.0) % 360.0 - 180.0


def zyz(alpha, beta, gamma) -> Matrix:
    """R = Rz(alpha) Ry(beta) Rz(gamma) (Z-Y-Z Euler, active, right-handed), angles in radians.

    The orientation convention of wang7dof (docs/models.md "wang7dof"); :func:`zyz_angles` inverts it.
    """
    ca, sa = np.cos(alpha), np.sin(alpha)
    cb, sb = np.cos(beta), np.sin(beta)
    cg, sg = np.cos(gamma), np.sin(gamma)
    return (
        (ca * cb * cg - sa * sg, -ca * cb * sg - sa * cg, ca * sb),
        (sa * cb * cg + ca * sg, -sa * cb * sg + ca * cg, sa * sb),
        (-sb * cg, sb * sg, cb),
    )


def zyz_angles(R: Matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Z-Y-Z Euler angles (alpha, beta, gamma) in radians of R = [n o a], as wang7dof prints them:

    beta = atan2(sqrt(n_z^2 + o_z^2), a_z) in [0, pi], alpha = atan2(a_y, a_x),
    gamma = atan2(o_z, -n_z). Singular at sin(beta) = 0, where alpha and gamma are atan2 of
    rounding noise (only alpha + gamma, or alpha - gamma, is defined there).
    """
    nz, oz = R[2][0], R[2][1]
    beta = np.arctan2(np.sqrt(nz * nz + oz * oz), R[2][2])
    alpha = np.arctan2(R[1][2], R[0][2])
    gamma = np.arctan2(oz, -nz)
    return alpha, beta, gamma


def quaternion_matrix(w, x, y, z) -> Matrix:
    """R of the unit quaternion w + xi + yj + zk (Hamilton convention, active; the convention of
    URDF tools, ROS' geometry_msgs/Quaternion and pinocchio's Quaternion(w, x, y, z)); the
    quaternion is normalised first. Shoemake, "Animating rotation with quaternion curves",
    SIGGRAPH 1985, eq. for Rot(q)."""
    n = np.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return (
        (1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
        (2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
        (2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)),
    )


def relative_quaternion(Ra: Matrix, Rb: Matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Unit quaternion (w, x, y, z), w >= 0, of the relative rotation M = Ra^T Rb.

    Shepperd's method (branch on the largest of 4w^2, 4x^2, 4y^2, 4z^2, chosen per element with
    ``np.where``), so it is accurate for every angle including pi; elementwise, no matmul.
    """
    M = [[sum(Ra[k][i] * Rb[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    t0 = 1.0 + M[0][0] + M[1][1] + M[2][2]
    t1 = 1.0 + M[0][0] - M[1][1] - M[2][2]
    t2 = 1.0 - M[0][0] + M[1][1] - M[2][2]
    t3 = 1.0 - M[0][0] - M[1][1] + M[2][2]
    s21, s02, s10 = M[2][1] - M[1][2], M[0][2] - M[2][0], M[1][0] - M[0][1]
    p01, p02, p12 = M[0][1] + M[1][0], M[0][2] + M[2][0], M[1][2] + M[2][1]
    big = np.argmax(np.stack(np.broadcast_arrays(t0, t1, t2, t3)), axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        r0, r1, r2, r3 = (np.sqrt(np.maximum(t, 0.0)) for t in (t0, t1, t2, t3))
        # case k: the k-th component is r_k / 2, the others are (pair sums) / (2 r_k)
        cand = [
            (0.5 * r0, s21 / (2 * r0), s02 / (2 * r0), s10 / (2 * r0)),
            (s21 / (2 * r1), 0.5 * r1, p01 / (2 * r1), p02 / (2 * r1)),
            (s02 / (2 * r2), p01 / (2 * r2), 0.5 * r2, p12 / (2 * r2)),
            (s10 / (2 * r3), p02 / (2 * r3), p12 / (2 * r3), 0.5 * r3),
        ]
    q = [np.choose(big, [c[m] for c in cand]) for m in range(4)]
    sign = np.where(q[0] < 0, -1.0, 1.0)
    return tuple(sign * c for c in q)


def geodesic_angle(Ra: Matrix, Rb: Matrix) -> np.ndarray:
    """Rotation angle in [0, pi] radians of Ra^T Rb (the geodesic distance on SO(3)).

    2 atan2(|v|, w) of the relative quaternion: accurate near 0 and near pi, where
    acos((trace - 1) / 2) loses half the digits.
    """
    w, x, y, z = relative_quaternion(Ra, Rb)
    return 2.0 * np.arctan2(np.sqrt(x * x + y * y + z * z), w)


def rotation_vector(Ra: Matrix, Rb: Matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Axis * angle (radians) of Ra^T Rb; its norm is :func:`geodesic_angle`."""
    w, x, y, z = relative_quaternion(Ra, Rb)
    s = np.sqrt(x * x + y * y + z * z)
    angle = 2.0 * np.arctan2(s, w)
    with np.errstate(divide="ignore", invalid="ignore"):
        # small angles: angle / s -> 2 / w (w ~ 1), avoiding 0/0
        k = np.where(s > 1e-12, angle / s, 2.0 / w)
    return k * x, k * y, k * z


# ----------------------------------------------------------------------------------------------
# Stacked rotations: (k, 3, 3) arrays, rows of a batch side by side
# ----------------------------------------------------------------------------------------------
def zyz_rows(euler_deg: np.ndarray) -> np.ndarray:
    """(k, 3, 3) matrices of Z-Y-Z Euler angles (k, 3) in degrees (the formulas of :func:`zyz`):
    ``fkopt.inverse``'s target rotations."""
    a, b, g = np.radians(euler_deg).T
    ca, sa, cb, sb, cg, sg = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(g), np.sin(g)
    R = np.empty((len(a), 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 0, 2] = ca * cb * cg - sa * sg, -ca * cb * sg - sa * cg, ca * sb
    R[:, 1, 0], R[:, 1, 1], R[:, 1, 2] = sa * cb * cg + ca * sg, -sa * cb * sg + ca * cg, sa * sb
    R[:, 2, 0], R[:, 2, 1], R[:, 2, 2] = -sb * cg, sb * sg, cb
    return R


def zyx_rows(a, b, g) -> np.ndarray:
    """(k, 3, 3) Z-Y-X Euler matrices, angles in radians (the formulas of :func:`zyx`)."""
    ca, sa, cb, sb, cg, sg = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(g), np.sin(g)
    return np.stack([
        np.stack([cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa], -1),
        np.stack([sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa], -1),
        np.stack([-sb, cb * sa, cb * ca], -1)], -2)


def zyx_angles_rows(R: np.ndarray) -> np.ndarray:
    """Z-Y-X Euler angles (k, 3) in degrees, beta in [-90, 90], of (k, 3, 3) rotation matrices."""
    beta = np.arctan2(-R[:, 2, 0], np.hypot(R[:, 0, 0], R[:, 1, 0]))
    alpha = np.arctan2(R[:, 2, 1], R[:, 2, 2])
    gamma = np.arctan2(R[:, 1, 0], R[:, 0, 0])
    return np.degrees(np.stack([alpha, beta, gamma], -1))


def unit_quaternion_rows(w, x, y, z) -> np.ndarray:
    """(k, 3, 3) matrices of unit quaternions (Hamilton, active; as :func:`quaternion_matrix`
    without its normalisation: the quaternions are unit already)."""
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], -2)


def rotate_rows(w: np.ndarray, R: np.ndarray) -> np.ndarray:
    """exp([w]x) R for rotation vectors w (k, 3) and row-major matrices R (k, 9), elementwise
    (Rodrigues: exp([w]x) = I + a [w]x + b [w]x^2 with [w]x^2 = w w^T - |w|^2 I)."""
    w0, w1, w2 = w[:, 0], w[:, 1], w[:, 2]
    th2 = w0 * w0 + w1 * w1 + w2 * w2
    small = th2 < 1e-8
    th = np.sqrt(np.where(small, 1.0, th2))
    a = np.where(small, 1.0 - th2 / 6.0, np.sin(th) / th)
    b = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(th)) / (th * th))
    d = 1.0 - b * th2
    bw0, bw1, bw2 = b * w0, b * w1, b * w2
    aw0, aw1, aw2 = a * w0, a * w1, a * w2
    E = ((bw0 * w0 + d, bw0 * w1 - aw2, bw0 * w2 + aw1),
         (bw1 * w0 + aw2, bw1 * w1 + d, bw1 * w2 - aw0),
         (bw2 * w0 - aw1, bw2 * w1 + aw0, bw2 * w2 + d))
    out = np.empty((len(w), 9))
    for k in range(3):
        for j in range(3):
            out[:, 3 * k + j] = E[k][0] * R[:, j] + E[k][1] * R[:, 3 + j] + E[k][2] * R[:, 6 + j]
    return out


def rotation_error_rows(R: np.ndarray, Rt: np.ndarray) -> np.ndarray:
    """Rotation vectors (k, 3) of R Rt^T (base frame), angle in [0, pi] radians, for (k, 3, 3)
    stacks: ``fkopt.inverse``'s orientation residual (:func:`rotation_error1` row by row)."""
    M = R @ np.swapaxes(Rt, -1, -2)
    v = np.stack([M[:, 2, 1] - M[:, 1, 2], M[:, 0, 2] - M[:, 2, 0], M[:, 1, 0] - M[:, 0, 1]], axis=-1)
    s = 0.5 * np.sqrt(np.einsum("...i,...i->...", v, v))          # sin(angle)
    c = 0.5 * (M[:, 0, 0] + M[:, 1, 1] + M[:, 2, 2] - 1.0)         # cos(angle)
    angle = np.arctan2(s, c)
    k = np.where(s > 1e-12, angle / np.where(s > 1e-12, 2.0 * s, 1.0), 0.5)
    e = v * k[:, None]
    half = (s <= 1e-12) & (c <= 0.0)        # a half turn: its axis from the symmetric part (half_turn)
    for i in np.flatnonzero(half):
        e[i] = half_turn(M[i, 0, 0], M[i, 1, 1], M[i, 2, 2], 0.5 * (M[i, 0, 1] + M[i, 1, 0]),
                         0.5 * (M[i, 0, 2] + M[i, 2, 0]), 0.5 * (M[i, 1, 2] + M[i, 2, 1]))
    return e


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


# ----------------------------------------------------------------------------------------------
# One rotation on Python floats (the one-pose paths: a few µs, no numpy call)
# ----------------------------------------------------------------------------------------------
def zyz1(a: float, b: float, g: float) -> list[list[float]]:
    """:func:`zyz_rows` of one triple of Euler angles (deg) on Python floats (the same formulas)."""
    a, b, g = math.radians(a), math.radians(b), math.radians(g)
    ca, sa, cb, sb, cg, sg = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(g), math.sin(g)
    return [[ca * cb * cg - sa * sg, -ca * cb * sg - sa * cg, ca * sb],
            [sa * cb * cg + ca * sg, -sa * cb * sg + ca * cg, sa * sb],
            [-sb * cg, sb * sg, cb]]


def zyx1(alpha: float, beta: float, gamma: float) -> np.ndarray:
    """R = Rz(gamma) Ry(beta) Rx(alpha) (3, 3) of one triple (radians) on Python floats: URDF's
    fixed-axis roll-pitch-yaw (roll = alpha, pitch = beta, yaw = gamma); :func:`zyx`'s formulas."""
    cr, sr, cp, sp, cy, sy = (math.cos(alpha), math.sin(alpha), math.cos(beta), math.sin(beta),
                              math.cos(gamma), math.sin(gamma))
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def zyx_angles1(R: np.ndarray) -> tuple[float, float, float]:
    """URDF's roll, pitch, yaw (radians) of one rotation (3, 3) with |pitch| away from 90 deg."""
    return (math.atan2(R[2, 1], R[2, 2]), math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0])),
            math.atan2(R[1, 0], R[0, 0]))


def ry1(angle: float) -> np.ndarray:
    """Rotation (3, 3) by ``angle`` (rad) about y."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rz1(angle: float) -> np.ndarray:
    """Rotation (3, 3) by ``angle`` (rad) about z."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def axis_angle1(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation (3, 3) by ``angle`` (rad) about the unit ``axis`` (Rodrigues)."""
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def mujoco_quaternion1(q) -> np.ndarray:
    """Rotation (3, 3) of a unit quaternion (w, x, y, z) in MuJoCo's formulas (``mju_quat2Mat``:
    squares on the diagonal, not 1 - 2(...), so the bits are MuJoCo's)."""
    w, x, y, z = (float(v) for v in q)
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


def quaternion_xyzw1(R) -> tuple[float, float, float, float]:
    """Unit quaternion (x, y, z, w) of a rotation matrix by Shepperd's method (Shepperd, J.
    Guidance and Control 1(3), 1978): the largest of w, x, y, z taken from the diagonal, the others
    from the off-diagonal sums, so no division by a small number."""
    (a, b, c), (d, e, f), (g, h, i) = R[0][:3], R[1][:3], R[2][:3]
    tr = a + e + i
    if tr >= a and tr >= e and tr >= i:
        w = 0.5 * math.sqrt(max(0.0, 1.0 + tr))
        s = 0.25 / w
        return (h - f) * s, (c - g) * s, (d - b) * s, w
    if a >= e and a >= i:
        x = 0.5 * math.sqrt(max(0.0, 1.0 + a - e - i))
        s = 0.25 / x
        return x, (b + d) * s, (c + g) * s, (h - f) * s
    if e >= i:
        y = 0.5 * math.sqrt(max(0.0, 1.0 - a + e - i))
        s = 0.25 / y
        return (b + d) * s, y, (f + h) * s, (c - g) * s
    z = 0.5 * math.sqrt(max(0.0, 1.0 - a - e + i))
    s = 0.25 / z
    return (c + g) * s, (f + h) * s, z, (d - b) * s


def rotation_error1(R, T):
    """Rotation vector of R T^T (base frame, angle in [0, pi]) for rotations given as 3 rows of
    3 floats (:func:`rotation_error_rows` of one row; compiled twin
    ``fkopt.numerics.compiled._rotation_error``, operation for operation)."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R
    (t00, t01, t02), (t10, t11, t12), (t20, t21, t22) = T
    v0 = (r20 * t10 + r21 * t11 + r22 * t12) - (r10 * t20 + r11 * t21 + r12 * t22)
    v1 = (r00 * t20 + r01 * t21 + r02 * t22) - (r20 * t00 + r21 * t01 + r22 * t02)
    v2 = (r10 * t00 + r11 * t01 + r12 * t02) - (r00 * t10 + r01 * t11 + r02 * t12)
    s = 0.5 * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    c = 0.5 * ((r00 * t00 + r01 * t01 + r02 * t02) + (r10 * t10 + r11 * t11 + r12 * t12)
               + (r20 * t20 + r21 * t21 + r22 * t22) - 1.0)
    if s > 1e-12 or c > 0.0:
        k = math.atan2(s, c) / (2.0 * s) if s > 1e-12 else 0.5
        return v0 * k, v1 * k, v2 * k
    return half_turn(r00 * t00 + r01 * t01 + r02 * t02, r10 * t10 + r11 * t11 + r12 * t12,
                     r20 * t20 + r21 * t21 + r22 * t22, r00 * t10 + r01 * t11 + r02 * t12,
                     r00 * t20 + r01 * t21 + r02 * t22, r10 * t20 + r11 * t21 + r12 * t22)


def half_turn(m00, m11, m22, m01, m02, m12):
    """Rotation vector of a half turn M = R T^T = 2 a a^T - I (sin = 0, cos = -1), where the
    antisymmetric part that gives the axis elsewhere vanishes: pi times the axis read from the
    symmetric part (a_i^2 = (M_ii + 1) / 2 from the largest diagonal, a_j = M_ij / (2 a_i)). Without
    it the error vector of an answer a half turn off was zero, and such an answer counted as solved."""
    if m00 >= m11 and m00 >= m22:
        a0 = math.sqrt(max(0.5 * (m00 + 1.0), 0.0))
        a1, a2 = m01 / (2.0 * a0), m02 / (2.0 * a0)
    elif m11 >= m22:
        a1 = math.sqrt(max(0.5 * (m11 + 1.0), 0.0))
        a0, a2 = m01 / (2.0 * a1), m12 / (2.0 * a1)
    else:
        a2 = math.sqrt(max(0.5 * (m22 + 1.0), 0.0))
        a0, a1 = m02 / (2.0 * a2), m12 / (2.0 * a2)
    return math.pi * a0, math.pi * a1, math.pi * a2
