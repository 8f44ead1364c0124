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
* the stall test: a candidate whose |r|^2 is above ``stall`` times its value two evaluations before
  gives way to the next start (0: never; the last start runs to its end; when no start converges,
  the best answer goes on from where it ended without the test, its evaluations counted). A start
  that converges does so fast, a damped least-squares step from near a solution cuts |r| by far
  more than sqrt(2) in two steps, and a start that does not is mostly stuck against joint limits
  (issue 38: in the sweep of docs/performance.md, 0.5 cut the evaluations per pose by 19 %, as
  many poses solved);
* restarts: candidates one after another in the order of their starts, stopping at the first that
  converges; the best (smallest max(pe / tol[0], re / tol[1])) is kept: the one restart loop,
  :func:`fkopt.numerics.restart_loop.restart`, with this module's candidate search as its search.
"""
from __future__ import annotations

import math

from fkopt.numerics.restart_loop import restart
from fkopt.numerics.rotations import rotation_error1

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


def inverse_candidates(fj, pt, T, L, start_of, budget, tol, iterations, damping, down, up, step_cap,
                       stall, lo, hi, W=None):
    """The iteration of the module docstring for one pose: ``fj(q)`` -> (p, R, J) on floats
    (internal units), target position ``pt`` (3 floats) and rotation ``T`` (3 rows), orientation
    scale ``L``, ``start_of(j)`` the j-th start, ``lo``/``hi`` saturation limits (lists; +-inf
    for periodic joints), ``W`` the task mask (6 floats 0/1) or None.
    Returns (best joints (list, internal units), starts used, evaluations)."""
    tp, tr = tol
    t0, t1, t2 = pt

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

    def search(q):
        """One candidate: the damped least-squares steps from start q; (q, pe, re), its evaluations counted."""
        r, J, pe, re, S = evaluate(q)
        ne = 1
        lam = damping
        patience = stall if counted[1] < budget - 1 else 0.0     # the last start runs to its end
        counted[1] += 1
        s1 = s2 = math.inf                             # |r|^2 one and two evaluations before
        for _ in range(iterations):
            if pe <= tp and re <= tr:
                break
            if patience > 0.0 and S > patience * s2:
                break
            s1, s2 = S, s1
            mu = lam * trace6(J)
            d = dls_step(J, r, mu)
            if d is None:
                break
            big = max(map(abs, d))
            if big > step_cap:
                d = [v * (step_cap / big) for v in d]
            qn = saturate(q, [a + b for a, b in zip(q, d)], J, r, mu, lo, hi)
            rn, Jn, pen, ren, Sn = evaluate(qn)
            ne += 1
            if Sn < S:
                q, r, J, pe, re, S = qn, rn, Jn, pen, ren, Sn
                lam = max(lam * down, LAMBDA_MIN)
            else:
                lam *= up
                if lam > LAMBDA_STALL:
                    break
        counted[0] += ne
        return q, pe, re

    counted = [0, 0]                                   # evaluations, starts searched
    merit = lambda a: max(a[1] / tp, a[2] / tr)        # noqa: E731 - the restart loop's and the polish's
    best, met, used = restart(start_of, search, lambda a: a[1] <= tp and a[2] <= tr, merit=merit, budget=budget)
    if not met and stall > 0.0 and budget > 1:
        # every start failed: the best answer, most likely ended by the stall test, goes on without it
        # (counted[1] is past the last start, so the search runs without the test)
        polished = search(list(best[0]))
        if merit(polished) < merit(best):
            best = polished
    return best[0], used, counted[0]
