"""A serial chain as arrays, the form every frame arm reduces to (DH tables, URDF chains, MJCF
bodies), and its FK and frame Jacobian of one configuration on Python floats.

The recursion (as :meth:`fkopt.mechanisms.urdf.URDFArm._walk`): the carried frame F_i has
joint i's axis as its z column, F_i = F_{i-1} C_i Rz(q_i) for a revolute joint, origin
p_i = p_{i-1} + F_{i-1} v_i (+ q_i z for a prismatic joint), with the constant rotation C_i and
offset v_i folding every fixed transform since the previous joint; a tail (C, v) after the last
joint carries fixed joints and the tool. Joint i moves with q_i = mult_i t[var_i] + off_i
(internal units: rad, length unit): a mimic joint follows its master, a DH theta offset is off.
The geometric Jacobian column of unknown k sums, over the joints that follow it, mult times
(z x (p - o), z) for a revolute joint with world axis z through o, (z, 0) for a prismatic one
(Siciliano et al., Robotics, 2009, eq. 3.30).

A DH row (theta, d, a, alpha) is Rz(theta) Tz(d) Tx(a) Rx(alpha): joint i+1 gets
v = (a_i, 0, d_i), C = Rx(alpha_i), joint 1 none, the tail the last row's; the sums below then
perform the DH recursion's operations in its order (a zero term adds an exact zero), so both give
the same numbers.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Chain:
    """Constants of a serial chain (m moving joints, n unknowns); see the module docstring.

    ``prismatic`` (m,) bool; ``C`` (m, 3, 3), ``v`` (m, 3); ``var`` (m,) unknown index;
    ``mult``, ``off`` (m,); ``tail_C`` (3, 3), ``tail_v`` (3,); ``dof`` = n.
    """

    prismatic: np.ndarray
    C: np.ndarray
    v: np.ndarray
    var: np.ndarray
    mult: np.ndarray
    off: np.ndarray
    tail_C: np.ndarray
    tail_v: np.ndarray
    dof: int

    def arrays(self) -> tuple:
        """The constants in the order the compiled kernels take them (contiguous, typed)."""
        got = self.__dict__.get("_arrays")
        if got is None:
            got = (np.ascontiguousarray(self.prismatic, dtype=np.bool_), np.ascontiguousarray(self.C, dtype=float),
                   np.ascontiguousarray(self.v, dtype=float), np.ascontiguousarray(self.var, dtype=np.int64),
                   np.ascontiguousarray(self.mult, dtype=float), np.ascontiguousarray(self.off, dtype=float),
                   np.ascontiguousarray(self.tail_C, dtype=float), np.ascontiguousarray(self.tail_v, dtype=float))
            object.__setattr__(self, "_arrays", got)
        return got

    def lists(self) -> tuple:
        """The constants as Python lists (the float reference :func:`frame_jacobian1` reads them)."""
        got = self.__dict__.get("_lists")
        if got is None:
            got = (self.prismatic.tolist(), self.C.tolist(), self.v.tolist(), self.var.tolist(),
                   self.mult.tolist(), self.off.tolist(), self.tail_C.tolist(), self.tail_v.tolist())
            object.__setattr__(self, "_lists", got)
        return got


def from_terms(joints, tail, dof: int) -> Chain:
    """A :class:`Chain` from the sparse constants of :class:`fkopt.mechanisms.urdf.URDFArm`:
    per joint (prismatic, terms, v, var, mult, off) with ``terms`` the non-zero entries of C by
    column ((row, value), ...), and the tail (terms, v)."""
    def dense(terms):
        C = np.zeros((3, 3))
        for c, col in enumerate(terms):
            for r, val in col:
                C[r, c] = val
        return C
    m = len(joints)
    return Chain(prismatic=np.array([j[0] for j in joints], dtype=bool),
                 C=np.array([dense(j[1]) for j in joints]).reshape(m, 3, 3),
                 v=np.array([j[2] for j in joints], dtype=float).reshape(m, 3),
                 var=np.array([j[3] for j in joints], dtype=np.int64),
                 mult=np.array([j[4] for j in joints], dtype=float), off=np.array([j[5] for j in joints], dtype=float),
                 tail_C=dense(tail[0]), tail_v=np.array(tail[1], dtype=float), dof=int(dof))


def from_dh(a, d, ca, sa, offset_rad) -> Chain:
    """A :class:`Chain` of a standard DH table (revolute joints; see the module docstring)."""
    n = len(a)

    def rx(c, s):
        return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    C = np.array([np.eye(3)] + [rx(ca[i], sa[i]) for i in range(n - 1)])
    v = np.array([[0.0, 0.0, 0.0]] + [[a[i], 0.0, d[i]] for i in range(n - 1)])
    return Chain(prismatic=np.zeros(n, dtype=bool), C=C, v=v, var=np.arange(n, dtype=np.int64),
                 mult=np.ones(n), off=np.array(offset_rad, dtype=float), tail_C=rx(ca[-1], sa[-1]),
                 tail_v=np.array([a[-1], 0.0, d[-1]]), dof=n)


def frame_jacobian1(chain: Chain, t) -> tuple[list[float], list[list[float]], list[list[float]]]:
    """Tip position (3), rotation (3 rows of 3) and frame Jacobian (6 rows of n, per internal
    unit) of one configuration ``t`` (n floats, internal units) on Python floats: the reference
    the compiled kernel (:func:`fkopt.numerics.compiled.frame_jacobian`) is held to."""
    prismatic, C, v, var, mult, off, tC, tv = chain.lists()
    x0, x1, x2, y0, y1, y2, z0, z1, z2 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
    p0 = p1 = p2 = 0.0
    n = chain.dof
    J = [[0.0] * n for _ in range(6)]
    axes = []
    for i in range(len(prismatic)):
        q = t[var[i]] * mult[i] + off[i]
        (c00, c01, c02), (c10, c11, c12), (c20, c21, c22) = C[i]
        v0, v1, v2 = v[i]
        p0, p1, p2 = p0 + (x0 * v0 + y0 * v1 + z0 * v2), p1 + (x1 * v0 + y1 * v1 + z1 * v2), \
            p2 + (x2 * v0 + y2 * v1 + z2 * v2)
        x0, x1, x2, y0, y1, y2, z0, z1, z2 = (
            x0 * c00 + y0 * c10 + z0 * c20, x1 * c00 + y1 * c10 + z1 * c20, x2 * c00 + y2 * c10 + z2 * c20,
            x0 * c01 + y0 * c11 + z0 * c21, x1 * c01 + y1 * c11 + z1 * c21, x2 * c01 + y2 * c11 + z2 * c21,
            x0 * c02 + y0 * c12 + z0 * c22, x1 * c02 + y1 * c12 + z1 * c22, x2 * c02 + y2 * c12 + z2 * c22)
        axes.append((z0, z1, z2, p0, p1, p2))
        if prismatic[i]:
            p0, p1, p2 = p0 + z0 * q, p1 + z1 * q, p2 + z2 * q
        else:
            c, s = math.cos(q), math.sin(q)
            x0, x1, x2, y0, y1, y2 = (x0 * c + y0 * s, x1 * c + y1 * s, x2 * c + y2 * s,
                                      y0 * c - x0 * s, y1 * c - x1 * s, y2 * c - x2 * s)
    (c00, c01, c02), (c10, c11, c12), (c20, c21, c22) = tC
    v0, v1, v2 = tv
    p0, p1, p2 = p0 + (x0 * v0 + y0 * v1 + z0 * v2), p1 + (x1 * v0 + y1 * v1 + z1 * v2), \
        p2 + (x2 * v0 + y2 * v1 + z2 * v2)
    x0, x1, x2, y0, y1, y2, z0, z1, z2 = (
        x0 * c00 + y0 * c10 + z0 * c20, x1 * c00 + y1 * c10 + z1 * c20, x2 * c00 + y2 * c10 + z2 * c20,
        x0 * c01 + y0 * c11 + z0 * c21, x1 * c01 + y1 * c11 + z1 * c21, x2 * c01 + y2 * c11 + z2 * c21,
        x0 * c02 + y0 * c12 + z0 * c22, x1 * c02 + y1 * c12 + z1 * c22, x2 * c02 + y2 * c12 + z2 * c22)
    for i, (a0, a1, a2, o0, o1, o2) in enumerate(axes):
        k, w = var[i], mult[i]
        if prismatic[i]:
            col = (a0, a1, a2, 0.0, 0.0, 0.0)
        else:
            d0, d1, d2 = p0 - o0, p1 - o1, p2 - o2
            col = (a1 * d2 - a2 * d1, a2 * d0 - a0 * d2, a0 * d1 - a1 * d0, a0, a1, a2)
        for r in range(6):
            J[r][k] += col[r] * w
    return [p0, p1, p2], [[x0, y0, z0], [x1, y1, z1], [x2, y2, z2]], J
