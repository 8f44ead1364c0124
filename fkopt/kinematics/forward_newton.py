"""``fkopt.forward``'s local search, the step its restart loop iterates: damped Newton on
r(x) = ik(x) - joints with the mechanism's analytic Jacobian (:func:`_newton`, vectorised over the
rows of a batch; :func:`_newton1` the same for one row; :func:`_newton_scalar` on Python floats
for a mechanism with ``ik_jacobian1``), the verdict of an answer (:func:`_verify`) and the
likelihood weight of an assembly mode (:func:`_jacobian_volume`). The three Newton forms are kept
apart because their sums run in different orders (numpy's batched einsum, ``r @ r``, Python
floats): one of them for every path would move stored bits. See :mod:`fkopt.kinematics.solvers`."""
from __future__ import annotations

import math

import numpy as np

from fkopt.kinematics.start_tables import _sumsq
from fkopt.mechanisms.base import ParallelMechanism


class _Residuals:
    """r(x) = ik(x) - joints (angle joints wrapped) and J for rows ``idx`` of the batch."""

    def __init__(self, mechanism: ParallelMechanism, joints: np.ndarray):
        self.m = mechanism
        self.L = joints
        self.angle = mechanism.angle_mask(mechanism.joint_units)
        self.analytic = hasattr(mechanism, "jacobian")
        w = mechanism.bounds[:, 1] - mechanism.bounds[:, 0]
        self.h = 1e-6 * w

    def _wrap(self, r):
        if self.angle.any():
            r[..., self.angle] = (r[..., self.angle] + 180.0) % 360.0 - 180.0
        return r

    def r(self, x, idx):
        return self._wrap(self.m.ik(x) - self.L[idx])

    def rj(self, x, idx):
        """(r, J, residual evaluations, jacobian evaluations) per call."""
        if self.analytic:
            v, J = self.m.ik_jacobian(x)
            return self._wrap(v - self.L[idx]), J, 1, 1
        n = x.shape[-1]
        E = np.eye(n) * self.h
        pts = np.concatenate([x[:, None], x[:, None] + E, x[:, None] - E], axis=1)
        r = self._wrap(self.m.ik(pts) - self.L[idx][:, None])
        J = (r[:, 1:n + 1] - r[:, n + 1:]) / (2.0 * self.h[None, :, None])
        return r[:, 0], np.swapaxes(J, 1, 2), 1 + 2 * n, 0


def _newton(res: _Residuals, x: np.ndarray, idx: np.ndarray, ftol: float, evals,
            iterations: int = 30, halvings: int = 10):
    """Damped Newton from rows x (k, n) for batch rows ``idx``.

    Returns (x, max |r|) with r the residual at the returned x, as evaluated by the loop (the
    mechanism's closed form, ``ik_jacobian``). Rows stop when max |r| <= ftol, when no step
    along the Newton direction decreases |r|^2, or after ``iterations``.
    """
    bounds = res.m.bounds
    inv_cap = 4.0 / (bounds[:, 1] - bounds[:, 0])
    x = np.array(x, dtype=float)
    out_x = x.copy()
    out_r = np.full(len(x), np.inf)
    calls = np.ones(len(x), dtype=np.int64)            # rj calls per row (counted at exit)
    act = np.arange(len(x))
    r, J, ne, nj = res.rj(x, idx)
    F = _sumsq(r)
    square = J.shape[-1] == J.shape[-2]
    it = 1
    for _ in range(iterations):
        rmax = np.abs(r).max(axis=-1)
        done = ~(rmax > ftol)                              # converged, or not finite
        if done.any():
            out_x[act[done]], out_r[act[done]] = x[done], rmax[done]
            calls[act[done]] = it
            keep = ~done
            act, x, r, J, F = act[keep], x[keep], r[keep], J[keep], F[keep]
            if not len(act):
                break
        d = None
        if square:
            try:
                d = np.linalg.solve(J, r[..., None])[..., 0]
            except np.linalg.LinAlgError:
                d = None
        big = None if d is None else np.max(np.abs(d) * inv_cap, axis=-1)
        if big is None or not (big <= 1.0).all():
            if big is None or not np.isfinite(big).all():
                # singular somewhere: least squares with a little damping for every row
                Jt = np.swapaxes(J, -1, -2)
                A = Jt @ J
                A += 1e-9 * np.trace(A, axis1=-2, axis2=-1)[:, None, None] * np.eye(A.shape[-1])
                d = np.linalg.solve(A, Jt @ r[..., None])[..., 0]
                d[~np.isfinite(d)] = 0.0
                big = np.max(np.abs(d) * inv_cap, axis=-1)
            d /= np.maximum(big, 1.0)[:, None]             # steps capped at 1/4 of the box width
        xt = x - d
        rt, Jt, _, _ = res.rj(xt, idx[act])
        it += 1
        Ft = _sumsq(rt)
        bad = ~(Ft < F)
        if bad.any():
            ia = idx[act]
            step = 1.0
            fresh = np.zeros(len(act), dtype=bool)
            for _ in range(halvings):
                step *= 0.5
                b = np.flatnonzero(bad)
                xb = x[b] - step * d[b]
                rb = res.r(xb, ia[b])
                evals[0][ia[b]] += 1
                Fb = _sumsq(rb)
                ok = Fb < F[b]
                xt[b[ok]], rt[b[ok]], Ft[b[ok]] = xb[ok], rb[ok], Fb[ok]
                fresh[b[ok]] = True
                bad[b[ok]] = False
                if not bad.any():
                    break
            if bad.any():                   # no decrease along the step: stalled, stop those rows
                b = np.flatnonzero(bad)
                out_x[act[b]], out_r[act[b]] = x[b], np.abs(r[b]).max(axis=-1)
                calls[act[b]] = it
            fresh = np.flatnonzero(fresh)   # J at backtracked points is not known yet
            if len(fresh):
                _, Jf, _, _ = res.rj(xt[fresh], ia[fresh])
                Jt[fresh] = Jf
                evals[0][ia[fresh]] += ne
                evals[1][ia[fresh]] += nj
            moved = ~bad
            act, x, r, J, F = act[moved], xt[moved], rt[moved], Jt[moved], Ft[moved]
            if not len(act):
                break
        else:
            x, r, J, F = xt, rt, Jt, Ft
    if len(act):
        out_x[act], out_r[act] = x, np.abs(r).max(axis=-1)
        calls[act] = it
    evals[0][idx] += calls * ne
    evals[1][idx] += calls * nj
    return out_x, out_r


def _newton1(res: _Residuals, x: np.ndarray, ftol: float, evals, iterations: int = 30,
             halvings: int = 10):
    """:func:`_newton` for one row (batch of 1) with Python scalars for the tests: the same
    iteration, a fraction of the numpy calls (the cost of a single pose is per-call overhead)."""
    bounds = res.m.bounds
    inv_cap = 4.0 / (bounds[:, 1] - bounds[:, 0])
    idx = np.zeros(1, dtype=np.intp)
    rj = res.rj
    r, J, ne, nj = rj(x[None], idx)
    r, J = r[0], J[0]
    F = float(r @ r)
    calls, extra = 1, 0
    for _ in range(iterations):
        rmax = float(np.abs(r).max())
        if not rmax > ftol:
            break
        try:
            d = np.linalg.solve(J, r) if J.shape[0] == J.shape[1] else None
        except np.linalg.LinAlgError:
            d = None
        big = np.inf if d is None else float((np.abs(d) * inv_cap).max())
        if not big <= 1.0:
            if not np.isfinite(big):
                A = J.T @ J
                A += 1e-9 * np.trace(A) * np.eye(len(A))
                d = np.linalg.solve(A, J.T @ r)
                d[~np.isfinite(d)] = 0.0
                big = float((np.abs(d) * inv_cap).max())
            if big > 1.0:
                d = d / big
        xt = x - d
        rt, Jt, _, _ = rj(xt[None], idx)
        rt, Jt = rt[0], Jt[0]
        calls += 1
        Ft = float(rt @ rt)
        if not Ft < F:
            step, moved = 1.0, False
            for _ in range(halvings):
                step *= 0.5
                xb = x - step * d
                rb = res.r(xb[None], idx)[0]
                extra += 1
                Fb = float(rb @ rb)
                if Fb < F:
                    xt, rt, Ft, moved = xb, rb, Fb, True
                    break
            if not moved:
                break
            _, Jt, _, _ = rj(xt[None], idx)
            Jt = Jt[0]
            calls += 1
        x, r, J, F = xt, rt, Jt, Ft
    evals[0][0] += calls * ne + extra
    evals[1][0] += calls * nj
    rmax = float(np.abs(r).max())
    return x[None], np.array([rmax if np.isfinite(rmax) else np.inf])


def _solve_small(A, b):
    """x with A x = b for a small dense system on Python floats (Gaussian elimination with
    partial pivoting; lists are not modified). None when singular or not finite."""
    n = len(b)
    M = [row[:] + [b[i]] for i, row in enumerate(A)]
    for k in range(n):
        piv, best = k, abs(M[k][k])
        for i in range(k + 1, n):
            a = abs(M[i][k])
            if a > best:
                piv, best = i, a
        if not best > 1e-300:
            return None
        if piv != k:
            M[k], M[piv] = M[piv], M[k]
        Mk = M[k]
        inv = 1.0 / Mk[k]
        for i in range(k + 1, n):
            Mi = M[i]
            f = Mi[k] * inv
            if f != 0.0:
                for j in range(k + 1, n + 1):
                    Mi[j] -= f * Mk[j]
    x = [0.0] * n
    for k in range(n - 1, -1, -1):
        Mk = M[k]
        acc = Mk[n]
        for j in range(k + 1, n):
            acc -= Mk[j] * x[j]
        x[k] = acc / Mk[k]
    if not all(map(math.isfinite, x)):
        return None
    return x


def _newton_scalar(m, x, L, ftol, evals, iterations: int = 30, halvings: int = 10):
    """:func:`_newton1` on Python floats with the mechanism's ``ik_jacobian1`` (one pose, no
    angle joints): the same iteration (Newton step capped at a quarter of the box width,
    halved until |r|^2 decreases, stop at max |r| <= ftol or when no halving decreases it).
    Returns (x (1, n), max |r| (1,)), or None when a Jacobian is singular (the caller then
    runs :func:`_newton1`)."""
    rj = m.ik_jacobian1
    cap = [4.0 / (hi - lo) for lo, hi in m.bounds.tolist()]
    x = [float(v) for v in x]
    L = [float(v) for v in L]
    v, J = rj(x)
    r = [a - b for a, b in zip(v, L)]
    F = sum(a * a for a in r)
    calls = 1
    for _ in range(iterations):
        rmax = max(map(abs, r))
        if not rmax > ftol:
            break
        d = _solve_small(J, r)
        if d is None:
            evals[0][0] += calls
            evals[1][0] += calls
            return None
        big = max(abs(a) * c for a, c in zip(d, cap))
        if big > 1.0:
            d = [a / big for a in d]
        step, moved = 1.0, False
        for _ in range(halvings + 1):
            xt = [a - step * b for a, b in zip(x, d)]
            vt, Jt = rj(xt)
            calls += 1
            rt = [a - b for a, b in zip(vt, L)]
            Ft = sum(a * a for a in rt)
            if Ft < F:
                moved = True
                break
            step *= 0.5
        if not moved:
            break
        x, r, J, F = xt, rt, Jt, Ft
    evals[0][0] += calls
    evals[1][0] += calls
    rmax = max(map(abs, r))
    return np.array([x]), np.array([rmax if math.isfinite(rmax) else np.inf])


def _verify(mechanism, L, x, resid, tol):
    """Angle variables moved by multiples of 360 deg into the bounds (when possible), and the
    verdict: (x, max |ik(x) - L| with angle joints wrapped, solved). ``resid`` is the residual
    the solver evaluated at x (the closed form via ``ik_jacobian``); rows whose angles moved are
    evaluated again with ``ik``."""
    angle = mechanism.angle_mask(mechanism.unknown_units)
    inside = mechanism.in_bounds(x)
    resid = np.where(np.isfinite(resid), resid, np.inf)
    if angle.any() and not inside.all():
        out = np.flatnonzero(~inside)
        lo, hi = mechanism.bounds[angle, 0], mechanism.bounds[angle, 1]
        a = x[np.ix_(out, np.flatnonzero(angle))]
        moved = lo + (a - lo) % 360.0
        a = np.where(((a >= lo) & (a <= hi)) | (moved > hi), a, moved)
        x = x.copy()
        x[np.ix_(out, np.flatnonzero(angle))] = a
        r = mechanism.ik(x[out]) - L[out]
        jang = mechanism.angle_mask(mechanism.joint_units)
        if jang.any():
            r[:, jang] = (r[:, jang] + 180.0) % 360.0 - 180.0
        ro = np.abs(r).max(axis=-1)
        resid = resid.copy()
        resid[out] = np.where(np.isfinite(ro), ro, np.inf)
        inside = mechanism.in_bounds(x)
    return x, resid, (resid <= tol) & inside


def _jacobian_volume(res: _Residuals, x: np.ndarray, idx: np.ndarray, evals) -> np.ndarray:
    """sqrt(det(J^T J)) (|det J| for a square J) of d joints / d pose at poses x (k, n), rows
    ``idx``: the likelihood weight of an assembly mode. For a pose drawn uniformly in the bounds
    the joints' density is sum over the modes x_i of 1 / |det J(x_i)| (change of variables), so
    given the joints the generating pose is mode i with probability proportional to
    1 / |det J(x_i)|: the smallest volume is the likeliest mode (against the nearest start's
    solution: docs/kinbench.md). One Jacobian evaluation per pose, counted."""
    _, J, ne, nj = res.rj(x, idx)
    np.add.at(evals[0], idx, ne)
    np.add.at(evals[1], idx, nj)
    if J.shape[-1] == J.shape[-2]:
        return np.abs(np.linalg.det(J))
    return np.sqrt(np.abs(np.linalg.det(np.swapaxes(J, -1, -2) @ J)))
