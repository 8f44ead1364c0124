"""All assembly modes: every distinct real forward solution inside the bounds.

A swarm finds *one* pose whose inverse map matches the measured inputs; a parallel mechanism
usually has several (a general 6-SPS platform up to 40, Dietmaier 1998). :func:`all_solutions`
finds them all, numerically, for any :class:`~fkopt.mechanisms.base.ParallelMechanism` with as
many inputs as pose variables:

1. **Starts** come in rounds, points of one randomly shifted Kronecker sequence
   frac(u0 + k alpha) in the unit cube (Roberts 2018; ``qmc=False``: independent uniforms),
   u0 drawn from the seeded stream (:class:`fkopt.numerics.streams.RunStreams`), mapped to the unknowns.
   A low-discrepancy sequence reaches every region of the start space at a steady rate, so the
   rarest basins (a few hits per thousand starts) are found after a less variable number of
   starts than with independent draws (measured in the commit that introduced it).
   For a 6-SPS platform a start is a rotation -- uniform on SO(3) (Shoemake's quaternions) when
   the angle bounds cover a full turn, else uniform Euler angles in the bounds widened by
   ``_ANGLE_PAD`` (0.2) of their width on each side -- and the
   position that best satisfies, in least squares, the five *linear* equations obtained by
   subtracting leg 1's equation |R q_i + t - b_i|^2 = L_i^2 from the others. Only rotations are
   sampled, so no position box has to be guessed. The widening is for solutions near a face of
   the angle box: their Newton basins reach well beyond it, and starts drawn only inside cut
   them off (near a corner of three angle bounds, to about an eighth). Measured on 6-sps-cmm
   (+-30 deg) with 600 starts, seed 0, the basin of the pose the legs came from held, at the
   1st percentile of 400 poses with every coordinate within 5 % of a bound, 1.2 % of the starts
   unwidened (0 for the worst, u = [0.625, 0.02, 0.031, 0.02, 0.023, 0.031], whose neighbour just
   outside at y = -0.20005 took half), 8.8 % widened; for poses away from the bounds the worst
   stayed at 15 % (median 38 -> 29 %). With 40 starts per pose, 2000 poses near the bounds
   missed their pose 70 times unwidened, 5 times widened; a start costs ~1.2x the Newton steps.
   For other mechanisms a start is uniform in the bounds (their basins measured to cover the
   box: 3-RPS, 3-RPUPc-UPS and 3-PPR poses on and near the bounds are hit by > 99 % of the starts,
   or by both branches' halves).
2. **Damped Newton**, vectorised over all starts of a round: for 6-SPS on the leg equations
   (|v_i|^2 - L_i^2) / (2 L_i) = 0 with the analytic Jacobian [v_i, (R q_i) x v_i] / L_i in the
   position and a rotation vector (R <- exp([w]x) R, so no Euler singularity during the
   search); for other mechanisms on ``FKProblem.residuals`` with ``FKProblem.jacobian`` (central
   differences only for a mechanism without an analytic Jacobian).
   Steps are capped (6-SPS: 2 rad of rotation and one mechanism size of translation; others:
   a quarter of the bounds width). For other mechanisms they are halved up to 8 times until the
   squared residual decreases (backtracking line search: the full step's residual and Jacobian
   in one call, the Jacobian kept when the step is taken; the halvings of the rows that need
   them in one more call). For 6-SPS every capped step is taken (plain Newton): measured on
   Dietmaier's platform over 20 seeds, a seed then needs a median of ~1260 starts to see all 40
   solutions against ~1700 with the line search (the backtracking shrinks the rarest basins),
   and an iteration costs one evaluation. A start stops when converged (then one more
   polishing step), diverged, stalled (line search) or out of ``iterations`` (60), or is
   *captured*: its residual is at most ``capture[0]`` (1e-4, relative as ``tol``) and its
   state within ``capture[1]`` (1e-3, in the dedup coordinates) of a solution already known
   -- well inside that solution's quadratic convergence region, where the remaining steps would
   only confirm it; it counts as a hit of that solution (``capture=None``: every start runs to
   convergence). At most ``pool`` (512) starts of a round iterate at once;
   a finished start is replaced by the round's next one, in order, and converged starts are
   deduplicated after every iteration, so the search stops mid-round as soon as ``maximum``
   solutions are known (the answer stays a function of the seed alone).
3. **Deduplication** with the stated tolerance ``dedup``: two converged starts are one
   solution when they differ by at most ``dedup`` in the normalised pose space -- length
   variables divided by their bounds width, angle variables in radians compared modulo 2 pi,
   and for 6-SPS the rotation compared by its matrix (max entry difference), so the Euler
   equivalences (a, b, g) ~ (a + 180, 180 - b, g + 180) ~ (a + 360 k, ...) never split a
   solution. For other mechanisms whose pose holds a Tait-Bryan triple (alpha, beta, gamma)
   the triple is first mapped to the representative with beta in [-90, 90] (valid for every
   Tait-Bryan sequence) when that representative has the same inputs.
4. **Check**: the pose of each solution is written in the mechanism's own variables (Z-Y-X
   Euler degrees for 6-SPS, angles moved into the bounds by multiples of 360 deg or by the
   Euler equivalence), its residual ``max |ik(pose) - joints|`` recomputed with the
   mechanism's inverse map; it is kept if that residual is at most ``tol * max(1, |joint|)``
   for every joint and the pose is inside the bounds (solutions found outside are counted in
   ``Solutions.outside``). A pose at most ``_BOUND_SLACK`` (1e-3 of a width) past a bound is
   clipped into the bounds and polished there by Gauss-Newton with the clipped variables held
   (a root on a bound that is double, e.g. 3-PPR at x = 60, theta = 0, converges linearly and
   stops within ``tol`` but ~1e-6 past it); it is kept if its residual is within ``tol``
   (then it is a solution in the bounds by definition), merged into a solution already found
   within ``dedup``.

Rounds continue until ``patience`` consecutive rounds bring no new solution in the bounds,
after at least ``min_starts`` (or until ``max_starts``), or until ``maximum`` distinct real
solutions are known (40 for a 6-SPS platform: no more can exist); ``starts=N`` instead runs exactly N
starts in one round. ``Solutions.history`` records (starts, seconds, solutions in the bounds)
after every round.

On Dietmaier's platform (default "6-sps" geometry and legs ``DIETMAIER_LEGS``) all 40 real
solutions are found on every seed tried, almost always within the first round of 2000 starts
(counts and times: ``bench/targets.csv`` and ``fkopt bench``, section kinematics).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from fkopt.errors import FkoptError
from fkopt.mechanisms.base import Mechanism, ParallelMechanism
from fkopt.problems import FKProblem
from fkopt.numerics.streams import RunStreams


@dataclass
class Solution:
    """One assembly mode: its pose (mechanism variables), residual max |ik - joints|, and how many starts found it."""

    pose: dict[str, float]
    residual: float
    hits: int

    @property
    def x(self) -> np.ndarray:
        return np.array(list(self.pose.values()))


class Solutions(list):
    """List of :class:`Solution` (most hits first) with the search's bookkeeping as attributes."""

    names: tuple[str, ...] = ()
    #: starts used, wall time (s), distinct real solutions found outside the bounds
    starts: int = 0
    time_s: float = 0.0
    outside: int = 0
    #: (starts so far, seconds so far, solutions in the bounds so far) after every round
    history: list[tuple[int, float, int]]
    settings: dict[str, Any]

    def poses(self) -> np.ndarray:
        """Poses (n, dim), rows in the order of the list."""
        return np.array([s.x for s in self]).reshape(len(self), len(self.names))


def solutions_to_dict(solutions: Solutions) -> dict[str, Any]:
    """JSON-able form: ``{"solutions": [{"pose", "residual", "hits"}], "starts", "time_s", ...}``."""
    return {
        "solutions": [{"pose": {k: float(v) for k, v in s.pose.items()}, "residual": float(s.residual),
                       "hits": int(s.hits)} for s in solutions],
        "starts": int(getattr(solutions, "starts", 0)),
        "time_s": float(getattr(solutions, "time_s", 0.0)),
        "outside": int(getattr(solutions, "outside", 0)),
        "history": [list(h) for h in getattr(solutions, "history", [])],
    }


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


def _rotation_from_quaternion(w, x, y, z):
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], -2)


def _zyx_matrix(a, b, g):
    """(n, 3, 3) Z-Y-X Euler matrix, angles in radians (same convention as fkopt.numerics.rotations.zyx)."""
    ca, sa, cb, sb, cg, sg = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(g), np.sin(g)
    return np.stack([
        np.stack([cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa], -1),
        np.stack([sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa], -1),
        np.stack([-sb, cb * sa, cb * ca], -1)], -2)


def _zyx_angles(R):
    """Z-Y-X Euler angles (degrees, beta in [-90, 90]) of (n, 3, 3) rotation matrices."""
    beta = np.arctan2(-R[:, 2, 0], np.hypot(R[:, 0, 0], R[:, 1, 0]))
    alpha = np.arctan2(R[:, 2, 1], R[:, 2, 2])
    gamma = np.arctan2(R[:, 1, 0], R[:, 0, 0])
    return np.degrees(np.stack([alpha, beta, gamma], -1))


def _rotate(w, R):
    """exp([w]x) R for rotation vectors w (n, 3) and row-major matrices R (n, 9), elementwise
    (Rodrigues: exp([w]x) = I + a [w]x + b [w]x^2 with [w]x^2 = w w^T - |w|^2 I)."""
    w0, w1, w2 = w[:, 0], w[:, 1], w[:, 2]
    th2 = w0 * w0 + w1 * w1 + w2 * w2
    small = th2 < 1e-8
    th = np.sqrt(np.where(small, 1.0, th2))
    a = np.where(small, 1.0 - th2 / 6.0, np.sin(th) / th)
    b = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(th)) / (th * th))
    d = 1.0 - b * th2
    bw0, bw1, bw2 = b * w0, b * w1, b * w2
    aw0, aw1, aw2 = a * w0, a * w1, a * w2
    E = ((bw0 * w0 + d, bw0 * w1 - aw2, bw0 * w2 + aw1),
         (bw1 * w0 + aw2, bw1 * w1 + d, bw1 * w2 - aw0),
         (bw2 * w0 - aw1, bw2 * w1 + aw0, bw2 * w2 + d))
    out = np.empty((len(w), 9))
    for k in range(3):
        for j in range(3):
            out[:, 3 * k + j] = E[k][0] * R[:, j] + E[k][1] * R[:, 3 + j] + E[k][2] * R[:, 6 + j]
    return out


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
            R = _rotation_from_quaternion(a * np.sin(u2), a * np.cos(u2), b * np.sin(u3), b * np.cos(u3))
        else:
            lo, hi = self.angle_bounds[:, 0], self.angle_bounds[:, 1]
            e = lo + (hi - lo) * u
            R = _zyx_matrix(e[:, 0], e[:, 1], e[:, 2])
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
        out[:, 3:] = _rotate(dx[:, 3:], S[:, 3:])
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
        return np.concatenate([S[:, :3], _zyx_angles(R)], axis=1)

    def from_poses(self, X):
        a = np.radians(X[:, 3:6])
        R = _zyx_matrix(a[:, 0], a[:, 1], a[:, 2])
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
    from fkopt.mechanisms.sps6 import SixSPS
    if isinstance(mechanism, SixSPS):
        if np.any(joints <= 0):
            raise FkoptError(f"{mechanism.name} joints: leg lengths must be positive, got {joints.tolist()}")
        return _SixSPSModel(mechanism, joints)
    return _GenericModel(mechanism, joints)


def pose_distance(mechanism: ParallelMechanism, a, b) -> np.ndarray:
    """Distance between poses ``a`` and ``b`` (..., dim) as :func:`all_solutions` dedupes them.

    Max norm in the normalised pose space: length variables divided by their bounds width,
    angles in radians modulo 2 pi (through cos and sin), and for 6-SPS the rotation compared
    by its matrix entries, so Euler-equivalent poses are at distance ~0.
    """
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    shape = a.shape[:-1]
    A, B = a.reshape(-1, a.shape[-1]), b.reshape(-1, b.shape[-1])
    model = _model_for(mechanism, np.atleast_1d(mechanism.ik(A[0])))
    ka, kb = model.keys(model.from_poses(A)), model.keys(model.from_poses(B))
    return np.abs(ka - kb).max(-1).reshape(shape)


def all_solutions(mechanism: ParallelMechanism, joints, *, starts: int | None = None, seed: int = 0,
                  tol: float = 1e-9, dedup: float = 1e-6, round_size: int | None = None,
                  patience: int = 1, min_starts: int | None = None, max_starts: int = 200_000,
                  iterations: int = 60, maximum: int | None = None, pool: int | None = 512,
                  line_search: bool | None = None, capture: tuple[float, float] | None = (1e-4, 1e-3), qmc: bool = True) -> Solutions:
    """Every distinct real forward solution of ``mechanism`` for ``joints`` inside its bounds.

    ``starts``: run exactly this many starts (one round); by default rounds of ``round_size``
    starts (2000 for 6-SPS, 200 otherwise) run until ``patience`` consecutive rounds add no
    solution, after at least ``min_starts`` (default 2 rounds) and at most ``max_starts``.
    ``tol``: accepted residual, ``max_i |ik(pose)_i - joints_i| / max(1, |joints_i|)``.
    ``dedup``: duplicate tolerance in the normalised pose space (see the module docstring).
    ``seed``: the start stream (``RunStreams(seed, [0])``); same seed, same answer.
    ``line_search``: backtrack Newton steps until the squared residual decreases (default: yes,
    except for 6-SPS, whose plain capped Newton steps reach the rarest basins more often; see
    the module docstring). ``pool``: most starts iterated at once within a round (finished ones are replaced by the
    round's next starts, so the search can stop mid-round; None: the whole round at once).
    ``capture``: (residual, distance) under which a start is counted as a hit of a known
    solution and stopped (module docstring). ``qmc``: starts from a randomly shifted Kronecker
    sequence (default) rather than independent uniforms.
    ``maximum``: the most assembly modes the mechanism can have; the search stops as soon as
    that many distinct real solutions (inside or outside the bounds) are found, since no more
    can exist. Default 40 for a 6-SPS platform (the number of complex solutions of the general
    6-6 Stewart-Gough platform: Raghavan 1993, Ronga & Vust 1995), none otherwise.
    """
    if not isinstance(mechanism, ParallelMechanism):
        raise FkoptError(f"all_solutions needs a parallel mechanism; '{mechanism.name}' is {mechanism.kind}")
    joints = mechanism.as_values(joints, mechanism.joint_names, "joints")
    if len(mechanism.joint_names) != len(mechanism.pose_names):
        raise FkoptError(f"all_solutions needs as many joints as pose variables; {mechanism.name} has "
                         f"{len(mechanism.joint_names)} and {len(mechanism.pose_names)}")
    for name, value in (("tol", tol), ("dedup", dedup)):
        if not value > 0:
            raise FkoptError(f"all_solutions {name}: must be positive, got {value}")
    if starts is not None and int(starts) < 1:
        raise FkoptError(f"all_solutions starts: must be at least 1, got {starts}")

    t0 = time.perf_counter()
    model = _model_for(mechanism, joints)
    triple = (3, 4, 5) if isinstance(model, _SixSPSModel) else _euler_triple(mechanism)
    if starts is not None:
        size, limit, need = int(starts), int(starts), int(starts)
    else:
        size = int(round_size or (2000 if isinstance(model, _SixSPSModel) else 200))
        limit, need = int(max_starts), int(min_starts if min_starts is not None else 2 * size)
    streams = RunStreams(seed, [0])
    cap = maximum if maximum is not None else (40 if isinstance(model, _SixSPSModel) else None)
    search = (not isinstance(model, _SixSPSModel)) if line_search is None else bool(line_search)
    jscale = np.maximum(1.0, np.abs(joints))
    ftol = 1e-3 * tol * float(jscale.min())           # Newton's own stop, well below the acceptance

    problem = FKProblem(mechanism, joints)
    rep_keys: list[np.ndarray] = []                   # one key per distinct solution found
    hits: list[int] = []
    # (pose in bounds, residual, polished onto a bound), None: outside, False: merged duplicate
    found: list[tuple[np.ndarray, float, bool] | None | bool] = []
    unchecked: list[np.ndarray] = []                  # states of new solutions not checked yet
    history: list[tuple[int, float, int]] = []
    used, quiet = 0, 0
    known = [np.empty((0, 0))]                        # rep_keys as one array, rebuilt when it grows

    def known_keys():
        if len(known[0]) != len(rep_keys):
            known[0] = np.array(rep_keys)
        return known[0]

    def add(S):
        """Deduplicate converged states S against the solutions known so far and each other."""
        good = (np.abs(model.residual(S)) / jscale <= tol).all(-1)
        S = S[good]
        if not len(S):
            return
        keys = model.keys(S)
        if hits:                                      # known solutions (mutually > dedup apart)
            dist = np.abs(keys[:, None, :] - known_keys()[None]).max(-1)
            near = dist.min(-1) <= dedup
            for i in dist[near].argmin(-1).tolist():
                hits[i] += 1
            S, keys = S[~near], keys[~near]
            if not len(S):
                return
        labels = _cluster(keys, dedup)
        for lab in range(int(labels.max()) + 1):
            members = np.flatnonzero(labels == lab)
            rep_keys.append(keys[members[0]])
            hits.append(len(members))
            unchecked.append(S[members[0]])           # checked once per round (settle)

    def settle():
        """Check the round's new solutions (pose in the bounds, residual) in one call."""
        if unchecked:
            first = len(found)
            found.extend(_check_many(mechanism, problem, model.poses(np.array(unchecked)), triple, jscale, tol))
            unchecked.clear()
            # A root polished onto a bound may be one found inside already: merge it there.
            for i in range(first, len(found)):
                if found[i] is not None and found[i][2]:
                    key = model.keys(model.from_poses(found[i][0][None]))[0]
                    for j, fj in enumerate(found):
                        if j != i and fj and np.abs(model.keys(model.from_poses(fj[0][None]))[0] - key).max() <= dedup:
                            hits[j] += hits[i]
                            found[i] = False       # a duplicate: neither a solution nor outside
                            break

    def report(rows, S):
        add(S)
        return cap is not None and len(hits) >= cap   # every assembly mode is found

    cap_f2 = (capture[0] * float(jscale.min())) ** 2 if capture else 0.0

    def captured(S, F, open_):
        """Open rows near convergence (residual <= capture[0]) within capture[1] of a known solution."""
        if not hits:
            return None
        cand = np.flatnonzero((F <= cap_f2) & open_)
        if not len(cand):
            return None
        keys, known_ = model.keys(S[cand]), known_keys()
        # the known solution nearest in the first three key coordinates (position for 6-SPS),
        # then the full distance to that one only (a row it misses just runs to convergence)
        j = np.abs(keys[:, None, :3] - known_[None, :, :3]).max(-1).argmin(-1)
        near = np.abs(keys - known_[j]).max(-1) <= capture[1]
        for i in j[near].tolist():
            hits[i] += 1
        return cand[near]

    shift = None
    while used < limit:
        n = min(size, limit - used)
        if qmc:
            if shift is None:
                shift = streams.uniform(1, model.draws)[0][0]
            S0 = model.starts(_kronecker(shift, used, n, model.draws))
        else:
            S0 = model.starts(streams.uniform(n, model.draws)[0])
        inside_before = sum(bool(f) for f in found)
        with np.errstate(all="ignore"):                 # diverging starts may overflow
            _, _, started = _newton(model, S0, ftol=ftol, iterations=iterations, pool=pool, report=report,
                                    line_search=search, capture=captured if capture else None)
        used += started
        settle()
        inside = sum(bool(f) for f in found)
        history.append((used, time.perf_counter() - t0, inside))
        quiet = quiet + 1 if inside == inside_before else 0
        if used >= need and quiet >= patience:
            break
        if cap is not None and len(found) >= cap:     # every assembly mode is found
            break

    out = Solutions(sorted((Solution(pose=dict(zip(mechanism.pose_names, map(float, f[0]))), residual=f[1], hits=h)
                            for f, h in zip(found, hits) if f), key=lambda s: -s.hits))
    out.names = tuple(mechanism.pose_names)
    out.outside = sum(f is None for f in found)
    out.starts = used
    out.time_s = time.perf_counter() - t0
    out.history = history
    out.settings = dict(seed=seed, tol=tol, dedup=dedup, round_size=size, patience=patience,
                        iterations=iterations, maximum=cap, pool=pool, line_search=search)
    return out


def _check_many(mechanism, problem, X, triple, jscale, tol):
    """(pose moved into the bounds, residual, on_bound) of each converged row of X (k, dim), or
    None if it is outside or inexact; residuals in one call of the inverse map.

    A row that no move by 360 deg (or the Euler equivalence) brings into the bounds is clipped
    into them and polished there (:func:`_polish_on_bounds`), and kept (``on_bound`` True) if
    the polished pose has a residual within ``tol``: by definition a solution in the bounds.
    This is a root on a bound that Newton's stop left slightly past it (a double root converges
    linearly and stops within ``tol`` some 1e-6 beyond). A solution genuinely outside keeps a
    residual of the order of its distance to the bounds and stays outside."""
    moved = [_into_bounds(mechanism, x, triple) for x in X]
    out: list = [None] * len(X)
    inb = [i for i, xb in enumerate(moved) if xb is not None]
    if inb:
        r = np.abs(problem.residuals(np.array([moved[i] for i in inb])))
        for i, ri in zip(inb, r):
            if (ri / jscale <= tol).all():
                out[i] = (moved[i], float(ri.max()), False)
    rows, clipped = [], []
    for i, xb in enumerate(moved):
        if xb is None:
            for c in _clipped_into_bounds(mechanism, X[i], triple):
                rows.append(i)
                clipped.append(c)
    if clipped:
        C = _polish_on_bounds(mechanism, problem, np.array(clipped))
        r = np.abs(problem.residuals(C))
        for i, c, ri in zip(rows, C, r):
            if out[i] is None and (ri / jscale <= tol).all():
                out[i] = (c, float(ri.max()), True)
    return out


def _polish_on_bounds(mechanism, problem, X, steps: int = 8):
    """Gauss-Newton in the pose variables with the variables at a bound held there (rows X
    (k, dim) clipped into the bounds; a variable a step pushes out is clipped and held too)."""
    lo, hi = mechanism.bounds[:, 0], mechanism.bounds[:, 1]
    h = 1e-7 * (hi - lo)
    X = np.array(X, dtype=float)
    for _ in range(steps):
        held = (X <= lo) | (X >= hi)
        r = problem.residuals(X)
        if problem.has_jacobian:
            J = problem.jacobian(X)
        else:                                      # central differences, as _GenericModel
            E = np.eye(X.shape[1]) * h
            J = np.stack([(problem.residuals(X + e) - problem.residuals(X - e)) / (2 * hk)
                          for e, hk in zip(E, h)], axis=-1)
        J = np.where(held[:, None, :], 0.0, J)
        with np.errstate(all="ignore"):
            dx = -np.einsum("nij,nj->ni", np.linalg.pinv(J), r)
        if not np.isfinite(dx).all():
            break
        X = np.clip(X + dx, lo, hi)
        if (np.abs(dx) <= 1e-15 * (hi - lo)).all():
            break
    return X


#: How far past a bound (fraction of its width) a converged pose is clipped and polished back:
#: a double root stops ~1e-8 of the width past it, a triple one ~1e-4 (the pose error of a
#: k-fold root is ~ (Newton's stopping residual)^(1/k)); farther is a solution outside.
_BOUND_SLACK = 1e-3


def _clipped_into_bounds(mechanism: Mechanism, x: np.ndarray, triple) -> list[np.ndarray]:
    """The pose x clipped into the bounds, once per Euler representative (plain, then the
    equivalent triple), each angle first moved by multiples of 360 deg next to the bounds;
    representatives more than ``_BOUND_SLACK`` of a width outside are left out."""
    lo, hi = mechanism.bounds[:, 0], mechanism.bounds[:, 1]
    angle = np.flatnonzero(mechanism.angle_mask(mechanism.pose_units))
    x = np.array(x, dtype=float)
    candidates = [x]
    if triple is not None:
        a, b, g = triple
        alt = x.copy()
        alt[a] += 180.0
        alt[b] = 180.0 - alt[b]
        alt[g] += 180.0
        candidates.append(alt)
    out = []
    for c in candidates:
        c = c.copy()
        for i in angle:
            v = lo[i] + (c[i] - lo[i]) % 360.0           # smallest representative >= lo
            c[i] = v if v - hi[i] <= lo[i] - (v - 360.0) else v - 360.0   # the nearer side
        inside = np.clip(c, lo, hi)
        if (np.abs(inside - c) <= _BOUND_SLACK * (hi - lo)).all():
            out.append(inside)
    return out
