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
* :func:`inverse_one` -- the one-pose loop of :func:`fkopt.numerics.damped_least_squares.inverse_candidates`, every
  start (given start, start-table neighbours, seeded hash draws) and restart inside;
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
    else:   # a half turn (fkopt.numerics.damped_least_squares.half_turn, operation for operation)
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
    """Row ``row``, draw ``draw`` of :func:`fkopt.kinematics.solvers._uniform_hash` (SplitMix64's finaliser)."""
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


@njit(cache=True)
def _inverse_one(chain, pt, T, Lw, W, q0, own0, near, have, table, feat, v32, tq, seed, row, budget, tp, tr, iterations,
                 damping, down, up, step_cap, lo, hi, glo, ghi, best_q):
    """:func:`fkopt.numerics.damped_least_squares.inverse_candidates` compiled; the j-th start is q0 (j < own0),
    near[j - own0] (j < own0 + len(near)), else draw j - own0 - len(near) of the hash for
    (seed, row) scaled into [glo, ghi]. Writes the best joints into best_q; returns
    (starts used, evaluations). Only the first ``have`` rows of ``near`` are filled when it is
    called: the rest are the start table's next nearest (:func:`_near_rows` on ``table``,
    features ``feat``, the screen ``v32``, joints ``tq``), looked up only if a start reaches them
    (most poses are solved from their first or second start)."""
    n = q0.shape[0]
    m = chain[0].shape[0]
    nn = near.shape[0]
    r, rn, rr = np.empty(6), np.empty(6), np.empty(6)
    J, Jn = np.empty((6, n)), np.empty((6, n))
    p, R, ax, e = np.empty(3), np.empty((3, 3)), np.empty((m, 6)), np.empty(3)
    A, Lc, y, x = np.empty((6, 6)), np.empty((6, 6)), np.empty(6), np.empty(6)
    q, qn, d, ds, u = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    fixed_val = np.empty(n)
    fixed_order = np.empty(n, dtype=np.int64)
    free = np.ones(n, dtype=np.bool_)
    wone = True
    for a in range(6):
        wone = wone and W[a] == 1.0
    evals = 0
    best_m = math.inf
    for j in range(budget):
        if j < own0:
            q[:] = q0
        elif j < own0 + nn:
            if j - own0 >= have:
                _near_rows(table, feat, v32, tq, near)  # the top `have` of these are the rows already there
                have = nn
            q[:] = near[j - own0]
        else:
            _uniform_hash(seed, row, j - own0 - nn, u)
            for i in range(n):
                q[i] = glo[i] + (ghi[i] - glo[i]) * u[i]
        pe, re, S = _evaluate(chain, q, pt, T, Lw, W, r, J, p, R, ax, e, wone)
        evals += 1
        lam = damping
        for _ in range(iterations):
            if pe <= tp and re <= tr:
                break
            acc = 0.0
            for a in range(6):
                for i in range(n):
                    acc = acc + J[a, i] * J[a, i]
            mu = lam * (acc / 6.0)
            if not _dls_step_all(J, r, mu, free, d, A, Lc, y, x):
                break
            big = abs(d[0])
            for i in range(1, n):
                big = max(big, abs(d[i]))
            if big > step_cap:
                f = step_cap / big
                for i in range(n):
                    d[i] = d[i] * f
            anyout = False
            for i in range(n):
                qn[i] = q[i] + d[i]
                if qn[i] < lo[i] or qn[i] > hi[i]:
                    anyout = True
            if anyout:                                  # saturation in the null space
                nf = 0
                for i in range(n):
                    free[i] = True
                for _pass in range(2):
                    for i in range(n):
                        if free[i] and (qn[i] < lo[i] or qn[i] > hi[i]):
                            fixed_val[i] = min(max(qn[i], lo[i]), hi[i]) - q[i]
                            fixed_order[nf] = i
                            nf += 1
                    for k in range(nf):
                        free[fixed_order[k]] = False
                    for a in range(6):
                        acc = 0.0
                        for k in range(nf):
                            acc = acc + J[a, fixed_order[k]] * fixed_val[fixed_order[k]]
                        rr[a] = r[a] + acc
                    if not _dls_step(J, rr, mu, free, ds, A, Lc, y, x):
                        break
                    more = False
                    for i in range(n):
                        qn[i] = q[i] + (ds[i] if free[i] else fixed_val[i])
                        if free[i] and (qn[i] < lo[i] or qn[i] > hi[i]):
                            more = True
                    if not more:
                        break
                for i in range(n):
                    qn[i] = min(max(qn[i], lo[i]), hi[i])
            pen, ren, Sn = _evaluate(chain, qn, pt, T, Lw, W, rn, Jn, p, R, ax, e, wone)
            evals += 1
            if Sn < S:
                q[:] = qn
                r[:] = rn
                J[:, :] = Jn
                pe, re, S = pen, ren, Sn
                lam = max(lam * down, 1e-12)
            else:
                lam *= up
                if lam > 1e6:
                    break
        merit = max(pe / tp, re / tr)
        if merit < best_m or j == 0:                # the reference keeps the first finite merit
            best_m = min(merit, best_m)
            best_q[:] = q
        if pe <= tp and re <= tr:
            return j + 1, evals
    return budget, evals


def inverse_one(chain, pt, T, L, W, q0, own0, near, seed, budget, tol, iterations, damping, down, up,
                step_cap, lo, hi, glo, ghi):
    """One pose through :func:`_inverse_one`: (best joints (n,), starts used, evaluations)."""
    best = np.empty(chain.dof)
    used, evals = _inverse_one(chain.arrays(), pt, T, float(L), W, q0, int(own0), near, near.shape[0], NO_TABLE,
                               np.zeros(12), np.zeros(0, dtype=np.float32), np.zeros((0, chain.dof)), int(seed), 0,
                               int(budget),
                               float(tol[0]), float(tol[1]), int(iterations), float(damping), float(down),
                               float(up), float(step_cap), lo, hi, glo, ghi, best)
    return best, used, evals


@njit(cache=True)
def _table_distances(Ft, norms, f, v):
    """v[i] = |F_i|^2 - 2 F_i . f (= |F_i - f|^2 - |f|^2) for every row of the start table, as
    :func:`fkopt.kinematics.solvers._nearest`'s brute force: the dot product summed feature by feature,
    rows side by side, from ``Ft`` = F transposed."""
    c, N = Ft.shape
    d2 = np.zeros(N)
    for j in range(c):
        fj = f[j]
        if fj == 0.0:
            # a feature the task mask leaves out (or an exact zero): each term would be +-0.0, which
            # leaves every sum as it is (finite table, and -0.0 + 0.0 only changes a zero's sign,
            # which |F_i|^2 - 2 d2 does not see), so skipping its pass keeps the bits
            continue
        for i in range(N):
            d2[i] += Ft[j, i] * fj
    for i in range(N):
        v[i] = norms[i] - 2.0 * d2[i]


@njit(cache=True)
def _smallest(v, idx, best):
    """The k = len(idx) rows of the smallest v, smallest first, into idx (values into best): kept
    sorted by insertion in row order (ties: the lower row first)."""
    k = idx.shape[0]
    m = 0
    for i in range(v.shape[0]):
        x = v[i]
        if m < k:
            pos = m
            m += 1
        elif x < best[k - 1]:
            pos = k - 1
        else:
            continue
        while pos > 0 and best[pos - 1] > x:
            best[pos] = best[pos - 1]
            idx[pos] = idx[pos - 1]
            pos -= 1
        best[pos] = x
        idx[pos] = i


@njit(cache=True)
def _nearest_into(Ft, norms, f, idx, best):
    """The k = len(idx) rows of the start table nearest to features f, nearest first, into idx
    (:func:`_table_distances`, then :func:`_smallest`)."""
    v = np.empty(Ft.shape[1])
    _table_distances(Ft, norms, f, v)
    _smallest(v, idx, best)


#: A start table that holds nothing (:func:`inverse_one` is given all its neighbours).
NO_TABLE = (np.zeros((12, 0)), np.zeros(0), np.zeros((12, 0), dtype=np.float32), np.zeros(0, dtype=np.float32), 0.0)

#: Neighbours looked up before the first start; the rest only when a start reaches them. Most
#: poses are solved from their first or second start, and the nearest four cost about half of
#: the nearest 64 (the screening pass is the same, computed once; the exact rows are not).
NEAR_FIRST = 4
#: The float32 screen's error bound, relative to the sizes in :func:`start_screen`: float32's
#: unit roundoff is 2^-24, a 12-term dot product and the conversions need at most ~16 of them;
#: 2^-16 leaves a factor 16 more.
SCREEN_ROUNDOFF = 2.0 ** -16


def start_screen(Ft, norms):
    """The start table for :func:`_nearest_screened`: (Ft float64 (12, N), norms float64, Ft and
    norms as float32, max |F_i|^2)."""
    return (Ft, norms, np.ascontiguousarray(Ft, dtype=np.float32), np.ascontiguousarray(norms, dtype=np.float32),
            float(norms.max()) if norms.shape[0] else 0.0)


@njit(cache=True)
def _screen32(table, f, v32):
    """v32[i] = |F_i|^2 - 2 F_i . f in float32 for every row (half the bytes of the float64 pass,
    twice the lanes): only a screen, :func:`_nearest_screened` decides on float64 values."""
    Ft32, n32 = table[2], table[3]
    c, N = Ft32.shape
    for i in range(N):
        v32[i] = 0.0
    for j in range(c):
        fj = np.float32(f[j])
        if f[j] == 0.0:
            continue
        for i in range(N):
            v32[i] += Ft32[j, i] * fj
    two = np.float32(2.0)
    for i in range(N):
        v32[i] = n32[i] - two * v32[i]


@njit(cache=True)
def _nearest_screened(table, f, v32, idx, best):
    """:func:`_nearest_into`'s k = len(idx) nearest rows, the same rows in the same order: the
    float32 screen v32 (:func:`_screen32`) bounds every row's float64 value v within B (sizes
    times :data:`SCREEN_ROUNDOFF`), so with s_k the k-th smallest screen value, the k-th smallest
    v is at most s_k + B and a row of the k nearest has v32 <= s_k + 2B; only those rows get the
    float64 value of :func:`_table_distances` (the same operations), in row order, and the same
    sorted insertion (ties: the lower row first)."""
    Ft, norms, _, _, nmax = table
    k = idx.shape[0]
    c, N = Ft.shape
    ff = 0.0
    for j in range(c):
        ff += f[j] * f[j]
    B = SCREEN_ROUNDOFF * (1.0 + nmax + 2.0 * math.sqrt(nmax * ff) + ff)
    # the k smallest screen values (sorted insertion; k is small)
    sk = np.empty(k)
    m = 0
    for i in range(N):
        x = np.float64(v32[i])
        if m < k:
            pos = m
            m += 1
        elif x < sk[k - 1]:
            pos = k - 1
        else:
            continue
        while pos > 0 and sk[pos - 1] > x:
            sk[pos] = sk[pos - 1]
            pos -= 1
        sk[pos] = x
    limit = sk[m - 1] + 2.0 * B if m > 0 else math.inf
    m = 0
    for i in range(N):
        if not np.float64(v32[i]) <= limit:
            continue
        acc = 0.0
        first = True
        for j in range(c):
            fj = f[j]
            if fj == 0.0:
                continue
            # d2[i] starts at 0.0 in _table_distances: 0.0 + x is x (but for -0.0, whose sign
            # |F_i|^2 - 2 d2 does not see)
            acc = Ft[j, i] * fj if first else acc + Ft[j, i] * fj
            first = False
        x = norms[i] - 2.0 * acc
        if m < k:
            pos = m
            m += 1
        elif x < best[k - 1]:
            pos = k - 1
        else:
            continue
        while pos > 0 and best[pos - 1] > x:
            best[pos] = best[pos - 1]
            idx[pos] = idx[pos - 1]
            pos -= 1
        best[pos] = x
        idx[pos] = i


@njit(cache=True)
def _near_rows(table, f, v32, tq, near):
    """The table joints of the len(near) rows nearest to f (:func:`_nearest_screened`) into near."""
    k = near.shape[0]
    idx = np.empty(k, dtype=np.int64)
    _nearest_screened(table, f, v32, idx, np.empty(k))
    for i in range(k):
        near[i, :] = tq[idx[i]]


@njit(cache=True, nogil=True)
def _inverse_pose(chain, pose, Lw, W, q0, own0, tq, table, wf, fmask, nn, seed, budget, tp, tr, iterations,
                  damping, down, up, step_cap, slo, shi, lo, hi, angle, periodic, blo, bhi, out, info):
    """One pose of ``fkopt.inverse`` from the public pose to the public answer, all compiled:
    the target rotation (from ZYZ Euler angles in deg, :func:`fkopt.kinematics.solvers._zyz_matrix1`, for
    a pose (6,); as given for a frame row (12,): x, y, z and the rotation row-major), the
    start table's ``nn`` nearest configurations (:func:`_nearest_screened`, its float32 screen once; the first
    :data:`NEAR_FIRST` now, the rest when a start reaches them), the loop
    (:func:`_inverse_one`), then the answer in public units (deg; continuous joints wrapped into
    [-180, 180); clipped into [blo, bhi]) into ``out`` and its check, FK of the answer against the
    target (masked by W), into ``info`` = (position error, rotation error, inside limits, starts
    used, evaluations). Releases the GIL (``nogil``; the same arithmetic), so that a control
    loop's other Python threads may take it while this solves (:class:`fkopt.kinematics.solvers.InverseSolver`
    calls it directly)."""
    n = q0.shape[0]
    d2r = math.pi / 180.0                          # math.radians / math.degrees: x * (pi / 180), x * (180 / pi)
    r2d = 180.0 / math.pi
    T = np.empty((3, 3))
    if pose.shape[0] == 12:                        # a frame row: the rotation as given, row-major
        for r in range(3):
            for c in range(3):
                T[r, c] = pose[3 + 3 * r + c]
    else:
        a, b, g = pose[3] * d2r, pose[4] * d2r, pose[5] * d2r
        ca, sa, cb, sb, cg, sg = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(g), math.sin(g)
        T[0, 0], T[0, 1], T[0, 2] = ca * cb * cg - sa * sg, -ca * cb * sg - sa * cg, ca * sb
        T[1, 0], T[1, 1], T[1, 2] = sa * cb * cg + ca * sg, -sa * cb * sg + ca * cg, sa * sb
        T[2, 0], T[2, 1], T[2, 2] = -sb * cg, sb * sg, cb
    pt = pose[:3].copy()
    near = np.empty((nn, n))
    v32 = np.empty(tq.shape[0] if nn > 0 else 0, dtype=np.float32)
    have = min(nn, NEAR_FIRST)
    f = np.empty(12)
    if nn > 0:
        f[0], f[1], f[2] = pt[0], pt[1], pt[2]
        for r in range(3):
            for c in range(3):
                f[3 + 3 * r + c] = wf * T[r, c]
        for j in range(12):
            f[j] = f[j] * fmask[j]
        _screen32(table, f, v32)
        _near_rows(table, f, v32, tq, near[:have])
    best = np.empty(n)
    used, evals = _inverse_one(chain, pt, T, Lw, W, q0, own0, near, have, table, f, v32, tq, seed, 0, budget, tp, tr,
                               iterations, damping, down, up, step_cap, slo, shi, lo, hi, best)
    t = np.empty(n)
    inside = True
    for i in range(n):
        v = best[i] * r2d if angle[i] else best[i]
        if periodic[i]:
            v = (v + 180.0) % 360.0 - 180.0
        v = min(max(v, blo[i]), bhi[i])
        out[i] = v
        inside = inside and blo[i] <= v <= bhi[i]
        t[i] = v * d2r if angle[i] else v
    prismatic, C, v_, var, mult, off, tC, tv = chain
    p, R, J, ax, e = np.empty(3), np.empty((3, 3)), np.empty((6, n)), np.empty((prismatic.shape[0], 6)), np.empty(3)
    _walk(prismatic, C, v_, var, mult, off, tC, tv, t, p, R, J, ax)
    _rotation_error(R, T, e)
    d0, d1, d2 = (p[0] - pt[0]) * W[0], (p[1] - pt[1]) * W[1], (p[2] - pt[2]) * W[2]
    e0, e1, e2 = e[0] * W[3], e[1] * W[4], e[2] * W[5]
    info[0] = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    info[1] = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    info[2] = 1.0 if inside else 0.0
    info[3] = used
    info[4] = evals


def bound_inverse_pose(ctx, L, W, q0, own0, nn, budget, tol, iterations, damping, down, up, step_cap):
    """:func:`_inverse_pose` with the per-arm constants ``ctx`` (see
    :func:`fkopt.kinematics.solvers._fast_context`) and the options bound once: a function
    (pose, seed) -> (public joints (n,), info (5,)). The one place that lays ``ctx`` onto the
    kernel's arguments; a prepared solver (:class:`fkopt.kinematics.solvers.InverseSolver`) keeps it, so
    a control loop's call does no dictionary lookups."""
    chain, n = ctx["chain"], ctx["n"]
    head = (L, W, q0, own0, ctx["tq"], ctx["table"], ctx["w"], ctx["fmask"], nn)
    tail = (budget, tol[0], tol[1], iterations, damping, down, up, step_cap, ctx["slo"], ctx["shi"], ctx["lo"],
            ctx["hi"], ctx["angle"], ctx["periodic"], ctx["blo"], ctx["bhi"])

    def call(pose, seed):
        out, info = np.empty(n), np.empty(5)
        _inverse_pose(chain, pose, *head, seed, *tail, out, info)
        return out, info
    return call


def inverse_pose(ctx, pose, L, W, q0, own0, nn, seed, budget, tol, iterations, damping, down, up, step_cap):
    """One pose through :func:`_inverse_pose` (:func:`bound_inverse_pose`, bound for this call):
    (public joints (n,), info (5,))."""
    return bound_inverse_pose(ctx, L, W, q0, own0, nn, budget, tol, iterations, damping, down, up, step_cap)(pose, seed)


@njit(cache=True, nogil=True)
def _inverse_rows(chain, poses, Lw, W, q0, own0, tq, table, wf, fmask, nn, seed, budget, tp, tr, iterations,
                  damping, down, up, step_cap, slo, shi, lo, hi, angle, periodic, blo, bhi, out, info, first, step):
    """:func:`_inverse_pose` of rows first, first + step, ... of ``poses`` (k, 6) from start rows
    ``q0[k]``; row k's answer is the one-pose call's. Runs without the GIL, so that threads can
    share a batch (:func:`inverse_rows`)."""
    for k in range(first, poses.shape[0], step):
        _inverse_pose(chain, poses[k], Lw, W, q0[k], own0, tq, table, wf, fmask, nn, seed, budget, tp, tr,
                      iterations, damping, down, up, step_cap, slo, shi, lo, hi, angle, periodic, blo, bhi,
                      out[k], info[k])


#: Batches from this many rows are shared by one thread per core.
THREAD_ROWS = 64


def inverse_rows(ctx, poses, L, W, q0, own0, nn, seed, budget, tol, iterations, damping, down, up, step_cap):
    """Rows through :func:`_inverse_rows`: (public joints (k, n), info (k, 5)). From
    :data:`THREAD_ROWS` rows, one Python thread per core takes every t-th row (interleaved, so
    that the rows needing restarts spread evenly): plain threads rather than numba's parallel
    layer, whose OpenMP runtime does not survive a fork and whose fallback is not thread-safe."""
    import os
    k = poses.shape[0]
    out, info = np.empty((k, ctx["n"])), np.empty((k, 5))
    args = (ctx["chain"], poses, L, W, q0, own0, ctx["tq"], ctx["table"], ctx["w"], ctx["fmask"], nn,
            seed, budget, tol[0], tol[1], iterations, damping, down, up, step_cap, ctx["slo"], ctx["shi"],
            ctx["lo"], ctx["hi"], ctx["angle"], ctx["periodic"], ctx["blo"], ctx["bhi"], out, info)
    threads = min(os.cpu_count() or 1, max(1, k // (THREAD_ROWS // 2)))
    if k < THREAD_ROWS or threads < 2:
        _inverse_rows(*args, 0, 1)
        return out, info
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(threads) as pool:
        for f in [pool.submit(_inverse_rows, *args, t, threads) for t in range(threads)]:
            f.result()
    return out, info


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
