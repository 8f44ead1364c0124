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
* :func:`_rotation_error`, :func:`_rotation_target`, :func:`_geodesic` -- the compiled twins of
  :mod:`fkopt.numerics.rotations`' one-rotation helpers (``rotation_error1``, ``zyz1``);
* :func:`_evaluate`, :func:`_dls_step` -- the residual and the damped least-squares step of
  :mod:`fkopt.numerics.damped_least_squares`; the one-pose restart loop built on them is
  :mod:`fkopt.numerics.compiled_ik`, the all-solutions and path kernels :mod:`fkopt.numerics.compiled_branches`;
* :func:`fill_uniforms` -- the refill of :class:`fkopt.numerics.streams.RunStreams`' buffer, every run in one
  call: numpy's PCG64 and ``next_double`` on the runs' states in one array (``Generator.random``'s bits).

The compiled 3-RPS fitness lives beside its mechanism (:mod:`fkopt.mechanisms.rps3_kernels`), the
compiled PSO and ABC/GABC iterations beside their algorithms (:mod:`fkopt.algorithms.pso_kernels`,
:mod:`fkopt.algorithms.abc_kernels`).
"""
from __future__ import annotations

import math

import numpy as np
from numba import types               # numba first: without it, the ImportError names numba (not llvmlite)
from numba.core.extending import intrinsic
from llvmlite import ir

from fkopt.numerics.jit import njit                 # numba.njit with a cache that a corrupted file cannot break

_M1 = np.uint64(0x9E3779B97F4A7C15)
_M2 = np.uint64(0xBF58476D1CE4E5B9)
_M3 = np.uint64(0x94D049BB133111EB)


@njit(cache=True, _nrt=False)
def _walk(prismatic, C, v, var, mult, off, tC, tv, t, p, R, J, ax):
    """FK and Jacobian into p (3), R (3, 3) and J (6, n) (see :func:`fkopt.numerics.chain.frame_jacobian1`).
    The joints' cosines and sines come first, in a loop of their own (parked in ``ax``'s first
    columns until the walk reaches their link): a call inside the walk would cut its chain of
    products, registers saved and restored around every call; the same values either way."""
    x0, x1, x2, y0, y1, y2, z0, z1, z2 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
    p0 = 0.0
    p1 = 0.0
    p2 = 0.0
    m = prismatic.shape[0]
    for i in range(m):
        q = t[var[i]] * mult[i] + off[i]
        if prismatic[i]:
            ax[i, 0] = q
        else:
            ax[i, 0], ax[i, 1] = math.cos(q), math.sin(q)
    for i in range(m):
        q_or_c, s = ax[i, 0], ax[i, 1]              # a prismatic joint's value, a revolute one's cos, sin
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
            p0, p1, p2 = p0 + z0 * q_or_c, p1 + z1 * q_or_c, p2 + z2 * q_or_c
        else:
            c = q_or_c
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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
def _uniform_hash(seed, row, draw, out):
    """Row ``row``, draw ``draw`` of :func:`fkopt.kinematics.start_tables._uniform_hash` (SplitMix64's finaliser)."""
    c = (np.uint64(seed & 0xFFFFFFFF) * _M1) ^ (np.uint64(row) << np.uint64(20)) ^ (np.uint64(draw) << np.uint64(4))
    for k in range(out.shape[0]):
        z = c + np.uint64(k + 1) * _M2
        z = (z ^ (z >> np.uint64(30))) * _M2
        z = (z ^ (z >> np.uint64(27))) * _M3
        z = z ^ (z >> np.uint64(31))
        out[k] = np.float64(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True, _nrt=False)
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


@intrinsic
def _mulhi(typingctx, a, b):
    """The high 64 bits of the 128-bit product of two uint64 (LLVM's i128 multiply)."""
    sig = types.uint64(types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        i128 = ir.IntType(128)
        wide = builder.mul(builder.zext(args[0], i128), builder.zext(args[1], i128))
        return builder.trunc(builder.lshr(wide, ir.Constant(i128, 64)), ir.IntType(64))
    return sig, codegen


@intrinsic
def _fetch_add(typingctx, counter, step):
    """counter[0] += step as one atomic operation (LLVM's ``atomicrmw add``, monotonic: only the
    count itself is shared); returns the value before. Threads that run one compiled loop over
    shared rows take their next row with it (:func:`fkopt.numerics.compiled_ik.inverse_rows`)."""
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64 and counter.ndim == 1):
        return None
    sig = types.int64(counter, types.int64)

    def codegen(context, builder, signature, args):
        ary = context.make_array(signature.args[0])(context, builder, args[0])
        return builder.atomic_rmw("add", ary.data, args[1], "monotonic")
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
