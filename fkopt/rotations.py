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

    mao2017 eq. (2) and liu2008; SPEC.md "Rotation matrix used by mao2017 and liu2008".
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
