"""The damped least-squares (Levenberg-Marquardt) iteration of ``fkopt.inverse`` for one pose, on
Python floats: the reference that :mod:`fkopt.numerics.compiled` runs compiled, operation for
operation in the same order.

* step d = J^T (J J^T + mu I)^{-1} (-r) (minimum-norm damped least squares), mu = lambda
  trace(J J^T) / 6, J J^T + mu I factored by Cholesky (:func:`dls_step`);
* lambda adapted as in Levenberg-Marquardt: x ``down`` after a step that decreases |r|^2, x ``up``
  otherwise; the joint step capped at ``step_cap`` (max-norm);
* joint limits by saturation in the null space (Flacco, De Luca, Khatib 2012): a joint whose step
  would leave its range is fixed at the limit, its column removed, the others re-solved for the
  residual left (2 passes), then every joint clamped into its range (:func:`saturate`);
* convergence: position error <= tol[0] and geodesic rotation error <= tol[1]; a candidate stops
  after ``iterations`` steps, when lambda exceeds 1e6 (stalled) or when the system is singular;
* restarts: candidates one after another in the order of their starts, stopping at the first that
  converges; the best (smallest max(pe / tol[0], re / tol[1])) is kept.
"""
from __future__ import annotations

import math

#: lambda above this: the candidate stalled and restarts.
LAMBDA_STALL = 1e6
#: smallest lambda.
LAMBDA_MIN = 1e-12
#: passes of the saturation in the null space.
SATURATION_PASSES = 2


def trace6(J) -> float:
    """trace(J J^T) / 6 (sum of J's squared entries, row by row, / 6)."""
    acc = 0.0
    for row in J:
        for v in row:
            acc = acc + v * v
    return acc / 6.0


def dls_step(J, r, mu, fixed=None):
    """d = Jf^T (Jf Jf^T + mu I)^{-1} (-r) for a 6 x n Jacobian on Python floats (Jf: J with the
    columns in ``fixed`` zeroed), by Cholesky; None when Jf Jf^T + mu I is not positive definite
    or d not finite. Dot products summed left to right; L row by row, forward then back
    substitution."""
    n = len(J[0])
    if fixed:
        J = [[0.0 if i in fixed else v for i, v in enumerate(row)] for row in J]
    A = [[0.0] * 6 for _ in range(6)]
    for a in range(6):
        Ja = J[a]
        for b in range(a, 6):
            Jb = J[b]
            acc = Ja[0] * Jb[0]
            for i in range(1, n):
                acc = acc + Ja[i] * Jb[i]
            A[a][b] = acc + mu if a == b else acc
    L = [[0.0] * 6 for _ in range(6)]
    for i in range(6):
        for j in range(i + 1):
            acc = 0.0
            for k in range(j):
                acc = L[i][k] * L[j][k] if k == 0 else acc + L[i][k] * L[j][k]
            acc = A[j][i] - acc
            if i == j:
                if not acc > 0.0:
                    return None
                L[i][i] = math.sqrt(acc)
            else:
                L[i][j] = acc / L[j][j]
    y = [0.0] * 6
    for i in range(6):
        acc = 0.0
        for k in range(i):
            acc = L[i][k] * y[k] if k == 0 else acc + L[i][k] * y[k]
        y[i] = (-r[i] - acc) / L[i][i]
    x = [0.0] * 6
    for i in range(5, -1, -1):
        acc = y[i]
        for k in range(i + 1, 6):
            acc = acc - L[k][i] * x[k]
        x[i] = acc / L[i][i]
    if not all(map(math.isfinite, x)):
        return None
    d = []
    for i in range(n):
        acc = J[0][i] * x[0]
        for a in range(1, 6):
            acc = acc + J[a][i] * x[a]
        d.append(acc)
    return d


def saturate(q, qn, J, r, mu, lo, hi):
    """Trial joints ``qn`` = q + d kept inside [lo, hi] by saturation in the null space (module
    docstring): joints outside are fixed at their limit (in order of index, then those a second
    pass pushes out), the rest re-solved for r + J (fixed motion); finally clamped."""
    n = len(q)
    out = [i for i in range(n) if qn[i] < lo[i] or qn[i] > hi[i]]
    if not out:
        return qn
    fixed = {}
    for _ in range(SATURATION_PASSES):
        for i in out:
            fixed[i] = min(max(qn[i], lo[i]), hi[i]) - q[i]
        rr = [r[a] + sum(J[a][i] * f for i, f in fixed.items()) for a in range(6)]
        ds = dls_step(J, rr, mu, fixed)
        if ds is None:
            break
        qn = [q[i] + (fixed[i] if i in fixed else ds[i]) for i in range(n)]
        out = [i for i in range(n) if i not in fixed and (qn[i] < lo[i] or qn[i] > hi[i])]
        if not out:
            break
    return [min(max(v, a), b) for v, a, b in zip(qn, lo, hi)]


def rotation_error1(R, T):
    """Rotation vector of R T^T (base frame, angle in [0, pi]) for rotations given as 3 rows of
    3 floats."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R
    (t00, t01, t02), (t10, t11, t12), (t20, t21, t22) = T
    v0 = (r20 * t10 + r21 * t11 + r22 * t12) - (r10 * t20 + r11 * t21 + r12 * t22)
    v1 = (r00 * t20 + r01 * t21 + r02 * t22) - (r20 * t00 + r21 * t01 + r22 * t02)
    v2 = (r10 * t00 + r11 * t01 + r12 * t02) - (r00 * t10 + r01 * t11 + r02 * t12)
    s = 0.5 * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    c = 0.5 * ((r00 * t00 + r01 * t01 + r02 * t02) + (r10 * t10 + r11 * t11 + r12 * t12)
               + (r20 * t20 + r21 * t21 + r22 * t22) - 1.0)
    k = math.atan2(s, c) / (2.0 * s) if s > 1e-12 else 0.5
    return v0 * k, v1 * k, v2 * k


def inverse_candidates(fj, pt, T, L, start_of, budget, tol, iterations, damping, down, up, step_cap,
                       lo, hi, W=None):
    """The iteration of the module docstring for one pose: ``fj(q)`` -> (p, R, J) on floats
    (internal units), target position ``pt`` (3 floats) and rotation ``T`` (3 rows), orientation
    scale ``L``, ``start_of(j)`` the j-th start, ``lo``/``hi`` saturation limits (lists; +-inf
    for periodic joints), ``W`` the task mask (6 floats 0/1) or None.
    Returns (best joints (list, internal units), starts used, evaluations)."""
    tp, tr = tol
    t0, t1, t2 = pt
    evals = 0

    def evaluate(q):
        p, R, J = fj(q)
        e0, e1, e2 = rotation_error1(R, T)
        d0, d1, d2 = p[0] - t0, p[1] - t1, p[2] - t2
        if W is not None:                              # masked task: those rows do not count
            d0, d1, d2, e0, e1, e2 = d0 * W[0], d1 * W[1], d2 * W[2], e0 * W[3], e1 * W[4], e2 * W[5]
            J = [[v * w for v in row] for row, w in zip(J, W)]
        r = [d0, d1, d2, L * e0, L * e1, L * e2]
        J[3] = [v * L for v in J[3]]
        J[4] = [v * L for v in J[4]]
        J[5] = [v * L for v in J[5]]
        return (r, J, math.sqrt(d0 * d0 + d1 * d1 + d2 * d2), math.sqrt(e0 * e0 + e1 * e1 + e2 * e2),
                d0 * d0 + d1 * d1 + d2 * d2 + r[3] * r[3] + r[4] * r[4] + r[5] * r[5])

    best_q, best_m = None, math.inf
    for j in range(budget):
        q = start_of(j)
        r, J, pe, re, S = evaluate(q)
        evals += 1
        lam = damping
        for _ in range(iterations):
            if pe <= tp and re <= tr:
                break
            mu = lam * trace6(J)
            d = dls_step(J, r, mu)
            if d is None:
                break
            big = max(map(abs, d))
            if big > step_cap:
                d = [v * (step_cap / big) for v in d]
            qn = saturate(q, [a + b for a, b in zip(q, d)], J, r, mu, lo, hi)
            rn, Jn, pen, ren, Sn = evaluate(qn)
            evals += 1
            if Sn < S:
                q, r, J, pe, re, S = qn, rn, Jn, pen, ren, Sn
                lam = max(lam * down, LAMBDA_MIN)
            else:
                lam *= up
                if lam > LAMBDA_STALL:
                    break
        merit = max(pe / tp, re / tr)
        if merit < best_m:
            best_q, best_m = q, merit
        if pe <= tp and re <= tr:
            return best_q, j + 1, evals
    return best_q, budget, evals
