"""The search of :func:`fkopt.kinematics.assembly_modes.all_solutions`: how a start is drawn and
a state updated for a mechanism (:class:`_SixSPSModel` on the leg equations with a rotation-vector
update, :class:`_GenericModel` on ``FKProblem``'s residuals), the damped Newton step vectorised
over starts (:func:`_newton`: the local search each start runs), the low-discrepancy starts
(:func:`_kronecker`), the deduplication (:func:`_cluster`) and the move of angles into the bounds
(:func:`_into_bounds`). The rounds of starts and their stopping rule are the one restart loop's
(:func:`fkopt.numerics.restart_loop.restart`); see :mod:`fkopt.kinematics.assembly_modes`.
"""
from __future__ import annotations

import numpy as np

from fkopt.errors import FkoptError
from fkopt.mechanisms.base import Mechanism
from fkopt.numerics import rotations
from fkopt.problems import FKProblem
from fkopt.mechanisms.sps6 import SixSPS


# ------------------------------------------------------------------------------------------
# Models: how a start is drawn, how a state is updated, how it maps to the mechanism's pose
# ------------------------------------------------------------------------------------------
class _Model:
    """A state batch S (n, k) on which the damped Newton loop works."""

    def starts(self, u: np.ndarray) -> np.ndarray:                      # u: (n, draws) uniforms
        raise NotImplementedError

    draws: int

    def residual(self, S) -> np.ndarray:                                # (n, m)
        raise NotImplementedError

    def residual_jacobian(self, S) -> tuple[np.ndarray, np.ndarray]:    # (n, m), (n, m, m)
        raise NotImplementedError

    def step(self, S, dx) -> np.ndarray:
        raise NotImplementedError

    def cap(self, dx) -> np.ndarray:
        """Factor (n,) <= 1 limiting the Newton step."""
        raise NotImplementedError

    def diverged(self, S) -> np.ndarray:
        return np.zeros(len(S), dtype=bool)

    def keys(self, S) -> np.ndarray:
        """Coordinates (n, k) in which duplicates are within ``dedup`` (max norm)."""
        raise NotImplementedError

    def poses(self, S) -> np.ndarray:
        """Mechanism pose vectors (n, dim), angles not yet moved into the bounds."""
        raise NotImplementedError

    def from_poses(self, X) -> np.ndarray:
        """States of mechanism pose vectors (n, dim) (inverse of :meth:`poses`)."""
        raise NotImplementedError


def _solve3_sym(M, y):
    """x with M x = y for symmetric (n, 3, 3) M, by the adjugate (elementwise; LAPACK's per-matrix
    overhead dominates for 3x3); rows with det(M) = 0 get a non-finite x (their start diverges)."""
    a, b, c = M[:, 0, 0], M[:, 0, 1], M[:, 0, 2]
    d, e, f = M[:, 1, 1], M[:, 1, 2], M[:, 2, 2]
    A00, A01, A02 = d * f - e * e, c * e - b * f, b * e - c * d
    A11, A12, A22 = a * f - c * c, b * c - a * e, a * d - b * b
    det = a * A00 + b * A01 + c * A02
    y0, y1, y2 = y[:, 0], y[:, 1], y[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        return np.stack([(A00 * y0 + A01 * y1 + A02 * y2) * inv, (A01 * y0 + A11 * y1 + A12 * y2) * inv,
                         (A02 * y0 + A12 * y1 + A22 * y2) * inv], axis=-1)


#: Batch size from which the 6-SPS model evaluates legs elementwise rather than by one GEMM.
_SOA_MIN = 1024
#: Start rotations of a 6-SPS with bounded angles are drawn from the angle bounds widened by
#: this fraction of their width on each side (measured on 6-sps-cmm, see the module docstring).
_ANGLE_PAD = 0.2


class _SixSPSModel(_Model):
    """State S = (t (3), R (9 row-major)); t is the pose position p_s, l_i = R q_i + t - b_i."""

    def __init__(self, mechanism, joints):
        base, platform, probe = mechanism.points()
        self.base = base
        self.q = platform - probe
        self.L = joints
        self.L2 = joints * joints
        self.inv_L = 1.0 / joints
        self.half_inv_L = 0.5 / joints
        self.qT = np.ascontiguousarray(self.q.T)
        self.bT = np.ascontiguousarray(base.T)
        self.mechanism = mechanism
        ang = mechanism.bounds[3:6]
        width = ang[:, 1] - ang[:, 0]
        # Uniform on SO(3) when alpha and gamma turn fully and beta spans [-90, 90].
        self.full = bool(width[0] >= 360 and width[2] >= 360 and ang[1, 0] <= -90 and ang[1, 1] >= 90)
        # Start angles from the bounds widened by _ANGLE_PAD of their width on each side (at
        # most a full turn): a solution near a face of the angle box keeps the part of its
        # basin beyond that face (module docstring, step 1).
        pad = np.minimum(_ANGLE_PAD * width, np.maximum(0.0, (360.0 - width) / 2))
        self.angle_bounds = np.radians(np.stack([ang[:, 0] - pad, ang[:, 1] + pad], axis=1))
        self.scale = float(np.abs(joints).max() + np.linalg.norm(base, axis=1).max()
                           + np.linalg.norm(self.q, axis=1).max())
        self.draws = 3

    def starts(self, u):
        if self.full:
            u1, u2, u3 = u[:, 0], 2 * np.pi * u[:, 1], 2 * np.pi * u[:, 2]
            a, b = np.sqrt(1 - u1), np.sqrt(u1)
            R = rotations.unit_quaternion_rows(a * np.sin(u2), a * np.cos(u2), b * np.sin(u3), b * np.cos(u3))
        else:
            lo, hi = self.angle_bounds[:, 0], self.angle_bounds[:, 1]
            e = lo + (hi - lo) * u
            R = rotations.zyx_rows(e[:, 0], e[:, 1], e[:, 2])
        # Position from the five linear equations (leg i minus leg 1), least squares.
        w = np.swapaxes(R @ self.qT, 1, 2) - self.base             # R q_i - b_i, (n, 6, 3)
        c = self.L2 - (w * w).sum(-1)                              # |t|^2 + 2 t.w_i = c_i
        A = 2.0 * (w[:, 1:] - w[:, :1])
        d = c[:, 1:] - c[:, :1]
        M = np.swapaxes(A, 1, 2) @ A                               # normal equations, 3x3 symmetric
        M[:, (0, 1, 2), (0, 1, 2)] += 1e-12
        y = (np.swapaxes(A, 1, 2) @ d[..., None])[..., 0]
        t = _solve3_sym(M, y)
        return np.concatenate([t, R.reshape(-1, 9)], axis=1)

    def _legs(self, S):
        t = S[:, :3]
        w = (np.ascontiguousarray(S[:, 3:]).reshape(-1, 3) @ self.qT).reshape(-1, 3, 6)   # R q_i, one GEMM
        v = w + (t[:, :, None] - self.bT)
        f = ((v * v).sum(1) - self.L2) * self.half_inv_L
        return f, v, w

    def _legs_soa(self, S, jac):
        """Same as :meth:`_legs` (+ Jacobian), elementwise per leg: faster for large batches."""
        n = len(S)
        t = S[:, 0], S[:, 1], S[:, 2]
        R = [[S[:, 3 + 3 * k + j] for j in range(3)] for k in range(3)]
        f = np.empty((6, n)).T
        J = np.empty((n, 6, 6)) if jac else None
        for i in range(6):
            q, b = self.q[i], self.base[i]
            w, v = [], []
            acc = None
            for k in range(3):
                wk = None
                for j in range(3):
                    if q[j] != 0.0:
                        wk = R[k][j] * q[j] if wk is None else wk + R[k][j] * q[j]
                if wk is None:
                    wk = np.zeros(n)
                vk = wk + (t[k] - b[k])
                w.append(wk)
                v.append(vk)
                acc = vk * vk if acc is None else acc + vk * vk
            f[:, i] = (acc - self.L2[i]) * self.half_inv_L[i]
            if jac:
                il, Ji = self.inv_L[i], J[:, i]
                Ji[:, 0], Ji[:, 1], Ji[:, 2] = v[0] * il, v[1] * il, v[2] * il
                Ji[:, 3] = (w[1] * v[2] - w[2] * v[1]) * il             # (R q_i) x v_i
                Ji[:, 4] = (w[2] * v[0] - w[0] * v[2]) * il
                Ji[:, 5] = (w[0] * v[1] - w[1] * v[0]) * il
        return f, J

    def residual(self, S):
        if len(S) >= _SOA_MIN:
            return self._legs_soa(S, False)[0]
        return self._legs(S)[0]

    def residual_jacobian(self, S):
        if len(S) >= _SOA_MIN:
            return self._legs_soa(S, True)
        f, v, w = self._legs(S)
        J = np.empty((len(S), 6, 6))
        J[:, :, :3] = np.swapaxes(v, 1, 2)
        J[:, :, 3] = w[:, 1] * v[:, 2] - w[:, 2] * v[:, 1]          # (R q_i) x v_i
        J[:, :, 4] = w[:, 2] * v[:, 0] - w[:, 0] * v[:, 2]
        J[:, :, 5] = w[:, 0] * v[:, 1] - w[:, 1] * v[:, 0]
        J *= self.inv_L[:, None]
        return f, J

    def step(self, S, dx):
        out = np.empty_like(S)
        out[:, :3] = S[:, :3] + dx[:, :3]
        out[:, 3:] = rotations.rotate_rows(dx[:, 3:], S[:, 3:])
        return out

    def cap(self, dx):
        # At most 2 rad of rotation (measured: smaller caps shrink the rarest basins of
        # Dietmaier's example, 1 rad by a third) and one mechanism size of translation.
        rot = np.sqrt((dx[:, 3:] ** 2).sum(-1)) / 2.0
        pos = np.sqrt((dx[:, :3] ** 2).sum(-1)) / self.scale
        return 1.0 / np.maximum(1.0, np.maximum(rot, pos))

    def diverged(self, S):
        return np.abs(S[:, :3]).max(-1) > 100.0 * self.scale

    def keys(self, S):
        width = self.mechanism.bounds[:3, 1] - self.mechanism.bounds[:3, 0]
        return np.concatenate([S[:, :3] / width, S[:, 3:]], axis=1)

    def poses(self, S):
        R = S[:, 3:].reshape(-1, 3, 3)
        # Re-orthonormalise (Newton's products of exponentials drift at round-off level).
        u, _, vt = np.linalg.svd(R)
        R = u @ vt
        return np.concatenate([S[:, :3], rotations.zyx_angles_rows(R)], axis=1)

    def from_poses(self, X):
        a = np.radians(X[:, 3:6])
        R = rotations.zyx_rows(a[:, 0], a[:, 1], a[:, 2])
        return np.concatenate([X[:, :3], R.reshape(-1, 9)], axis=1)


class _GenericModel(_Model):
    """Newton on FKProblem residuals in the mechanism's own pose variables (the mechanism's
    analytic Jacobian; central differences for a mechanism without one)."""

    def __init__(self, mechanism, joints):
        self.problem = FKProblem(mechanism, joints)
        self.mechanism = mechanism
        self.lo, self.hi = mechanism.bounds[:, 0], mechanism.bounds[:, 1]
        self.width = self.hi - self.lo
        self.angle = mechanism.angle_mask(mechanism.pose_units)
        self.h = 1e-6 * self.width
        self.draws = len(self.lo)
        self.triple = _euler_triple(mechanism)

    def starts(self, u):
        return self.lo + self.width * u

    def residual(self, S):
        return self.problem.residuals(S)

    def residual_jacobian(self, S):
        if self.problem.has_jacobian:
            return self.problem.residuals(S), self.problem.jacobian(S)
        n, d = S.shape
        E = np.eye(d) * self.h
        pts = np.concatenate([S[:, None, :], S[:, None, :] + E, S[:, None, :] - E], axis=1)
        r = self.problem.residuals(pts)                            # (n, 1 + 2d, m)
        J = (r[:, 1:d + 1] - r[:, d + 1:]) / (2.0 * self.h[None, :, None])
        return r[:, 0], np.swapaxes(J, 1, 2)

    def step(self, S, dx):
        return S + dx

    def cap(self, dx):
        return 1.0 / np.maximum(1.0, np.abs(dx / (0.25 * self.width)).max(-1))

    def diverged(self, S):
        return (np.abs((S - self.lo) / self.width) > 100.0).any(-1) | ~np.isfinite(S).all(-1)

    def _canonical(self, S):
        """Angles modulo 360, and a Tait-Bryan triple moved to beta in [-90, 90] when equivalent."""
        S = S.copy()
        if self.triple is not None:
            a, b, g = self.triple
            beta = _wrap(S[:, b])
            flip = np.abs(beta) > 90.0
            if flip.any():
                alt = S[flip].copy()
                alt[:, a] += 180.0
                alt[:, b] = 180.0 - alt[:, b]
                alt[:, g] += 180.0
                ik_alt, ik_s = self.mechanism.ik(alt), self.mechanism.ik(S[flip])
                same = np.abs(ik_alt - ik_s).max(-1) <= 1e-9 * (1.0 + np.abs(ik_s).max(-1))
                idx = np.flatnonzero(flip)[same]
                S[idx] = alt[same]
        S[:, self.angle] = _wrap(S[:, self.angle])
        return S

    def keys(self, S):
        C = self._canonical(S)
        out = C / np.where(self.angle, 1.0, self.width)
        out[:, self.angle] = np.radians(C[:, self.angle])
        # Angles close to +-180 deg: compare through (cos, sin) so that -179.9999 ~ 179.9999.
        return np.concatenate([out[:, ~self.angle], np.cos(out[:, self.angle]), np.sin(out[:, self.angle])], axis=1)

    def poses(self, S):
        return self._canonical(S)

    def from_poses(self, X):
        return np.array(X, dtype=float)


def _euler_triple(mechanism):
    names = mechanism.pose_names
    if all(n in names for n in ("alpha", "beta", "gamma")):
        idx = tuple(names.index(n) for n in ("alpha", "beta", "gamma"))
        if all(mechanism.pose_units[i] == "deg" for i in idx):
            return idx
    return None


def _wrap(d):
    return (np.asarray(d) + 180.0) % 360.0 - 180.0


# ------------------------------------------------------------------------------------------
# Damped Newton, vectorised over starts
# ------------------------------------------------------------------------------------------
def _solve(J, f):
    try:
        return np.linalg.solve(J, -f[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return -np.einsum("nij,nj->ni", np.linalg.pinv(J), f)


def _sumsq(f):
    out = f[:, 0] * f[:, 0]
    for k in range(1, f.shape[1]):
        out += f[:, k] * f[:, k]
    return out


def _newton(model: _Model, S: np.ndarray, *, ftol: float, iterations: int, halvings: int = 8,
            pool: int | None = None, report=None, line_search: bool = True, capture=None):
    """Damped Newton from every row of S. Returns (S, converged mask, rows started).

    Rows that finish (converged and polished, stalled, singular, diverged) are written back
    and dropped from the working arrays, so late iterations only cost what is still running.
    With ``pool``, at most that many rows run at once and finished ones are replaced by the
    next rows of S in order; ``report(rows, S_rows)`` receives the rows that finished converged
    after every iteration and returns True to stop the whole search (rows not started yet are
    then never started). Both keep the answer a function of S alone. ``line_search=False``
    takes every (capped) Newton step whose residual is finite: plain Newton. ``capture(S, F,
    open)`` sees the rows still iterating (``open``: not converged) after every iteration and returns
    the indices of those to stop now (counted by the caller as hits of solutions it knows) or None.
    """
    total = len(S)
    out = S.copy()
    conv = np.zeros(total, dtype=bool)
    started = total if pool is None else min(total, int(pool))
    idx = np.arange(started)
    S = S[:started].copy()
    it = np.zeros(started, dtype=np.int64)
    f, J = model.residual_jacobian(S)
    F = _sumsq(f)
    polish = np.zeros(len(S), dtype=bool)
    while len(idx):
        bad = ~np.isfinite(F + J.sum(axis=(1, 2)))     # F = |f|^2: one test for f and J
        if bad.any():                                  # e.g. a pose outside the inverse map's domain
            J[bad], f[bad] = np.eye(J.shape[-1]), 0.0
        dx = _solve(J, f)
        ok = np.isfinite(dx).all(-1) & ~bad
        dx[~ok] = 0.0
        dx *= model.cap(dx)[:, None]
        # Backtracking: the full step for all (residual and Jacobian at the trial point, the
        # Jacobian kept when the step is taken), then all halvings 1/2 ... 1/2^halvings of the
        # rows that need them evaluated together, taking the longest that decreases F.
        cand = model.step(S, dx)
        fc, Jc = model.residual_jacobian(cand)
        Fc = _sumsq(fc)
        # Polishing steps (already converged) are taken unconditionally.
        accepted = ((Fc < F) | polish | (not line_search)) & np.isfinite(Fc)
        if accepted.all():
            S, F, f, J = cand, Fc, fc, Jc
        else:
            S[accepted], F[accepted], f[accepted], J[accepted] = (
                cand[accepted], Fc[accepted], fc[accepted], Jc[accepted])
        stale = np.zeros(len(idx), dtype=bool)         # J not at S: taken at a halving
        pending = np.flatnonzero(~accepted)
        if len(pending) and halvings > 0:
            lams = 0.5 ** np.arange(1, halvings + 1)
            k = len(lams)
            rows = np.repeat(pending, k)
            lam = np.tile(lams, len(pending))
            cand = model.step(S[rows], dx[rows] * lam[:, None])
            Fc = _sumsq(model.residual(cand))
            good = ((Fc < F[rows]) & np.isfinite(Fc)).reshape(-1, k)
            hit = good.any(-1)
            first = np.argmax(good, axis=-1)
            pick = np.flatnonzero(hit) * k + first[hit]
            sel = pending[hit]
            S[sel], F[sel] = cand[pick], Fc[pick]
            accepted[sel] = True
            stale[sel] = True
        newly = (F <= ftol * ftol) & ~polish & ok
        it += 1
        finished = polish | ~accepted | ~ok | model.diverged(S) | (it >= iterations)
        if capture is not None:
            got = capture(S, F, ~finished & ~polish & ~newly)
            if got is not None:
                finished[got] = True
        conv[idx[newly]] = True
        polish |= newly
        out[idx[finished]] = S[finished]
        if report is not None:
            fin = idx[finished]
            good = fin[conv[fin]]
            if len(good) and report(good, out[good]):
                return out[:started], conv[:started], started
        keep = ~finished
        idx, S, F, f, J, polish, it, stale = (a[keep] for a in (idx, S, F, f, J, polish, it, stale))
        k = min(total - started, int(finished.sum())) if pool is not None else 0
        if k > 0:                                      # refill the pool with the next starts
            new = np.arange(started, started + k)
            started += k
            idx, S = np.concatenate([idx, new]), np.concatenate([S, out[new]])
            F = np.concatenate([F, np.zeros(k)])
            f = np.concatenate([f, np.zeros((k,) + f.shape[1:])])
            J = np.concatenate([J, np.zeros((k,) + J.shape[1:])])
            polish = np.concatenate([polish, np.zeros(k, dtype=bool)])
            it = np.concatenate([it, np.zeros(k, dtype=np.int64)])
            stale = np.concatenate([stale, np.ones(k, dtype=bool)])
        st = np.flatnonzero(stale)
        if len(st):
            f[st], J[st] = model.residual_jacobian(S[st])
            F[st] = _sumsq(f[st])
    out[idx] = S
    return out[:started], conv[:started], started


def _kronecker(shift, start: int, n: int, d: int) -> np.ndarray:
    """Points start .. start + n - 1 (n, d) of the randomly shifted Kronecker sequence
    frac(shift + k alpha), alpha_j = phi_d^-(j+1), phi_d the root > 1 of x^(d+1) = x + 1
    (M. Roberts 2018, "The unreasonable effectiveness of quasirandom sequences")."""
    phi = 2.0
    for _ in range(60):
        phi = (1.0 + phi) ** (1.0 / (d + 1))
    alpha = phi ** -np.arange(1, d + 1)
    k = np.arange(start, start + n, dtype=float)[:, None]
    return (np.asarray(shift)[None, :] + k * alpha[None, :]) % 1.0


def _cluster(keys: np.ndarray, tol: float) -> np.ndarray:
    """Label rows whose keys are within ``tol`` (max norm) of a representative: greedy, vectorised."""
    labels = np.full(len(keys), -1)
    k = 0
    while True:
        rest = np.flatnonzero(labels < 0)
        if not len(rest):
            return labels
        near = np.abs(keys[rest] - keys[rest[0]]).max(-1) <= tol
        labels[rest[near]] = k
        k += 1


def _into_bounds(mechanism: Mechanism, x: np.ndarray, triple) -> np.ndarray | None:
    """Move angle variables into the bounds by multiples of 360 deg (and the Euler equivalence).

    On Python floats (the same floor-modulo arithmetic as numpy's): called once per solution."""
    lo, hi = mechanism.bounds[:, 0].tolist(), mechanism.bounds[:, 1].tolist()
    angle = np.flatnonzero(mechanism.angle_mask(mechanism.pose_units)).tolist()
    x = [float(v) for v in x]
    candidates = [x]
    if triple is not None:
        a, b, g = triple
        alt = list(x)
        alt[a] += 180.0
        alt[b] = 180.0 - alt[b]
        alt[g] += 180.0
        candidates.append(alt)

    def inside(c):                                   # mechanism.in_bounds (tolerance 1e-9)
        return all(lo[i] - 1e-9 <= v <= hi[i] + 1e-9 for i, v in enumerate(c))

    for c in candidates:
        c = list(c)
        ok = True
        for i in angle:
            v = lo[i] + (c[i] - lo[i]) % 360.0           # smallest representative >= lo
            if v > hi[i] + 1e-9 and v - 360.0 >= lo[i] - 1e-9:
                v -= 360.0                                 # round-off just below lo
            if v > hi[i] + 1e-9:
                ok = False
                break
            c[i] = v
        if ok and inside(c):
            # Prefer the plain wrap to [-180, 180) when that is inside the bounds too.
            w = list(c)
            for i in angle:
                w[i] = (w[i] + 180.0) % 360.0 - 180.0
            return np.array(w if inside(w) else c)
    return None


def _model_for(mechanism, joints):
    if isinstance(mechanism, SixSPS):
        if np.any(joints <= 0):
            raise FkoptError(f"{mechanism.name} joints: leg lengths must be positive, got {joints.tolist()}")
        return _SixSPSModel(mechanism, joints)
    return _GenericModel(mechanism, joints)
