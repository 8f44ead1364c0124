"""Rotation helpers, vectorised over any leading batch shape, angles in radians.

Matrices are returned as nested tuples of arrays (structure of arrays, ``R[i][j]``) rather than
(..., 3, 3) stacks: elementwise products avoid BLAS, so results are bit-identical whatever the
batch size (a matmul may reorder its sums by batch size) and are faster for small 3x3 maps.
"""
from __future__ import annotations

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
