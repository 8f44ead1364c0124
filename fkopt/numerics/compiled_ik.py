"""The compiled one-pose IK of ``fkopt.inverse`` (numba): the one restart loop
(:func:`_inverse_one`, the twin of :func:`fkopt.numerics.restart_loop.restart` driving
:func:`fkopt.numerics.damped_least_squares.inverse_candidates`' search, :func:`_dls_candidate`),
the start table's nearest-neighbour search (a float32 screen, then the float64 rows it cannot rule
out: :func:`_nearest_screened`), one pose from the public target to the public answer
(:func:`inverse_pose`, :func:`bound_inverse_pose`) and rows shared by threads (:func:`inverse_rows`).
Built on :mod:`fkopt.numerics.compiled`'s chain, rotation and step kernels, operation for operation
in the reference's order. Importing this module imports numba.
"""
from __future__ import annotations

import math
import threading

import numpy as np

from fkopt.numerics.compiled import (_dls_step, _dls_step_all, _evaluate, _fetch_add, _rotation_error,
                                     _rotation_target, _uniform_hash, _walk)
from fkopt.numerics.jit import njit                 # numba.njit with a cache that a corrupted file cannot break


@njit(cache=True, _nrt=False)   # no reference counts: it only reads and writes the arrays it is given
def _dls_candidate(chain, q, pt, T, Lw, W, wone, tp, tr, iterations, damping, down, up, step_cap, stall, lo, hi,
                   work):
    """One candidate of the one restart loop: the damped least-squares steps from start q (updated
    in place) -- :func:`fkopt.numerics.damped_least_squares.inverse_candidates`' search, compiled,
    with saturation in the null space and its stall test (|r|^2 above ``stall`` times its value two
    evaluations before ends the candidate; 0: never); ``work`` the loop's scratch arrays. Returns
    (position error, rotation error, evaluations)."""
    r, rn, rr, J, Jn, p, R, ax, e, A, Lc, y, x, qn, d, ds, fixed_val, fixed_order, free = work
    n = q.shape[0]
    pe, re, S = _evaluate(chain, q, pt, T, Lw, W, r, J, p, R, ax, e, wone)
    evals = 1
    lam = damping
    s1 = s2 = math.inf                              # |r|^2 one and two evaluations before
    for _ in range(iterations):
        if pe <= tp and re <= tr:
            break
        if stall > 0.0 and S > stall * s2:          # stalled: the next start is likelier to converge
            break
        s1, s2 = S, s1
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
            for i in range(n):
                q[i] = qn[i]
            for a in range(6):
                r[a] = rn[a]
                for i in range(n):
                    J[a, i] = Jn[a, i]
            pe, re, S = pen, ren, Sn
            lam = max(lam * down, 1e-12)
        else:
            lam *= up
            if lam > 1e6:
                break
    return pe, re, evals


@njit(cache=True)
def _inverse_one(chain, pt, T, Lw, W, q0, own0, near, have, table, feat, v32, tq, seed, row, budget, tp, tr, iterations,
                 damping, down, up, step_cap, stall, lo, hi, glo, ghi, best_q):
    """:func:`fkopt.numerics.damped_least_squares.inverse_candidates` compiled; the j-th start is q0 (j < own0),
    near[j - own0] (j < own0 + len(near)), else draw j - own0 - len(near) of the hash for
    (seed, row) scaled into [glo, ghi]; every start but the last may end at the stall test
    (``stall``, :func:`_dls_candidate`), and when no start converges the best answer goes on
    from where it ended without the test (its evaluations counted, not a start). Writes the best
    joints into best_q; returns
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
    work = (r, rn, rr, J, Jn, p, R, ax, e, A, Lc, y, x, qn, d, ds, fixed_val, fixed_order, free)
    evals = 0
    best_m = math.inf
    for j in range(budget):                     # the one restart loop (fkopt.numerics.restart_loop.restart)
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
        pe, re, ev = _dls_candidate(chain, q, pt, T, Lw, W, wone, tp, tr, iterations, damping, down, up, step_cap,
                                    stall if j < budget - 1 else 0.0, lo, hi, work)
        evals += ev
        merit = max(pe / tp, re / tr)
        if merit < best_m or j == 0:                # the first answer is kept whatever its merit
            best_m = min(merit, best_m)
            best_q[:] = q
        if pe <= tp and re <= tr:
            return j + 1, evals
    if stall > 0.0 and budget > 1:
        # every start failed: the best answer, most likely ended by the stall test, goes on without it
        q[:] = best_q
        pe, re, ev = _dls_candidate(chain, q, pt, T, Lw, W, wone, tp, tr, iterations, damping, down, up, step_cap,
                                    0.0, lo, hi, work)
        evals += ev
        if max(pe / tp, re / tr) < best_m:
            best_q[:] = q
    return budget, evals


def inverse_one(chain, pt, T, L, W, q0, own0, near, seed, budget, tol, iterations, damping, down, up,
                step_cap, stall, lo, hi, glo, ghi):
    """One pose through :func:`_inverse_one`: (best joints (n,), starts used, evaluations)."""
    best = np.empty(chain.dof)
    used, evals = _inverse_one(chain.arrays(), pt, T, float(L), W, q0, int(own0), near, near.shape[0], NO_TABLE,
                               np.zeros(12), np.zeros(0, dtype=np.float32), np.zeros((0, chain.dof)), int(seed), 0,
                               int(budget),
                               float(tol[0]), float(tol[1]), int(iterations), float(damping), float(down),
                               float(up), float(step_cap), float(stall), lo, hi, glo, ghi, best)
    return best, used, evals


@njit(cache=True)
def _table_distances(Ft, norms, f, v):
    """v[i] = |F_i|^2 - 2 F_i . f (= |F_i - f|^2 - |f|^2) for every row of the start table, as
    :func:`fkopt.kinematics.start_tables._nearest`'s brute force: the dot product summed feature by feature,
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


@njit(inline="always")
def _insert(best, idx, m, x, i):
    """Row i of value x into the k = len(idx) smallest (value, row) pairs so far (``m`` of them
    held, sorted; ties: the lower row first, in whatever order the rows arrive); returns how many
    are held after it."""
    k = idx.shape[0]
    if m < k:
        pos = m
        m += 1
    elif x < best[k - 1] or (x == best[k - 1] and i < idx[k - 1]):
        pos = k - 1
    else:
        return m
    while pos > 0 and (best[pos - 1] > x or (best[pos - 1] == x and idx[pos - 1] > i)):
        best[pos] = best[pos - 1]
        idx[pos] = idx[pos - 1]
        pos -= 1
    best[pos] = x
    idx[pos] = i
    return m


@njit(cache=True)
def _table_features(pt, T, wf, fmask, f):
    """The start table's features of a target (position pt, rotation T) into f (12): position,
    then wf times the rotation row-major, times the task mask's ``fmask``
    (:func:`fkopt.kinematics.start_tables._start_table`'s features)."""
    f[0], f[1], f[2] = pt[0], pt[1], pt[2]
    for r in range(3):
        for c in range(3):
            f[3 + 3 * r + c] = wf * T[r, c]
    for j in range(12):
        f[j] = f[j] * fmask[j]


@njit(cache=True)
def _smallest(v, idx, best):
    """The k = len(idx) rows of the smallest v, smallest first, into idx (values into best): kept
    sorted by insertion in row order (ties: the lower row first)."""
    m = 0
    for i in range(v.shape[0]):
        x = v[i]
        m = _insert(best, idx, m, x, i)


@njit(cache=True)
def _nearest_into(Ft, norms, f, idx, best):
    """The k = len(idx) rows of the start table nearest to features f, nearest first, into idx
    (:func:`_table_distances`, then :func:`_smallest`)."""
    v = np.empty(Ft.shape[1])
    _table_distances(Ft, norms, f, v)
    _smallest(v, idx, best)


#: A start table that holds nothing (:func:`inverse_one` is given all its neighbours).
NO_TABLE = (np.zeros((12, 0)), np.zeros(0), np.zeros((12, 0), dtype=np.float32), np.zeros(0, dtype=np.float32), 0.0,
            np.zeros((0, 12)), np.zeros((7, 0), dtype=np.float32), np.zeros(0, dtype=np.float32), 0.0)

#: Neighbours looked up before the first start; the rest only when a start reaches them. Most
#: poses are solved from their first or second start, and the nearest four cost about half of
#: the nearest 64 (the screening pass is the same, computed once; the exact rows are not).
NEAR_FIRST = 4
#: The float32 screen's error bound, relative to the sizes in :func:`start_screen`: float32's
#: unit roundoff is 2^-24, a 12-term dot product and the conversions need at most ~16 of them;
#: 2^-16 leaves a factor 16 more.
SCREEN_ROUNDOFF = 2.0 ** -16


def start_screen(Ft, norms, wf=0.0):
    """The start table for :func:`_nearest_screened`: (Ft float64 (12, N), norms float64, Ft and
    norms as float32, max |F_i|^2, F float64 (N, 12), PQ float32 (7, N), a float32 (N,), wf). F is
    Ft row by row, for the float64 value of the few rows the screen keeps: a row's 12 features in
    two cache lines, where a column of Ft spreads them over 12 pages (measured on Panda: the
    nearest four 2.35 -> 2.1 µs a pose). PQ and a serve :func:`_screen32`'s quaternion screen:
    each row's position and the unit quaternion of its rotation, a = |F_i|^2 + 2 wf^2; empty
    (7, 0) unless every row is a start table's (position, ``wf`` times a rotation) -- a task
    mask's table zeroes features, and is screened feature by feature."""
    N = norms.shape[0]
    F = np.ascontiguousarray(Ft.T)
    PQ, a = np.zeros((7, 0), dtype=np.float32), np.zeros(0, dtype=np.float32)
    if wf > 0.0 and Ft.shape[0] == 12 and N:
        R = F[:, 3:].reshape(N, 3, 3) / wf
        if np.abs(R @ np.swapaxes(R, 1, 2) - np.eye(3)).max() <= ROTATION_TOL:
            PQ = np.ascontiguousarray(np.vstack([Ft[:3], _quaternions(R).T]), dtype=np.float32)
            a = np.ascontiguousarray(norms + 2.0 * wf * wf, dtype=np.float32)
    return (Ft, norms, np.ascontiguousarray(Ft, dtype=np.float32), np.ascontiguousarray(norms, dtype=np.float32),
            float(norms.max()) if N else 0.0, F, PQ, a, float(wf))


#: Largest |R R^T - I| of a rotation the quaternion screen takes (fkopt.inverse's own check of a
#: target frame, :data:`fkopt.kinematics.inputs.FRAME_ORTHONORMAL_TOL`, is this one).
ROTATION_TOL = 1e-9


def _quaternions(R):
    """Unit quaternions (N, 4) of rotations R (N, 3, 3), up to sign, by the largest of the trace
    and the diagonal (Shepperd 1978): :func:`_quaternion`'s cases on every row."""
    out = np.empty((len(R), 4))
    _quaternion_rows(np.ascontiguousarray(R, dtype=float), out)
    return out


@njit(cache=True)
def _quaternion_rows(R, out):
    """:func:`_quaternion` of every row (compiled: the start table's 4096 rows are part of a
    process's first call)."""
    for i in range(R.shape[0]):
        _quaternion(R[i], out[i])


@njit(cache=True, _nrt=False)
def _quaternion(T, q):
    """The unit quaternion (w, x, y, z) of rotation T into q, up to sign, from the largest of its
    trace and diagonal (Shepperd 1978: no square root of a small number)."""
    m00, m11, m22 = T[0, 0], T[1, 1], T[2, 2]
    t = m00 + m11 + m22
    if t >= m00 and t >= m11 and t >= m22:
        s = 2.0 * math.sqrt(max(1.0 + t, 0.0))
        q[0], q[1], q[2], q[3] = 0.25 * s, (T[2, 1] - T[1, 2]) / s, (T[0, 2] - T[2, 0]) / s, (T[1, 0] - T[0, 1]) / s
    elif m00 >= m11 and m00 >= m22:
        s = 2.0 * math.sqrt(max(1.0 + m00 - m11 - m22, 0.0))
        q[0], q[1], q[2], q[3] = (T[2, 1] - T[1, 2]) / s, 0.25 * s, (T[0, 1] + T[1, 0]) / s, (T[0, 2] + T[2, 0]) / s
    elif m11 >= m22:
        s = 2.0 * math.sqrt(max(1.0 + m11 - m00 - m22, 0.0))
        q[0], q[1], q[2], q[3] = (T[0, 2] - T[2, 0]) / s, (T[0, 1] + T[1, 0]) / s, 0.25 * s, (T[1, 2] + T[2, 1]) / s
    else:
        s = 2.0 * math.sqrt(max(1.0 + m22 - m00 - m11, 0.0))
        q[0], q[1], q[2], q[3] = (T[1, 0] - T[0, 1]) / s, (T[0, 2] + T[2, 0]) / s, (T[1, 2] + T[2, 1]) / s, 0.25 * s


@njit(cache=True)
def _screen32(table, f, v32):
    """v32[i] = |F_i|^2 - 2 F_i . f in float32 for every row (half the bytes of the float64 pass,
    twice the lanes): only a screen, :func:`_nearest_screened` decides on float64 values. The 12
    features in two passes of six, each summed in registers by pairs (two loads and stores of a
    row where a pass per feature made twelve; measured 0.75x the time); a masked-out feature adds
    F_ij * 0. Any order of the 12-term sum is within :data:`SCREEN_ROUNDOFF`'s bound.

    When f is a start table's features of a rotation (position, wf R) and the table keeps its
    rows' quaternions (:func:`start_screen`), the same values from 7 numbers a row instead of 12
    (:func:`_screen_quaternion`)."""
    Ft32, n32 = table[2], table[3]
    c, N = Ft32.shape
    if N > 0 and table[6].shape[1] == N and _screen_quaternion(table, f, v32):
        return
    two = np.float32(2.0)
    if c != 12:                                     # not a start table's 12 features: feature by feature
        for i in range(N):
            v32[i] = 0.0
        for j in range(c):
            fj = np.float32(f[j])
            for i in range(N):
                v32[i] += Ft32[j, i] * fj
        for i in range(N):
            v32[i] = n32[i] - two * v32[i]
        return
    f0, f1, f2, f3 = np.float32(f[0]), np.float32(f[1]), np.float32(f[2]), np.float32(f[3])
    f4, f5, f6, f7 = np.float32(f[4]), np.float32(f[5]), np.float32(f[6]), np.float32(f[7])
    f8, f9, f10, f11 = np.float32(f[8]), np.float32(f[9]), np.float32(f[10]), np.float32(f[11])
    F0, F1, F2, F3, F4, F5 = Ft32[0], Ft32[1], Ft32[2], Ft32[3], Ft32[4], Ft32[5]
    for i in range(N):
        v32[i] = (F0[i] * f0 + F1[i] * f1) + (F2[i] * f2 + F3[i] * f3) + (F4[i] * f4 + F5[i] * f5)
    F6, F7, F8, F9, F10, F11 = Ft32[6], Ft32[7], Ft32[8], Ft32[9], Ft32[10], Ft32[11]
    for i in range(N):
        v32[i] = n32[i] - two * (v32[i] + ((F6[i] * f6 + F7[i] * f7) + (F8[i] * f8 + F9[i] * f9)
                                           + (F10[i] * f10 + F11[i] * f11)))


@njit(cache=True)
def _screen_quaternion(table, f, v32):
    """:func:`_screen32`'s values from each row's position p_i and unit quaternion q_i: with f =
    (p, wf R) and R of unit quaternion q, F_i . f = p_i . p + wf^2 tr(R_i^T R) and tr(R_i^T R) =
    4 (q_i . q)^2 - 1, so |F_i|^2 - 2 F_i . f = a_i - 2 p_i . p - 8 wf^2 (q_i . q)^2 with a_i =
    |F_i|^2 + 2 wf^2 -- 28 bytes a row read instead of 48 (measured on Panda: 2.45 -> 1.7 µs a
    pose). Its float32 error, ~2^-24 (|F_i|^2 + 3 |p_i| |p| + 256 wf^2) with wf^2 <= |F_i|^2 / 3, is
    within :data:`SCREEN_ROUNDOFF`'s bound as the 12-term sum's is. Returns False (nothing
    written) when R = f[3:] / wf is not a rotation within :data:`ROTATION_TOL`."""
    PQ, a, wf = table[6], table[7], table[8]
    T = np.empty((3, 3))
    for r in range(3):
        for c in range(3):
            T[r, c] = f[3 + 3 * r + c] / wf
    for r in range(3):
        for c in range(3):
            dot = T[r, 0] * T[c, 0] + T[r, 1] * T[c, 1] + T[r, 2] * T[c, 2]
            if not abs(dot - (1.0 if r == c else 0.0)) <= ROTATION_TOL:
                return False
    q = np.empty(4)
    _quaternion(T, q)
    p0, p1, p2 = np.float32(2.0 * f[0]), np.float32(2.0 * f[1]), np.float32(2.0 * f[2])
    q0, q1, q2, q3 = np.float32(q[0]), np.float32(q[1]), np.float32(q[2]), np.float32(q[3])
    g = np.float32(8.0 * wf * wf)
    P0, P1, P2, Q0, Q1, Q2, Q3 = PQ[0], PQ[1], PQ[2], PQ[3], PQ[4], PQ[5], PQ[6]
    for i in range(v32.shape[0]):
        cq = (Q0[i] * q0 + Q1[i] * q1) + (Q2[i] * q2 + Q3[i] * q3)
        v32[i] = a[i] - (P0[i] * p0 + P1[i] * p1 + P2[i] * p2) - g * (cq * cq)
    return True


#: Rows of the start table per screen group in :func:`_nearest_screened`: group g holds rows g, g + G,
#: g + 2G, ... (G = :data:`SCREEN_GROUPS`), so that the groups' minima are one vectorised pass.
SCREEN_GROUPS = 256
#: Up to this many neighbours, :func:`_nearest_screened` visits the rows group by group; beyond, in row order.
GROUP_SCAN_K = 8


@njit(cache=True)
def _group_minima(v32, gm):
    """gm[g] = the smallest screen value of group g (rows g, g + G, ...; G = len(gm)), NaN rows
    left out (+inf for a group without a number): lane by lane over the table, one vectorised pass."""
    G = gm.shape[0]
    N = v32.shape[0]
    for g in range(G):
        gm[g] = np.inf
    full = N - N % G
    for s in range(0, full, G):
        row = v32[s:s + G]                          # a view: plain range indices vectorise, s + g does not
        for g in range(G):
            x = row[g]
            gm[g] = x if x < gm[g] else gm[g]
    rest = v32[full:]
    for g in range(N - full):
        x = rest[g]
        gm[g] = x if x < gm[g] else gm[g]


@njit(inline="always")
def _keep_smallest(kth, x):
    """x into the k = len(kth) smallest values so far, sorted (+inf where fewer were offered): only
    the values count here, not which row holds them, so one comparison with the largest held ends
    most offers (the (value, row) insertion of :func:`_insert` took 5x as long for the groups'
    minima). The screen's values are finite (finite table, checked target); +inf is never held."""
    k = kth.shape[0]
    if x < kth[k - 1]:
        j = k - 1
        while j > 0 and kth[j - 1] > x:
            kth[j] = kth[j - 1]
            j -= 1
        kth[j] = x


@njit(cache=True)
def _nearest_screened(table, f, v32, idx, best):
    """:func:`_nearest_into`'s k = len(idx) nearest rows, the same rows in the same order: the
    float32 screen v32 (:func:`_screen32`) bounds every row's float64 value v within B (sizes
    times :data:`SCREEN_ROUNDOFF`), so with s_k the k-th smallest screen value, the k-th smallest
    v is at most s_k + B and a row of the k nearest has v32 <= s_k + 2B; only those rows get the
    float64 value of :func:`_table_distances` (the same operations) and a sorted insertion by
    (value, row) (ties: the lower row first). s_k is found without a scalar pass over every row:
    the k-th smallest of the groups' minima (:func:`_group_minima`) is at least s_k (k groups, k
    rows at or below it), so the k smallest screen values are all in the groups whose minimum is
    at most it, and the rows at most s_k + 2B in the groups whose minimum is (for more than
    :data:`GROUP_SCAN_K` neighbours the rows are visited in row order instead, same rows)."""
    Ft, norms, nmax, F = table[0], table[1], table[4], table[5]
    k = idx.shape[0]
    c, N = Ft.shape
    ff = 0.0
    for j in range(c):
        ff += f[j] * f[j]
    B = SCREEN_ROUNDOFF * (1.0 + nmax + 2.0 * math.sqrt(nmax * ff) + ff)
    G = min(SCREEN_GROUPS, N)
    gm = np.empty(G, dtype=np.float32)
    _group_minima(v32, gm)
    # U: the k-th smallest group minimum (+inf with fewer than k groups holding a number)
    kth = np.empty(k)
    for j in range(k):
        kth[j] = math.inf
    for g in range(G):
        _keep_smallest(kth, np.float64(gm[g]))
    U = kth[k - 1]
    # s_k: the k-th smallest screen value, from the rows at most U: for a few neighbours those of the
    # few groups at most U; for many (more groups, each row in another cache line) a pass in row order
    # (at least k rows are visited: k groups hold a row at most U, and U = +inf visits all N >= k rows)
    for j in range(k):
        kth[j] = math.inf
    if k <= GROUP_SCAN_K:
        for g in range(G):
            if np.float64(gm[g]) <= U:
                for i in range(g, N, G):
                    _keep_smallest(kth, np.float64(v32[i]))
    else:
        for i in range(N):
            if np.float64(v32[i]) <= U:
                _keep_smallest(kth, np.float64(v32[i]))
    limit = kth[k - 1] + 2.0 * B
    m = 0
    if k <= GROUP_SCAN_K:
        for g in range(G):
            if np.float64(gm[g]) <= limit:
                for i in range(g, N, G):
                    if np.float64(v32[i]) <= limit:
                        m = _insert(best, idx, m, _table_distance(F, norms, f, i), i)
    else:
        for i in range(N):
            if np.float64(v32[i]) <= limit:
                m = _insert(best, idx, m, _table_distance(F, norms, f, i), i)


@njit(inline="always")
def _table_distance(F, norms, f, i):
    """Row i's float64 value |F_i|^2 - 2 F_i . f (F row by row), operation for operation
    :func:`_table_distances`'."""
    acc = 0.0
    first = True
    for j in range(F.shape[1]):
        fj = f[j]
        if fj == 0.0:
            continue
        # d2[i] starts at 0.0 in _table_distances: 0.0 + x is x (but for -0.0, whose sign
        # |F_i|^2 - 2 d2 does not see)
        acc = F[i, j] * fj if first else acc + F[i, j] * fj
        first = False
    return norms[i] - 2.0 * acc


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
                  damping, down, up, step_cap, stall, slo, shi, lo, hi, angle, periodic, blo, bhi, out, info):
    """One pose of ``fkopt.inverse`` from the public pose to the public answer, all compiled:
    the target rotation (from ZYZ Euler angles in deg, :func:`fkopt.numerics.rotations.zyz1`, for
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
    _rotation_target(pose, T)
    pt = pose[:3].copy()
    near = np.empty((nn, n))
    v32 = np.empty(tq.shape[0] if nn > 0 else 0, dtype=np.float32)
    have = min(nn, NEAR_FIRST)
    f = np.empty(12)
    if nn > 0:
        _table_features(pt, T, wf, fmask, f)
        _screen32(table, f, v32)
        _near_rows(table, f, v32, tq, near[:have])
    best = np.empty(n)
    used, evals = _inverse_one(chain, pt, T, Lw, W, q0, own0, near, have, table, f, v32, tq, seed, 0, budget, tp, tr,
                               iterations, damping, down, up, step_cap, stall, slo, shi, lo, hi, best)
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


def bound_inverse_pose(ctx, L, W, q0, own0, nn, budget, tol, iterations, damping, down, up, step_cap, stall):
    """:func:`_inverse_pose` with the per-arm constants ``ctx`` (see
    :func:`fkopt.kinematics.inverse_pose._fast_context`) and the options bound once: a function
    (pose, seed) -> (public joints (n,), info (5,)). The one place that lays ``ctx`` onto the
    kernel's arguments; a prepared solver (:class:`fkopt.kinematics.solvers.InverseSolver`) keeps it, so
    a control loop's call does no dictionary lookups."""
    chain, n = ctx["chain"], ctx["n"]
    head = (L, W, q0, own0, ctx["tq"], ctx["table"], ctx["w"], ctx["fmask"], nn)
    tail = (budget, tol[0], tol[1], iterations, damping, down, up, step_cap, stall, ctx["slo"], ctx["shi"], ctx["lo"],
            ctx["hi"], ctx["angle"], ctx["periodic"], ctx["blo"], ctx["bhi"])

    def call(pose, seed):
        out, info = np.empty(n), np.empty(5)
        _inverse_pose(chain, pose, *head, seed, *tail, out, info)
        return out, info
    return call


def inverse_pose(ctx, pose, L, W, q0, own0, nn, seed, budget, tol, iterations, damping, down, up, step_cap, stall):
    """One pose through :func:`_inverse_pose` (:func:`bound_inverse_pose`, bound for this call):
    (public joints (n,), info (5,))."""
    return bound_inverse_pose(ctx, L, W, q0, own0, nn, budget, tol, iterations, damping, down, up, step_cap,
                              stall)(pose, seed)


@njit(cache=True, nogil=True)
def _inverse_rows(chain, poses, Lw, W, q0, own0, tq, table, wf, fmask, nn, seed, budget, tp, tr, iterations,
                  damping, down, up, step_cap, stall, slo, shi, lo, hi, angle, periodic, blo, bhi, out, info, next_row):
    """:func:`_inverse_pose` of rows of ``poses`` (k, 6) from start rows ``q0[k]``: each row the
    one it takes from the shared count ``next_row[0]`` (:func:`fkopt.numerics.compiled._fetch_add`)
    until none is left; row k's answer is the one-pose call's, whoever takes it. Runs without the
    GIL, so that threads can share a batch (:func:`inverse_rows`)."""
    k = _fetch_add(next_row, 1)
    while k < poses.shape[0]:
        _inverse_pose(chain, poses[k], Lw, W, q0[k], own0, tq, table, wf, fmask, nn, seed, budget, tp, tr,
                      iterations, damping, down, up, step_cap, stall, slo, shi, lo, hi, angle, periodic, blo, bhi,
                      out[k], info[k])
        k = _fetch_add(next_row, 1)


#: Batches from this many rows are shared by threads (below, a thread costs more than it saves).
THREAD_ROWS = 64


def inverse_rows(ctx, poses, L, W, q0, own0, nn, seed, budget, tol, iterations, damping, down, up, step_cap,
                 stall, threads):
    """Rows through :func:`_inverse_rows`: (public joints (k, n), info (k, 5)). From
    :data:`THREAD_ROWS` rows, ``threads`` threads (this one and threads - 1 more; at most one per
    :data:`THREAD_ROWS` // 2 rows) share them, each taking the next row not yet taken: a row that
    needs many restarts holds up one thread, not a fixed share of the batch. Plain threads rather
    than numba's parallel layer, whose OpenMP runtime does not survive a fork and whose fallback
    is not thread-safe. Every row's answer depends only on its pose, start and the seed, so the
    answers are the same bits for any ``threads`` (1: this thread alone)."""
    k = poses.shape[0]
    out, info = np.empty((k, ctx["n"])), np.empty((k, 5))
    next_row = np.zeros(1, dtype=np.int64)
    args = (ctx["chain"], poses, L, W, q0, own0, ctx["tq"], ctx["table"], ctx["w"], ctx["fmask"], nn,
            seed, budget, tol[0], tol[1], iterations, damping, down, up, step_cap, stall, ctx["slo"], ctx["shi"],
            ctx["lo"], ctx["hi"], ctx["angle"], ctx["periodic"], ctx["blo"], ctx["bhi"], out, info, next_row)
    helpers = min(int(threads), max(1, k // (THREAD_ROWS // 2))) - 1 if k >= THREAD_ROWS else 0
    if helpers < 1:
        _inverse_rows(*args)
        return out, info
    failures = []

    def helper():
        try:
            _inverse_rows(*args)
        except BaseException as err:            # noqa: BLE001 - handed to the calling thread below
            failures.append(err)
    started = [threading.Thread(target=helper, name=f"fkopt-inverse-{i}", daemon=True) for i in range(helpers)]
    for t in started:
        t.start()
    try:
        _inverse_rows(*args)
    finally:
        for t in started:
            t.join()
    if failures:
        raise failures[0]
    return out, info
