"""The compiled fast path: :mod:`fkopt.numerics.chain` and :mod:`fkopt.numerics.damped_least_squares` compiled by
numba, operation for operation in the reference's order (numba compiles without fast-math, so no
reassociation or fused multiply-add; ``cos``, ``sin``, ``atan2`` and ``sqrt`` are the C library's,
as Python's ``math``). Importing this module imports numba, which costs a noticeable part of a
second; :mod:`fkopt.numerics.path` imports it only when a compiled kernel is first asked for.

Compiled code is cached on disk (``cache=True``, through :func:`fkopt.numerics.jit.njit`: an
unreadable cache file is set aside and rebuilt, an unwritable folder only costs the cache): in the
``__pycache__`` folder beside this file, or, when that is not writable, numba's user-wide cache
(``~/.cache/numba`` style; ``NUMBA_CACHE_DIR`` overrides both). The first call after installing
compiles (tens of seconds for all kernels, docs/performance.md); later processes load the cache.

* :func:`frame_jacobian` -- FK and frame Jacobian of one configuration of a chain;
* :func:`rps3_fitness`, :func:`pso_rps3`, :func:`abc_rps3` -- the 3-RPS swarm fitness and the PSO
  and ABC/GABC iterations on it (the default path; numpy's own ``np.tan`` between a move and a
  finish kernel, so the numpy path's bits: :func:`numpy_tan`). These compile with
  ``error_model="numpy"``: a float division by zero gives numpy's inf/NaN instead of a Python
  exception, so no check guards each division (half of the fitness' time, measured: 57 -> 29 ns
  per point); the values are the same wherever the divisor is not zero;
* :func:`_rotation_error`, :func:`_rotation_target`, :func:`_geodesic` -- the compiled twins of
  :mod:`fkopt.numerics.rotations`' one-rotation helpers (``rotation_error1``, ``zyz1``);
* :func:`_evaluate`, :func:`_dls_step` -- the residual and the damped least-squares step of
  :mod:`fkopt.numerics.damped_least_squares`; the one-pose restart loop built on them is
  :mod:`fkopt.numerics.compiled_ik`, the all-solutions and path kernels :mod:`fkopt.numerics.compiled_branches`;
* :func:`fill_uniforms` -- the refill of :class:`fkopt.numerics.streams.RunStreams`' buffer, every run in one
  call: numpy's PCG64 and ``next_double`` on the runs' states in one array (``Generator.random``'s bits);
"""
from __future__ import annotations

import math
import threading

import numpy as np
from numba import types               # numba first: without it, the ImportError names numba (not llvmlite)
from numba.core.extending import intrinsic
from llvmlite import ir

from fkopt.numerics.jit import njit                 # numba.njit with a cache that a corrupted file cannot break

_M1 = np.uint64(0x9E3779B97F4A7C15)
_M2 = np.uint64(0xBF58476D1CE4E5B9)
_M3 = np.uint64(0x94D049BB133111EB)


@njit(cache=True)
def _walk(prismatic, C, v, var, mult, off, tC, tv, t, p, R, J, ax):
    """FK and Jacobian into p (3), R (3, 3) and J (6, n) (see :func:`fkopt.numerics.chain.frame_jacobian1`)."""
    x0, x1, x2, y0, y1, y2, z0, z1, z2 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
    p0 = 0.0
    p1 = 0.0
    p2 = 0.0
    m = prismatic.shape[0]
    for i in range(m):
        q = t[var[i]] * mult[i] + off[i]
        v0, v1, v2 = v[i, 0], v[i, 1], v[i, 2]
        p0, p1, p2 = (p0 + (x0 * v0 + y0 * v1 + z0 * v2), p1 + (x1 * v0 + y1 * v1 + z1 * v2),
                      p2 + (x2 * v0 + y2 * v1 + z2 * v2))
        c00, c01, c02 = C[i, 0, 0], C[i, 0, 1], C[i, 0, 2]
        c10, c11, c12 = C[i, 1, 0], C[i, 1, 1], C[i, 1, 2]
        c20, c21, c22 = C[i, 2, 0], C[i, 2, 1], C[i, 2, 2]
        x0, x1, x2, y0, y1, y2, z0, z1, z2 = (
            x0 * c00 + y0 * c10 + z0 * c20, x1 * c00 + y1 * c10 + z1 * c20, x2 * c00 + y2 * c10 + z2 * c20,
            x0 * c01 + y0 * c11 + z0 * c21, x1 * c01 + y1 * c11 + z1 * c21, x2 * c01 + y2 * c11 + z2 * c21,
            x0 * c02 + y0 * c12 + z0 * c22, x1 * c02 + y1 * c12 + z1 * c22, x2 * c02 + y2 * c12 + z2 * c22)
        ax[i, 0], ax[i, 1], ax[i, 2], ax[i, 3], ax[i, 4], ax[i, 5] = z0, z1, z2, p0, p1, p2
        if prismatic[i]:
            p0, p1, p2 = p0 + z0 * q, p1 + z1 * q, p2 + z2 * q
        else:
            c, s = math.cos(q), math.sin(q)
            x0, x1, x2, y0, y1, y2 = (x0 * c + y0 * s, x1 * c + y1 * s, x2 * c + y2 * s,
                                      y0 * c - x0 * s, y1 * c - x1 * s, y2 * c - x2 * s)
    v0, v1, v2 = tv[0], tv[1], tv[2]
    p0, p1, p2 = (p0 + (x0 * v0 + y0 * v1 + z0 * v2), p1 + (x1 * v0 + y1 * v1 + z1 * v2),
                  p2 + (x2 * v0 + y2 * v1 + z2 * v2))
    c00, c01, c02 = tC[0, 0], tC[0, 1], tC[0, 2]
    c10, c11, c12 = tC[1, 0], tC[1, 1], tC[1, 2]
    c20, c21, c22 = tC[2, 0], tC[2, 1], tC[2, 2]
    x0, x1, x2, y0, y1, y2, z0, z1, z2 = (
        x0 * c00 + y0 * c10 + z0 * c20, x1 * c00 + y1 * c10 + z1 * c20, x2 * c00 + y2 * c10 + z2 * c20,
        x0 * c01 + y0 * c11 + z0 * c21, x1 * c01 + y1 * c11 + z1 * c21, x2 * c01 + y2 * c11 + z2 * c21,
        x0 * c02 + y0 * c12 + z0 * c22, x1 * c02 + y1 * c12 + z1 * c22, x2 * c02 + y2 * c12 + z2 * c22)
    p[0], p[1], p[2] = p0, p1, p2
    R[0, 0], R[0, 1], R[0, 2] = x0, y0, z0
    R[1, 0], R[1, 1], R[1, 2] = x1, y1, z1
    R[2, 0], R[2, 1], R[2, 2] = x2, y2, z2
    J[:, :] = 0.0
    for i in range(m):
        a0, a1, a2 = ax[i, 0], ax[i, 1], ax[i, 2]
        k, w = var[i], mult[i]
        if prismatic[i]:
            J[0, k] += a0 * w
            J[1, k] += a1 * w
            J[2, k] += a2 * w
            J[3, k] += 0.0 * w
            J[4, k] += 0.0 * w
            J[5, k] += 0.0 * w
        else:
            d0, d1, d2 = p0 - ax[i, 3], p1 - ax[i, 4], p2 - ax[i, 5]
            J[0, k] += (a1 * d2 - a2 * d1) * w
            J[1, k] += (a2 * d0 - a0 * d2) * w
            J[2, k] += (a0 * d1 - a1 * d0) * w
            J[3, k] += a0 * w
            J[4, k] += a1 * w
            J[5, k] += a2 * w


@njit(cache=True)
def _frame_jacobian(prismatic, C, v, var, mult, off, tC, tv, t, n):
    p = np.empty(3)
    R = np.empty((3, 3))
    J = np.empty((6, n))
    ax = np.empty((prismatic.shape[0], 6))
    _walk(prismatic, C, v, var, mult, off, tC, tv, t, p, R, J, ax)
    return p, R, J


def frame_jacobian(chain, t):
    """(p (3,), R (3, 3), J (6, n)) of one configuration ``t`` (internal units) as arrays."""
    return _frame_jacobian(*chain.arrays(), np.ascontiguousarray(t, dtype=float), chain.dof)


@njit(cache=True)
def _frame_jacobian_rows(prismatic, C, v, var, mult, off, tC, tv, t, n):
    k = t.shape[0]
    P = np.empty((k, 3))
    R = np.empty((k, 3, 3))
    J = np.empty((k, 6, n))
    ax = np.empty((prismatic.shape[0], 6))
    for i in range(k):
        _walk(prismatic, C, v, var, mult, off, tC, tv, t[i], P[i], R[i], J[i], ax)
    return P, R, J


def frame_jacobian_rows(chain, t):
    """:func:`frame_jacobian` of rows t (k, n): (k, 3), (k, 3, 3), (k, 6, n)."""
    return _frame_jacobian_rows(*chain.arrays(), np.ascontiguousarray(t, dtype=float), chain.dof)


@njit(cache=True)
def _rotation_error(R, T, e):
    """:func:`fkopt.numerics.rotations.rotation_error1` into e, operation for operation."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = (R[0, 0], R[0, 1], R[0, 2], R[1, 0], R[1, 1], R[1, 2],
                                                   R[2, 0], R[2, 1], R[2, 2])
    t00, t01, t02, t10, t11, t12, t20, t21, t22 = (T[0, 0], T[0, 1], T[0, 2], T[1, 0], T[1, 1], T[1, 2],
                                                   T[2, 0], T[2, 1], T[2, 2])
    v0 = (r20 * t10 + r21 * t11 + r22 * t12) - (r10 * t20 + r11 * t21 + r12 * t22)
    v1 = (r00 * t20 + r01 * t21 + r02 * t22) - (r20 * t00 + r21 * t01 + r22 * t02)
    v2 = (r10 * t00 + r11 * t01 + r12 * t02) - (r00 * t10 + r01 * t11 + r02 * t12)
    s = 0.5 * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    c = 0.5 * ((r00 * t00 + r01 * t01 + r02 * t02) + (r10 * t10 + r11 * t11 + r12 * t12)
               + (r20 * t20 + r21 * t21 + r22 * t22) - 1.0)
    if s > 1e-12 or c > 0.0:
        k = math.atan2(s, c) / (2.0 * s) if s > 1e-12 else 0.5
        e[0], e[1], e[2] = v0 * k, v1 * k, v2 * k
    else:   # a half turn: fkopt.numerics.rotations.half_turn, operation for operation (written out here:
        # a call in this branch made the whole one-pose kernel ~5 % slower, measured)
        m00 = r00 * t00 + r01 * t01 + r02 * t02
        m11 = r10 * t10 + r11 * t11 + r12 * t12
        m22 = r20 * t20 + r21 * t21 + r22 * t22
        m01 = r00 * t10 + r01 * t11 + r02 * t12
        m02 = r00 * t20 + r01 * t21 + r02 * t22
        m12 = r10 * t20 + r11 * t21 + r12 * t22
        if m00 >= m11 and m00 >= m22:
            a0 = math.sqrt(max(0.5 * (m00 + 1.0), 0.0))
            a1, a2 = m01 / (2.0 * a0), m02 / (2.0 * a0)
        elif m11 >= m22:
            a1 = math.sqrt(max(0.5 * (m11 + 1.0), 0.0))
            a0, a2 = m01 / (2.0 * a1), m12 / (2.0 * a1)
        else:
            a2 = math.sqrt(max(0.5 * (m22 + 1.0), 0.0))
            a0, a1 = m02 / (2.0 * a2), m12 / (2.0 * a2)
        e[0], e[1], e[2] = math.pi * a0, math.pi * a1, math.pi * a2


@njit(cache=True)
def _geodesic(R, T):
    """The angle of R T^T in [0, pi] from both its skew part and its trace: the rotation vector
    of :func:`_rotation_error` is zero at exactly pi (its skew part
    vanishes there), so a turn by pi about the tool axis would pass a check on it."""
    v0 = (R[2, 0] * T[1, 0] + R[2, 1] * T[1, 1] + R[2, 2] * T[1, 2]) - (R[1, 0] * T[2, 0] + R[1, 1] * T[2, 1] + R[1, 2] * T[2, 2])
    v1 = (R[0, 0] * T[2, 0] + R[0, 1] * T[2, 1] + R[0, 2] * T[2, 2]) - (R[2, 0] * T[0, 0] + R[2, 1] * T[0, 1] + R[2, 2] * T[0, 2])
    v2 = (R[1, 0] * T[0, 0] + R[1, 1] * T[0, 1] + R[1, 2] * T[0, 2]) - (R[0, 0] * T[1, 0] + R[0, 1] * T[1, 1] + R[0, 2] * T[1, 2])
    c = 0.0
    for a in range(3):
        for b in range(3):
            c += R[a, b] * T[a, b]
    return math.atan2(0.5 * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2), 0.5 * (c - 1.0))


@njit(cache=True)
def _rotation_target(pose, T):
    """The target rotation of a pose row into T: ZYZ Euler angles in deg (6,) as
    :func:`fkopt.numerics.rotations.zyz1`, or a frame row (12,) row-major as given."""
    if pose.shape[0] == 12:
        for r in range(3):
            for c in range(3):
                T[r, c] = pose[3 + 3 * r + c]
    else:
        d2r = math.pi / 180.0
        a, b, g = pose[3] * d2r, pose[4] * d2r, pose[5] * d2r
        ca, sa, cb, sb, cg, sg = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(g), math.sin(g)
        T[0, 0], T[0, 1], T[0, 2] = ca * cb * cg - sa * sg, -ca * cb * sg - sa * cg, ca * sb
        T[1, 0], T[1, 1], T[1, 2] = sa * cb * cg + ca * sg, -sa * cb * sg + ca * cg, sa * sb
        T[2, 0], T[2, 1], T[2, 2] = -sb * cg, sb * sg, cb


@njit(inline="always")
def _cholesky_solve(J, r, A, L, y, x, d, free, masked):
    """The rest of :func:`_dls_step` once A = J J^T + mu I is built: Cholesky of A, x = A^{-1} (-r),
    d = J^T x (J's columns with free[i] False as zero when ``masked``)."""
    n = J.shape[1]
    for i in range(6):
        for j in range(i + 1):
            acc = 0.0
            for k in range(j):
                acc = L[i, k] * L[j, k] if k == 0 else acc + L[i, k] * L[j, k]
            acc = A[j, i] - acc
            if i == j:
                if not acc > 0.0:
                    return False
                L[i, i] = math.sqrt(acc)
            else:
                L[i, j] = acc / L[j, j]
    for i in range(6):
        acc = 0.0
        for k in range(i):
            acc = L[i, k] * y[k] if k == 0 else acc + L[i, k] * y[k]
        y[i] = (-r[i] - acc) / L[i, i]
    for i in range(5, -1, -1):
        acc = y[i]
        for k in range(i + 1, 6):
            acc = acc - L[k, i] * x[k]
        x[i] = acc / L[i, i]
    for i in range(6):
        if not math.isfinite(x[i]):
            return False
    if masked:
        for i in range(n):
            ji = J[0, i] if free[i] else 0.0
            acc = ji * x[0]
            for a in range(1, 6):
                acc = acc + (J[a, i] if free[i] else 0.0) * x[a]
            d[i] = acc
    else:
        for i in range(n):
            acc = J[0, i] * x[0]
            for a in range(1, 6):
                acc = acc + J[a, i] * x[a]
            d[i] = acc
    return True


@njit(cache=True)
def _dls_step(J, r, mu, free, d, A, L, y, x):
    """:func:`fkopt.numerics.damped_least_squares.dls_step` into d; J's columns with free[i] = False count as zero.
    Returns False when not positive definite or not finite."""
    n = J.shape[1]
    for a in range(6):
        for b in range(a, 6):
            acc = (J[a, 0] if free[0] else 0.0) * (J[b, 0] if free[0] else 0.0)
            for i in range(1, n):
                acc = acc + (J[a, i] if free[i] else 0.0) * (J[b, i] if free[i] else 0.0)
            A[a, b] = acc + mu if a == b else acc
    return _cholesky_solve(J, r, A, L, y, x, d, free, True)


@njit(cache=True)
def _dls_step_all(J, r, mu, free, d, A, L, y, x):
    """:func:`_dls_step` with every column free (``free`` is not read): the same operations
    without the masks (a free column's value is itself, so the bits are the same)."""
    n = J.shape[1]
    for a in range(6):
        for b in range(a, 6):
            acc = J[a, 0] * J[b, 0]
            for i in range(1, n):
                acc = acc + J[a, i] * J[b, i]
            A[a, b] = acc + mu if a == b else acc
    return _cholesky_solve(J, r, A, L, y, x, d, free, False)


@njit(cache=True)
def _uniform_hash(seed, row, draw, out):
    """Row ``row``, draw ``draw`` of :func:`fkopt.kinematics.start_tables._uniform_hash` (SplitMix64's finaliser)."""
    c = (np.uint64(seed & 0xFFFFFFFF) * _M1) ^ (np.uint64(row) << np.uint64(20)) ^ (np.uint64(draw) << np.uint64(4))
    for k in range(out.shape[0]):
        z = c + np.uint64(k + 1) * _M2
        z = (z ^ (z >> np.uint64(30))) * _M2
        z = (z ^ (z >> np.uint64(27))) * _M3
        z = z ^ (z >> np.uint64(31))
        out[k] = np.float64(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True)
def _evaluate(chain, t, pt, T, Lw, W, r, J, p, R, ax, e, wone=False):
    """Residual r (6), scaled Jacobian J (6, n) at t; returns (pe, re, S). ``wone``: W is all
    ones, whose products change no bit (x * 1.0 == x), so they are skipped."""
    prismatic, C, v, var, mult, off, tC, tv = chain
    _walk(prismatic, C, v, var, mult, off, tC, tv, t, p, R, J, ax)
    _rotation_error(R, T, e)
    d0, d1, d2 = (p[0] - pt[0]) * W[0], (p[1] - pt[1]) * W[1], (p[2] - pt[2]) * W[2]
    e0, e1, e2 = e[0] * W[3], e[1] * W[4], e[2] * W[5]
    n = J.shape[1]
    if not wone:
        for a in range(6):
            for i in range(n):
                J[a, i] = J[a, i] * W[a]
    r[0], r[1], r[2], r[3], r[4], r[5] = d0, d1, d2, Lw * e0, Lw * e1, Lw * e2
    for a in range(3, 6):
        for i in range(n):
            J[a, i] = J[a, i] * Lw
    return (math.sqrt(d0 * d0 + d1 * d1 + d2 * d2), math.sqrt(e0 * e0 + e1 * e1 + e2 * e2),
            d0 * d0 + d1 * d1 + d2 * d2 + r[3] * r[3] + r[4] * r[4] + r[5] * r[5])


@njit(cache=True, error_model="numpy")
def _rps3_tan(ta, tb, z, j0, j1, j2, ra, rb, absolute):
    """Fitness of one 3-RPS pose from its half-angle tangents ta = tan(alpha/2), tb = tan(beta/2)
    (alpha, beta in rad) and z, against legs (j0, j1, j2): the operations of
    :meth:`fkopt.mechanisms.rps3.ThreeRPS._legs` after its ``np.tan`` in their order, then
    :meth:`fkopt.problems.FKProblem.fitness` (sum of squared or absolute residuals)."""
    s3 = 0.5 * math.sqrt(3.0)
    pm_rb, pm_2 = s3 * rb, -2.0 * s3
    ta2, tb2 = ta * ta, tb * tb
    ra_, rb_ = 1.0 / (1.0 + ta2), 1.0 / (1.0 + tb2)
    sa, sb = (ta + ta) * ra_, (tb + tb) * rb_
    ca, cb = (1.0 - ta2) * ra_, (1.0 - tb2) * rb_
    sbsa = sb * sa
    tg = sbsa / (ca + cb)
    cg = 1.0 / math.sqrt(1.0 + tg * tg)
    sg = tg * cg
    R00, R10 = cg * cb, sg * cb
    R11 = sg * sbsa + cg * ca
    R01 = cg * sbsa - sg * ca
    h = (0.5 * rb) * R11
    e = (1.5 * rb) * R00 - h - ra
    f = z - rb * sb
    d1 = math.sqrt(e * e + f * f)
    ax = 0.5 * ra - h
    bx = pm_rb * R01
    ay = (-1.5 * rb) * R10
    by = pm_2 * ax
    az = z + (0.5 * rb) * sb
    bz = pm_rb * (cb * sa)
    u, v, w = ax + bx, ay + by, az + bz
    d2 = math.sqrt((u * u + v * v) + w * w)
    u, v, w = ax + (-bx), ay + (-by), az + (-bz)
    d3 = math.sqrt((u * u + v * v) + w * w)
    r1, r2, r3 = d1 - j0, d2 - j1, d3 - j2
    if absolute:
        return (abs(r1) + abs(r2)) + abs(r3)
    return (r1 * r1 + r2 * r2) + r3 * r3


#: Degrees -> half-angle in radians (the factor :meth:`fkopt.mechanisms.rps3.ThreeRPS._legs` uses).
_HALF_DEG = math.pi / 360.0


@njit(cache=True, error_model="numpy")
def _rps3_point(p0, p1, z, j0, j1, j2, ra, rb, absolute):
    """Fitness of one 3-RPS pose (alpha, beta in deg, z) against legs (j0, j1, j2) with the C
    library's ``tan`` (:func:`_rps3_tan`): numpy's (SIMD) may differ from it by an ulp, so this
    serves only callers that want one point per call (the pygmo bench row); the fitness of
    :func:`rps3_fitness` and the swarm iterations take numpy's tangents (:func:`numpy_tan`)."""
    return _rps3_tan(math.tan(p0 * _HALF_DEG), math.tan(p1 * _HALF_DEG), z, j0, j1, j2, ra, rb, absolute)


# -- numpy's tangents in a compiled iteration ---------------------------------------------------
# A swarm turns an ulp into another run, and numpy's tan (SIMD code on some machines) may be an
# ulp from the C library's on ~0.7 % of inputs. So the compiled iterations stop where the numpy
# path calls np.tan: a move kernel writes the half-angle arguments of the candidates into a
# buffer laid out as the numpy path's own call sees them (ThreeRPS.ik_columns: per block of at most
# `block` poses of one fitness call, the block's alphas, then its betas, contiguous), numpy_tan
# runs np.tan on each such block, and a finish kernel computes the rest of the fitness from the
# tangents (_rps3_tan). The same ufunc on the same values at the same positions of arrays of the
# same lengths: the numpy path's bits on any build, whether its SIMD loop has a scalar tail or not.

@njit(cache=True)
def _slot(c, s0, sl, block):
    """(position of alpha's argument, offset of beta's from it) in the tangent buffer of pose c
    of a fitness call over poses [s0, s0 + sl), cut into blocks of ``block`` poses."""
    k = c - s0
    if sl <= block:                    # one block (the usual case): no integer division
        return 2 * s0 + k, sl
    first = (k // block) * block
    return 2 * (s0 + first) + (k - first), min(block, sl - first)


def numpy_tan(arg, out, segments, block):
    """``np.tan`` of the argument buffer ``arg`` into ``out`` as the numpy path calls it: for each
    fitness call (start pose, poses) in ``segments``, one call per block of at most ``block``
    poses on that block's contiguous [alphas, betas]."""
    tan = np.tan
    for s0, sl in segments:
        for b0 in range(0, sl, block):
            s, e = 2 * (s0 + b0), 2 * (s0 + min(b0 + block, sl))
            tan(arg[s:e], out[s:e])


@njit(cache=True, error_model="numpy")
def _rps3_args(P, arg, block):
    """The half-angle arguments of poses P (n, 3) into ``arg`` as one fitness call (:func:`_slot`)."""
    n = P.shape[0]
    for i in range(n):
        s, off = _slot(i, 0, n, block)
        arg[s] = P[i, 0] * _HALF_DEG
        arg[s + off] = P[i, 1] * _HALF_DEG


@njit(cache=True, error_model="numpy")
def _rps3_from_tan(P, tan, J, ra, rb, absolute, out, block):
    """:func:`_rps3_tan` of poses P (n, 3) with numpy's tangents ``tan`` (:func:`_rps3_args`'
    layout) against leg rows J (3, 1) or (3, n) into out (n,)."""
    n = P.shape[0]
    one = J.shape[1] == 1
    for i in range(n):
        c = 0 if one else i
        s, off = _slot(i, 0, n, block)
        out[i] = _rps3_tan(tan[s], tan[s + off], P[i, 2], J[0, c], J[1, c], J[2, c], ra, rb, absolute)


def rps3_fitness(P, J, ra, rb, absolute, block):
    """The 3-RPS fitness of poses (n, 3) against leg rows J (3, 1) or (3, n): fitness (n,), the
    numpy path's bits (numpy's tangents in its layout, :func:`numpy_tan`; ``block``: the poses
    per block of the numpy fitness)."""
    P = np.ascontiguousarray(P, dtype=float)
    n = P.shape[0]
    out, arg, tan = np.empty(n), np.empty(2 * n), np.empty(2 * n)
    _rps3_args(P, arg, block)
    numpy_tan(arg, tan, ((0, n),), block)
    _rps3_from_tan(P, tan, np.ascontiguousarray(J, dtype=float), float(ra), float(rb), bool(absolute), out, block)
    return out


_scratch = threading.local()


def _scratch_arrays(key, make):
    """This thread's scratch arrays for ``key`` (the kind and shape of an iteration), made by
    ``make()`` on first use: a swarm iteration's buffers are the same every iteration, and a
    dozen allocations cost about as much as a kernel's call. Nothing returned to a caller
    lives in them (see :func:`_kept`)."""
    cache = getattr(_scratch, "arrays", None)
    if cache is None:
        cache = _scratch.arrays = {}
    got = cache.get(key)
    if got is None:
        if len(cache) >= 16:           # a few shapes at a time (memory stays bounded)
            cache.clear()
        got = cache[key] = make()
    return got


def _kept(hr, he, hf, nh):
    """The log's improvements (rows, evaluation numbers, values) out of the scratch arrays, as new arrays."""
    return hr[:nh].copy(), he[:nh].copy(), hf[:nh].copy()


@njit(cache=True, error_model="numpy")
def _log_points(a, vals, lbest, lcount, lactive, hr, he, hf, nh):
    """:meth:`fkopt.algorithms.base.EvaluationLog.add` of the values ``vals`` (k,) that run ``a``
    just evaluated, in order: an improvement of the running best is kept as (row, evaluation
    number, value) in hr, he, hf from position nh while the run is active; the log's best and
    count advance either way. Returns the new nh."""
    run_best = lbest[a]
    for c in range(vals.shape[0]):
        g = vals[c]
        if g < run_best:
            if lactive[a]:
                hr[nh] = a
                he[nh] = lcount[a] + c + 1
                hf[nh] = g
                nh += 1
            run_best = g
    lbest[a] = run_best
    lcount[a] += vals.shape[0]
    return nh


@njit(cache=True, error_model="numpy")
def _fold_best(a, x, f, best_x, best_f):
    """:meth:`fkopt.algorithms.base.Algorithm.update_best` of run ``a``: its first minimum of f
    (a NaN first, as ``argmin``), if below best_f[a], into best_x[a], best_f[a]."""
    pop, dim = x.shape[1], x.shape[2]
    b = 0
    for i in range(pop):
        if f[a, i] != f[a, i]:
            b = i
            break
        if f[a, i] < f[a, b]:
            b = i
    if f[a, b] < best_f[a]:
        best_f[a] = f[a, b]
        for d in range(dim):
            best_x[a, d] = x[a, b, d]


@njit(cache=True, error_model="numpy")
def _pso_move(x, pos, vel, g, r, w, c1, c2, limit, bounds, npos, nvel, arg, block):
    """The move of :meth:`fkopt.algorithms.pso.PSO.iterate`, every run and particle in one pass:
    velocity w v + (c1 r1)(p - x) + (c2 r2)(g - x) (numpy's operations in their order), clamp,
    move, clip onto the box (velocity zeroed where clipped) into npos, nvel; the half-angle
    arguments of the new positions into ``arg`` (one fitness call, :func:`_slot`)."""
    runs, pop, dim = pos.shape
    n = runs * pop
    for a in range(runs):
        for i in range(pop):
            for d in range(dim):
                v = vel[a, i, d] * w + (r[a, 0, i, d] * c1) * (x[a, i, d] - pos[a, i, d])
                v = v + (r[a, 1, i, d] * c2) * (g[a, d] - pos[a, i, d])
                v = min(max(v, -limit[d]), limit[d])
                mv = pos[a, i, d] + v
                cp = min(max(mv, bounds[d, 0]), bounds[d, 1])
                nvel[a, i, d] = 0.0 if cp != mv else v
                npos[a, i, d] = cp
            s, off = _slot(a * pop + i, 0, n, block)
            arg[s] = npos[a, i, 0] * _HALF_DEG
            arg[s + off] = npos[a, i, 1] * _HALF_DEG


@njit(cache=True, error_model="numpy")
def _pso_finish(x, fb, npos, tan, J, ra, rb, absolute, nx, nf, fout, best_x, best_f, lbest, lcount, lactive, hr,
                he, hf, block):
    """The rest of a PSO iteration after numpy's tangents ``tan``: the fitness of the positions
    (:func:`_rps3_tan`) into fout, the personal bests into nx, nf, the fitness reported to the
    evaluation log held as arrays (:func:`_log_points`), and the personal bests folded into the
    best-so-far best_x, best_f (:func:`_fold_best`). Returns the number of improvements the log
    keeps."""
    runs, pop, dim = npos.shape
    n = runs * pop
    one = J.shape[1] == 1
    nh = 0
    for a in range(runs):
        for i in range(pop):
            c = 0 if one else a * pop + i
            s, off = _slot(a * pop + i, 0, n, block)
            f = _rps3_tan(tan[s], tan[s + off], npos[a, i, 2], J[0, c], J[1, c], J[2, c], ra, rb, absolute)
            fout[a, i] = f
            if f < fb[a, i]:
                nf[a, i] = f
                for d in range(dim):
                    nx[a, i, d] = npos[a, i, d]
            else:
                nf[a, i] = fb[a, i]
                for d in range(dim):
                    nx[a, i, d] = x[a, i, d]
        nh = _log_points(a, fout[a], lbest, lcount, lactive, hr, he, hf, nh)
        _fold_best(a, nx, nf, best_x, best_f)
    return nh


def pso_rps3(x, fb, pos, vel, g, g_f, r, w, c1, c2, limit, bounds, J, ra, rb, absolute, log, block):
    """One iteration of :meth:`fkopt.algorithms.pso.PSO.iterate` on a 3-RPS FK problem
    (:func:`_pso_move`, :func:`numpy_tan`, :func:`_pso_finish`): (personal bests x, their fitness,
    positions, velocities, best-so-far point and fitness (``g`` with the new personal bests folded
    in: :meth:`fkopt.algorithms.base.Algorithm.update_best`)), all new arrays, and (rows, evaluation numbers, values) of the improvements kept by ``log`` (best,
    count, active arrays updated in place, as :func:`abc_rps3`). ``g``, ``g_f``: the best-so-far
    point and fitness (the global best); ``limit``, ``bounds``: C-contiguous float arrays (dim,),
    (dim, 2); ``block``: the poses per block of the numpy fitness."""
    nx, nf, npos, nvel = np.empty_like(x), np.empty_like(fb), np.empty_like(pos), np.empty_like(vel)
    n = fb.size
    fout, arg, tan, hr, he, hf = _scratch_arrays(
        ("pso", fb.shape), lambda: (np.empty(fb.shape), np.empty(2 * n), np.empty(2 * n), np.empty(n, dtype=np.intp),
                                    np.empty(n, dtype=np.int64), np.empty(n)))
    best, count, active = log
    best_x, best_f = np.array(g, dtype=float, order="C"), np.array(g_f, dtype=float)
    _pso_move(x, pos, vel, best_x, r, float(w), float(c1), float(c2), limit, bounds, npos, nvel, arg, block)
    numpy_tan(arg, tan, ((0, n),), block)
    nh = _pso_finish(x, fb, npos, tan, J, float(ra), float(rb), bool(absolute), nx, nf, fout, best_x, best_f, best,
                     count, active, hr, he, hf, block)
    return nx, nf, npos, nvel, best_x, best_f, _kept(hr, he, hf, nh)


@njit(cache=True, error_model="numpy")
def _abc_move(xs, xk, xb, phi, psi, rule):
    """The neighbour move of :meth:`fkopt.algorithms.abc.ABC.move` (rule 0) and
    :meth:`fkopt.algorithms.gabc.GABC.move` (1: mao2017 eq. 19, 2: zhu2010 with psi = C u) on one
    coordinate, numpy's operations in their order, before clipping."""
    out = (xs - xk) * phi
    if rule == 1:
        out = out + (xb - xk) * phi
    elif rule == 2:
        out = out + (xb - xs) * psi
    return xs + out


@njit(cache=True, error_model="numpy")
def _abc_moves(x, best_x, u, o, a, src, rule, C, lo, hi, jj, mv, arg, base, n, block):
    """The moves of one phase of run ``a`` (uniforms of the block at ``u[a, o:]``): bee i moves
    coordinate j of source src[i] against a neighbour k != src[i], clipped, into jj[a], mv[a];
    the candidate (the source with that coordinate moved) is pose base + i of a fitness call
    over poses [0, n), whose half-angle arguments go into ``arg`` (:func:`_slot`)."""
    pop, dim = x.shape[1], x.shape[2]
    zhu = rule == 2
    for i in range(pop):
        s = src[i]
        j = int(u[a, o + i] * dim)
        k = int(u[a, o + pop + i] * (pop - 1))
        if k >= s:
            k += 1
        phi = u[a, o + 2 * pop + i] * 2.0 - 1.0
        psi = C * u[a, o + 3 * pop + i] if zhu else 0.0
        m = _abc_move(x[a, s, j], x[a, k, j], best_x[a, j], phi, psi, rule)
        m = min(max(m, lo[j]), hi[j])
        jj[a, i] = j
        mv[a, i] = m
        p, off = _slot(base + i, 0, n, block)
        arg[p] = (m if j == 0 else x[a, s, 0]) * _HALF_DEG
        arg[p + off] = (m if j == 1 else x[a, s, 1]) * _HALF_DEG


@njit(cache=True, error_model="numpy")
def _abc_employed_move(x, trial, best_x, u, limit, rule, C, lo, hi, separate, jj, mv, scout, arg, block):
    """Scout and employed moves of :meth:`fkopt.algorithms.abc.ABC.iterate` for every run, up to
    numpy's tangents. ``u`` (runs, D): the iteration's uniforms of each run in the order of the
    abc module's docstring (scout dim, employed 3 SN [+ SN psi], onlooker SN roulette, 3 SN [+ SN
    psi]). The scout (the source with the most trials, first of equals, if they exceed limit) is
    placed in x, its trials reset, scout[a] its source's index or -1; the employed bees' moves go
    into jj, mv (all from the sources as they stand, the scout's fresh one included). The
    arguments go into ``arg`` as the numpy path's fitness calls see them: candidates as poses
    [0, runs SN), the fresh scouts, in run order, after them in the same call (``separate``
    False) or in a call of their own (True: a target per row). Returns the number of scouts."""
    runs, pop, dim = x.shape
    n = runs * pop
    src = np.arange(pop)
    ns = 0
    for a in range(runs):
        scout[a] = -1
        s = 0
        over = False
        for i in range(pop):
            if trial[a, i] > limit:
                over = True
            if trial[a, i] > trial[a, s]:
                s = i
        if over:
            for d in range(dim):
                x[a, s, d] = lo[d] + u[a, d] * (hi[d] - lo[d])
            trial[a, s] = 0
            scout[a] = s
            ns += 1
    for a in range(runs):
        _abc_moves(x, best_x, u, dim, a, src, rule, C, lo, hi, jj, mv, arg, a * pop, n if separate else n + ns,
                   block)
    c = n
    for a in range(runs):
        if scout[a] >= 0:
            p, off = _slot(c, n if separate else 0, ns if separate else n + ns, block)
            arg[p] = x[a, scout[a], 0] * _HALF_DEG
            arg[p + off] = x[a, scout[a], 1] * _HALF_DEG
            c += 1
    return ns


@njit(cache=True, error_model="numpy")
def _abc_employed_finish(x, f, trial, best_x, best_f, u, rule, C, lo, hi, J, ra, rb, absolute, separate, ns, jj, mv,
                         scout, tan, fe, fo_src, fo_jj, fo_mv, arg, lbest, lcount, lactive, hr, he, hf, block):
    """After numpy's tangents ``tan`` of :func:`_abc_employed_move`'s arguments, for every run:
    the fitness of the fresh scout and of the employed candidates (NaN read as +inf, as
    ``np.fmin(f, inf)``) into fe, the greedy selection, the reports to the evaluation log held
    as arrays (employed, then the scout: :func:`_log_points`), GABC's best-so-far (rules 1, 2),
    the onlookers' roulette into fo_src and their moves into fo_jj, fo_mv with their arguments
    in ``arg`` (one call of runs SN poses). Returns the number of improvements the log keeps."""
    runs, pop, dim = x.shape
    n = runs * pop
    one = J.shape[1] == 1
    block4 = (4 if rule == 2 else 3) * pop
    cdf = np.empty(pop)
    fs = np.empty(1)
    nh = 0
    c_scout = n
    for a in range(runs):
        c = 0 if one else a * pop
        j0, j1, j2 = J[0, c], J[1, c], J[2, c]
        s = scout[a]
        if s >= 0:
            p, off = _slot(c_scout, n if separate else 0, ns if separate else n + ns, block)
            c_scout += 1
            g = _rps3_tan(tan[p], tan[p + off], x[a, s, 2], j0, j1, j2, ra, rb, absolute)
            if g != g:
                g = np.inf
            fs[0] = g
            f[a, s] = g
        # candidate i is source i with coordinate jj[i] moved; the greedy step of bee i changes
        # source i only (the moves read the sources before any of them changed, as numpy's
        # vectorised phase)
        for i in range(pop):
            p, off = _slot(a * pop + i, 0, n if separate else n + ns, block)
            j = jj[a, i]
            g = _rps3_tan(tan[p], tan[p + off], mv[a, i] if j == 2 else x[a, i, 2], j0, j1, j2, ra, rb, absolute)
            if g != g:
                g = np.inf
            fe[a, i] = g
            if g < f[a, i]:
                f[a, i] = g
                x[a, i, j] = mv[a, i]
                trial[a, i] = 0
            else:
                trial[a, i] += 1
        nh = _log_points(a, fe[a], lbest, lcount, lactive, hr, he, hf, nh)
        if s >= 0:
            nh = _log_points(a, fs, lbest, lcount, lactive, hr, he, hf, nh)
        if rule != 0:     # Algorithm.update_best between the phases (f holds no NaN: fmin'd, g's NaN is inf)
            _fold_best(a, x, f, best_x, best_f)
        # -- onlookers: roulette on the qualities 1/(1+f) (1-f below 0), cumulated in order
        o = dim + block4
        acc = 0.0
        for i in range(pop):
            q = 1.0 / (1.0 + f[a, i]) if f[a, i] >= 0 else 1.0 - f[a, i]
            acc = acc + q
            cdf[i] = acc
        src = fo_src[a]
        for i in range(pop):
            w = u[a, o + i] * cdf[pop - 1]
            # the first index with cdf > w = the count of cdf <= w (cdf is sorted): a branch-free
            # count for small colonies (a binary search mispredicts a branch per level), a binary
            # search for large ones, as abc.roulette
            if pop <= 32:
                n_le = 0
                for q_i in range(pop):
                    n_le += cdf[q_i] <= w
            else:
                n_le, hi_i = 0, pop
                while n_le < hi_i:
                    mid = (n_le + hi_i) // 2
                    if cdf[mid] <= w:
                        n_le = mid + 1
                    else:
                        hi_i = mid
            src[i] = 0 if n_le == pop else n_le
        _abc_moves(x, best_x, u, o + pop, a, src, rule, C, lo, hi, fo_jj, fo_mv, arg, a * pop, n, block)
    return nh


@njit(cache=True, error_model="numpy")
def _abc_onlooker_finish(x, f, trial, J, ra, rb, absolute, src_all, jj_all, mv_all, tan, fo, best_x, best_f, lbest,
                         lcount, lactive, hr, he, hf, nh, block):
    """After numpy's tangents of the onlookers' candidates, for every run: their fitness into fo,
    the reports to the log, then the synchronous onlookers -- per source the lowest candidate, the
    first onlooker reaching it, if it beats the source; a trial per attempt -- and the sources
    folded into the best-so-far (:func:`_fold_best`, what minimize's update_best does next). Returns nh."""
    runs, pop, dim = x.shape
    n = runs * pop
    one = J.shape[1] == 1
    bs = np.empty(pop)
    first = np.empty(pop, dtype=np.int64)
    for a in range(runs):
        c = 0 if one else a * pop
        j0, j1, j2 = J[0, c], J[1, c], J[2, c]
        src, jj, mv = src_all[a], jj_all[a], mv_all[a]
        for i in range(pop):
            p, off = _slot(a * pop + i, 0, n, block)
            g = _rps3_tan(tan[p], tan[p + off], mv[i] if jj[i] == 2 else x[a, src[i], 2], j0, j1, j2, ra, rb,
                          absolute)
            if g != g:
                g = np.inf
            fo[a, i] = g
        nh = _log_points(a, fo[a], lbest, lcount, lactive, hr, he, hf, nh)
        for i in range(pop):
            bs[i] = np.inf
            first[i] = pop
        for i in range(pop):
            if fo[a, i] < bs[src[i]]:
                bs[src[i]] = fo[a, i]
        for i in range(pop):
            s = src[i]
            if fo[a, i] == bs[s] and first[s] == pop:
                first[s] = i
            trial[a, s] += 1
        for s in range(pop):
            if bs[s] < f[a, s]:
                w_ = first[s]
                x[a, s, jj[w_]] = mv[w_]
                f[a, s] = bs[s]
                trial[a, s] = 0
        _fold_best(a, x, f, best_x, best_f)
    return nh


def abc_rps3(x, f, trial, best_x, best_f, u, limit, rule, C, bounds, J, ra, rb, absolute, log, separate, block):
    """One iteration of :meth:`fkopt.algorithms.abc.ABC.iterate` (scout, employed, onlooker;
    GABC's best-so-far refreshed between the phases, rules 1 and 2) on a 3-RPS FK problem:
    :func:`_abc_employed_move`, :func:`numpy_tan`, :func:`_abc_employed_finish`, :func:`numpy_tan`,
    :func:`_abc_onlooker_finish` on the state arrays x, f, trial (C-contiguous, updated in place)
    and best_x, best_f (updated in place: pass copies; GABC's refresh between the phases and
    minimize's update_best after the iteration both folded in), reporting to ``log`` (best (runs,) float,
    count (runs,) int64, active (runs,) bool, updated in place). ``separate``: the numpy path
    evaluates the fresh scouts in a fitness call of their own (a target per row); ``block``: the
    poses per block of the numpy fitness. Returns (scout (runs,) 0/1, (rows, evaluation numbers,
    values) of the improvements the log keeps)."""
    runs, pop = f.shape
    n = runs * pop
    separate = bool(separate)
    J = np.ascontiguousarray(J, dtype=float)
    ra, rb, absolute, C, limit, rule = float(ra), float(rb), bool(absolute), float(C), int(limit), int(rule)

    def make():
        most = runs * (2 * pop + 1)
        return ([np.empty((runs, pop), dtype=np.int64) for _ in range(3)] + [np.empty((runs, pop)) for _ in range(4)]
                + [np.empty(runs, dtype=np.int64), np.empty(2 * (n + runs)), np.empty(2 * (n + runs)),
                   np.empty(most, dtype=np.intp), np.empty(most, dtype=np.int64), np.empty(most),
                   np.ascontiguousarray(bounds[:, 0], dtype=float), np.ascontiguousarray(bounds[:, 1], dtype=float)])
    jj, fo_jj, fo_src, mv, fo_mv, fe, fo, scout, arg, tan, hr, he, hf, lo, hi = _scratch_arrays(
        ("abc", runs, pop, bounds.tobytes()), make)
    best, count, active = log
    ns = _abc_employed_move(x, trial, best_x, u, limit, rule, C, lo, hi, separate, jj, mv, scout, arg, block)
    numpy_tan(arg, tan, ((0, n), (n, ns)) if separate else ((0, n + ns),), block)
    nh = _abc_employed_finish(x, f, trial, best_x, best_f, u, rule, C, lo, hi, J, ra, rb, absolute, separate, ns, jj,
                              mv, scout, tan, fe, fo_src, fo_jj, fo_mv, arg, best, count, active, hr, he, hf, block)
    numpy_tan(arg, tan, ((0, n),), block)
    nh = _abc_onlooker_finish(x, f, trial, J, ra, rb, absolute, fo_src, fo_jj, fo_mv, tan, fo, best_x, best_f, best,
                              count, active, hr, he, hf, nh, block)
    return (scout >= 0).astype(np.int64), _kept(hr, he, hf, nh)



@intrinsic
def _mulhi(typingctx, a, b):
    """The high 64 bits of the 128-bit product of two uint64 (LLVM's i128 multiply)."""
    sig = types.uint64(types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        i128 = ir.IntType(128)
        wide = builder.mul(builder.zext(args[0], i128), builder.zext(args[1], i128))
        return builder.trunc(builder.lshr(wide, ir.Constant(i128, 64)), ir.IntType(64))
    return sig, codegen


#: PCG64's 128-bit LCG multiplier (O'Neill's PCG_DEFAULT_MULTIPLIER_128, numpy's PCG64), low and high words.
_PCG_LO = np.uint64(0x4385DF649FCCF645)
_PCG_HI = np.uint64(0x2360ED051FC65DA4)


@njit(inline="always")
def _pcg64_double(lo, hi, inc_lo, inc_hi):
    """One step of numpy's PCG64 (XSL-RR 128/64): state = state * M + inc (mod 2^128), output
    rotr64(hi ^ lo, hi >> 58) of the new state, and ``next_double``'s (out >> 11) * 2^-53.
    Returns (lo, hi, double)."""
    plo = lo * _PCG_LO
    phi = _mulhi(lo, _PCG_LO) + lo * _PCG_HI + hi * _PCG_LO
    lo = plo + inc_lo
    hi = phi + inc_hi + (np.uint64(1) if lo < plo else np.uint64(0))
    x = hi ^ lo
    rot = hi >> np.uint64(58)
    out = (x >> rot) | (x << ((np.uint64(64) - rot) & np.uint64(63)))
    return lo, hi, np.float64(out >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True)
def _fill_uniforms(buf, col, S):
    rows, width = buf.shape[0], buf.shape[1]
    r = 0
    while r + 4 <= rows:               # four runs at a time: four independent LCG chains in flight
        a0, a1, b0, b1 = S[r, 0], S[r, 1], S[r + 1, 0], S[r + 1, 1]
        c0, c1, d0, d1 = S[r + 2, 0], S[r + 2, 1], S[r + 3, 0], S[r + 3, 1]
        for j in range(col, width):
            a0, a1, va = _pcg64_double(a0, a1, S[r, 2], S[r, 3])
            b0, b1, vb = _pcg64_double(b0, b1, S[r + 1, 2], S[r + 1, 3])
            c0, c1, vc = _pcg64_double(c0, c1, S[r + 2, 2], S[r + 2, 3])
            d0, d1, vd = _pcg64_double(d0, d1, S[r + 3, 2], S[r + 3, 3])
            buf[r, j], buf[r + 1, j], buf[r + 2, j], buf[r + 3, j] = va, vb, vc, vd
        S[r, 0], S[r, 1], S[r + 1, 0], S[r + 1, 1] = a0, a1, b0, b1
        S[r + 2, 0], S[r + 2, 1], S[r + 3, 0], S[r + 3, 1] = c0, c1, d0, d1
        r += 4
    while r < rows:
        lo, hi = S[r, 0], S[r, 1]
        for j in range(col, width):
            lo, hi, v = _pcg64_double(lo, hi, S[r, 2], S[r, 3])
            buf[r, j] = v
        S[r, 0], S[r, 1] = lo, hi
        r += 1


def fill_uniforms(buf, col, S):
    """Row r of ``buf`` (runs, m), float64 and C-contiguous, from column ``col`` on: the next
    ``m - col`` doubles of the PCG64 whose 128-bit state and increment are S[r] = (state low,
    state high, inc low, inc high) (uint64 (runs, 4), advanced in place) -- numpy's
    ``Generator.random`` value by value (PCG64's XSL-RR output, ``next_double``), the same bits;
    one call for every run instead of one Python call per run, and the states in one compact
    array instead of behind two pointers per generator (with 1000 runs those pointer chases were
    cache misses on every refill). See :func:`pcg64_states`."""
    _fill_uniforms(buf, int(col), S)


_WORD = (1 << 64) - 1


def pcg64_states(generators) -> np.ndarray:
    """S (runs, 4) uint64 of :func:`fill_uniforms` from numpy PCG64 generators' ``state``."""
    S = np.empty((len(generators), 4), dtype=np.uint64)
    for r, g in enumerate(generators):
        st = g.bit_generator.state
        if st["bit_generator"] != "PCG64":
            raise ValueError(f"fill_uniforms draws PCG64 only, not {st['bit_generator']}")
        S[r] = (st["state"]["state"] & _WORD, st["state"]["state"] >> 64, st["state"]["inc"] & _WORD,
                st["state"]["inc"] >> 64)
    return S


def store_pcg64_states(generators, S) -> None:
    """Write S (see :func:`pcg64_states`) back into the generators, so that numpy draws continue
    the streams where :func:`fill_uniforms` left them."""
    for g, (lo, hi, ilo, ihi) in zip(generators, S.tolist()):
        st = g.bit_generator.state
        st["state"] = {"state": lo | (hi << 64), "inc": ilo | (ihi << 64)}
        g.bit_generator.state = st


@njit(cache=True)
def _probe(x):
    return math.sqrt(x * x) + 1.0


def probe(x: float) -> float:
    """x + 1 (x >= 0) through a compiled kernel: :func:`fkopt.numerics.path.compiled` calls it once
    per process to learn that numba compiles (or loads its cache) here before choosing this path."""
    return _probe(float(x))
