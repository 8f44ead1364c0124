"""Practical exact solvers: ``fkopt.forward`` (parallel mechanisms) and ``fkopt.inverse`` (serial arms).

:func:`fkopt.solve` is the optimiser-level API (runs, populations, convergence histories) used
to compare algorithms. These two functions are the domain-level API: give joints (or poses),
batched over any leading axes, get poses (or joints) back with a verdict per row.

**forward(mechanism, joints[..., m])** -- the pose whose closed-form inverse map gives ``joints``.

1. Local stage, vectorised over all rows (no per-row Python loop): damped Newton on
   r(x) = ik(x) - joints with the mechanism's analytic Jacobian (``ik_jacobian``; central
   differences for a mechanism without one), from ``start`` or the centre of the bounds. A step
   that does not decrease |r|^2 is halved (up to 10 times); steps are capped at a quarter of the
   box width per coordinate. At most 30 iterations. A single row takes the same iteration with
   scalar tests (its cost is numpy's per-call overhead), on Python floats throughout when the
   mechanism has ``ik_jacobian1`` (6-SPS: the same formulas per leg) and a 6x6 Gaussian
   elimination with partial pivoting.
2. Rows not solved restart the same Newton from a start table's poses nearest in joint space
   (as inverse's table, turned round for a parallel mechanism: ``table`` poses drawn uniformly in
   the bounds by a fixed hash, their joints by the closed-form inverse map, compared by the joints
   each divided by its spread over the table, nearest found exactly as inverse's (brute force
   below 32 rows, scipy's k-d tree from 32 on); :func:`_forward_table`, built once per mechanism
   geometry). A row takes ``neighbours`` of them, nearest first: the first ``candidates`` all
   run and the row keeps the likeliest of their solutions, the one with the smallest Jacobian
   volume (for a pose drawn uniformly in the bounds, mode i generated the joints with
   probability proportional to 1 / |det J(x_i)|, :func:`_jacobian_volume`); when none of them
   solves, the rest one after another until one does. Then a few deterministic starts: the centre
   moved by +-1/4 of the box width along each coordinate (2 n starts), all rows at once.
   Rows the start solves have the same answers with or without the table (``table=0`` is the
   solver before it); what the table buys on Dietmaier's platform is measured in
   docs/performance.md and docs/python-api.md.
3. Rows still not solved go to a seeded global search, one row at a time: ``gabc+lm``
   (population 20, 300 iterations, seed ``seed``, run id = row index) through :func:`fkopt.solve`.

**inverse(arm, poses[..., 6])** -- joints whose end-effector pose is ``poses`` (x, y, z in the
arm's length unit, Z-Y-Z Euler angles in degrees as :meth:`DHArm.fk` prints them), every joint
inside its limits, for any frame arm (DH tables and URDF chains alike: the solver uses the arm's
frame, frame Jacobian and periodic joints only). Internally angles are in radians and lengths
(prismatic joints) in the arm's unit; continuous (periodic) joints are not saturated and the
answer is wrapped into [-180, 180). ``mask`` selects task components (position only, ...);
``start`` as the current joints gives the locally nearest solution (see :func:`inverse`).
A bounded damped least-squares method on the 6 residuals (position error, L * rotation vector
of R R_t^T with L = ``orientation_scale`` length units per radian, default the arm's reach; the
geodesic orientation error, no Euler differences):

* step d = J^T (J J^T + mu I)^{-1} (-r) (minimum-norm damped least squares for a redundant
  arm), mu = lambda * trace(J J^T) / 6 with lambda adapted per candidate as in
  Levenberg-Marquardt (start ``damping`` = 0.01, x ``down`` = 0.1 after a step that decreases
  |r|^2, x ``up`` = 10 otherwise); the joint step is capped at ``step_cap`` radians; the
  orientation rows use the angular velocity (the derivative of the rotation vector at zero
  error; ``exact_rotation=True`` applies the inverse left Jacobian of SO(3) -- measured: the
  same number of Jacobian evaluations on 1000 random poses, so the cheaper one is the default);
* joint limits handled by the method (saturation in the null space, as in Flacco, De Luca,
  Khatib 2012, "Motion control of redundant robots under joint constraints: saturation in the
  null space"): a joint whose step would leave its range is fixed at the limit, its column
  removed, and the remaining joints re-solved for the residual left over (up to 3 passes) -- the
  redundancy absorbs the saturation instead of the step being clipped;
* optional secondary objective in the null space of the task, ``rest`` > 0: pull every joint
  towards mid-range, d += (I - J^+ J) z with z = g rest (mid - q) / half-range^2, J^+ the
  pseudo-inverse (damped by 1e-9 trace(J J^T) / 6) and g = min(1, |r|) fading the pull below
  1 length unit of residual, so that a finite null-space step does not keep the task from
  converging (off by default);
* starts from a table: ``table`` (4096) joint configurations drawn uniformly inside the limits
  by a fixed hash (not the seed), compared by their tool position and reach / (3 sqrt 2) times
  their rotation matrix entries (1 rad weighs about a third of the reach), nearest found
  exactly (brute force below 32 rows, scipy's k-d tree from 32 rows on); a row's starts are ``start`` (when given), then the table's configurations nearest to
  its target (``starts`` of them plus ``neighbours`` (32) more for restarts), then seeded random draws
  inside the limits from a counter-based hash of (seed, row index, draw number). Measured on
  1000 random reachable poses: about 80 % of nearest-configuration starts converge against
  about 60 % of mid-range or random ones, which is why the hardest rows of a batch try 32 table
  neighbours before the random draws (measured in the commit that chose it; docs/performance.md);
* one pose (N = 1, ``rest`` = 0, no ``exact_rotation``) runs the same iteration on Python
  floats (the arm's ``frame_jacobian1``, Cholesky solves of the 6x6 systems), its candidates
  one after another in the order of its starts, stopping at the first that converges: numpy's
  per-call overhead is most of the cost of the batched loop on a few rows;
* restarts: a candidate that has not converged after ``iterations`` (10) steps, or stalls
  (lambda above 1e6), restarts in place from its row's next start, at most ``restarts`` times
  per row; a solved row retires all its candidates at once. A batch of N < ``fill`` (32) rows
  starts with ``fill // N`` candidates per row side by side, and whenever fewer than ``tail``
  (256) candidates remain, every unsolved row gets more at once (the last hard rows then try
  many starts per iteration instead of a few per iteration for many iterations: in a batch
  the time of the last iterations is numpy's per-call overhead, whatever their few rows). These restarts are inverse's global
  stage (restarts of a local method with limits, rather than a swarm). Same poses and seed give
  the same answer; a row's answer may differ between batches.

**Verdicts.** ``solved`` is true only when the closed form of the answer reproduces the input
within ``tol`` and the answer is inside the bounds: forward, max |ik(pose) - joints| <= ``tol``
(joint units; default 1e-9) and the pose inside ``mechanism.bounds`` (angles may be moved by
multiples of 360 deg); any assembly mode that does so is a solution. The residual is the one
the Newton loop evaluated at the answer with ``ik_jacobian`` (the same closed form; a row whose
angles were moved into the bounds is evaluated again with ``ik``). Inverse, distance between
fk(joints) and the target position <= ``tol[0]`` (length unit; default 1e-6) and geodesic angle
<= ``tol[1]`` (radians; default 1e-6), every joint inside its limits, evaluated with the arm's
elementwise :meth:`DHArm.frame` (the numbers of ``fk``; for a single pose the same DH
recursion on Python floats, :meth:`DHArm.frame_jacobian1`, equal to ~1e-13), not with the
solver's products.

**Evaluations** are counted per row and separately: ``evaluations["residual"]`` counts
evaluations of the closed form (the inverse map for forward, the arm's forward map for inverse),
``evaluations["jacobian"]`` evaluations of its analytic Jacobian (each also yields the closed
form at the same point: one call of ``ik_jacobian``/``frame_jacobian`` counts one of each). A
mechanism without analytic Jacobian is differentiated by central differences, counted as
2 n residual evaluations and no Jacobian evaluation. The global stage of forward adds
:attr:`fkopt.Result.evaluations` of its run (swarm fitness evaluations plus LM's, an analytic
Jacobian counted as one) to ``residual``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fkopt.algorithms.hybrid import GABCLM
from fkopt.api_bounds import MAX_API_VALUE, MAX_SEED, check_array, check_integer, check_options
from fkopt.errors import FkoptError, did_you_mean
from fkopt.mechanisms.base import Mechanism, ParallelMechanism, SerialMechanism
from fkopt.mechanisms.catalog import MECHANISMS
from fkopt.numerics import path as numerics_path
from fkopt.numerics.options import InverseOptions
from fkopt.numerics.damped_least_squares import inverse_candidates, rotation_error1
from fkopt.problems import fk_problem, so3_right_jacobian_inverse
from fkopt.algorithms.runs import solve

#: Default forward tolerance: max |ik(pose) - joints| in the joint units.
FORWARD_TOL = 1e-9
#: Default inverse tolerances: (position in the arm's length unit, orientation in radians).
INVERSE_TOL = (1e-6, 1e-6)
#: The swarm budget of one pose: fkopt.forward's global stage (gabc+lm) and a forward solve by a
#: named algorithm (:func:`fkopt.kinematics.by_algorithm.forward_by`, ``fkopt fk --algorithm``).
FORWARD_SWARM = {"population": 20, "iterations": 300}
#: forward's start table: poses of the bounds and their joints (see :func:`forward`).
FORWARD_TABLE = 4096
#: Start-table poses nearest to the joints that a row not solved from its start tries.
FORWARD_NEIGHBOURS = 16
#: Of those, how many all run before a row keeps the likeliest of their solutions.
FORWARD_CANDIDATES = 8
#: The budget of one IK pose by a named algorithm (:func:`fkopt.kinematics.by_algorithm.inverse_by`).
INVERSE_SWARM = {"population": 50, "iterations": 500}


@dataclass
class ForwardResult:
    """Poses found by :func:`forward`, shaped like the input's leading axes.

    ``pose`` (..., n) in the mechanism's pose units (NaN-free: the best point found when not
    solved); ``residual`` (...) max |ik(pose) - joints| in joint units; ``solved`` (...) bool;
    ``stage`` (...) 0 local Newton, 1 deterministic restarts, 2 global search, -1 not solved;
    ``evaluations`` {"residual": (...), "jacobian": (...)} per row (see the module docstring).
    """

    mechanism: str
    names: tuple[str, ...]
    units: tuple[str, ...]
    pose: np.ndarray
    residual: np.ndarray
    solved: np.ndarray
    stage: np.ndarray
    evaluations: dict[str, np.ndarray] = field(default_factory=dict)
    tol: float = FORWARD_TOL

    def as_dict(self, index=()) -> dict:
        """One row (``index`` into the leading axes) as plain Python values."""
        return {"pose": dict(zip(self.names, map(float, self.pose[index]))),
                "residual": float(self.residual[index]), "solved": bool(self.solved[index]),
                "stage": int(self.stage[index]),
                "evaluations": {k: int(v[index]) for k, v in self.evaluations.items()}}


@dataclass
class InverseResult:
    """Joints found by :func:`inverse`, shaped like the input's leading axes.

    ``joints`` (..., n) degrees, always inside the limits; ``position_error`` (...) in the arm's
    length unit and ``rotation_error`` (...) geodesic, radians, of fk(joints) against the target;
    ``residual`` (...) max of the two errors measured in their tolerances' units
    (max(position_error / tol[0], rotation_error / tol[1]) <= 1 means solved);
    ``solved`` (...) bool; ``restarts`` (...) random restarts used;
    ``evaluations`` {"residual": (...), "jacobian": (...)} per row.
    """

    mechanism: str
    names: tuple[str, ...]
    joints: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    residual: np.ndarray
    solved: np.ndarray
    restarts: np.ndarray
    evaluations: dict[str, np.ndarray] = field(default_factory=dict)
    tol: tuple[float, float] = INVERSE_TOL

    def as_dict(self, index=()) -> dict:
        return {"joints": dict(zip(self.names, map(float, self.joints[index]))),
                "position_error": float(self.position_error[index]),
                "rotation_error_rad": float(self.rotation_error[index]),
                "solved": bool(self.solved[index]), "restarts": int(self.restarts[index]),
                "evaluations": {k: int(v[index]) for k, v in self.evaluations.items()}}


def _mechanism(mechanism, kind: type, what: str) -> Mechanism:
    if isinstance(mechanism, str):
        if mechanism not in MECHANISMS:
            raise FkoptError(f"unknown mechanism '{mechanism}'; allowed: {did_you_mean(mechanism, list(MECHANISMS))} "
                             "(a plug-in: pass fkopt.mechanism(name))")
        mechanism = MECHANISMS[mechanism]()
    if not isinstance(mechanism, Mechanism):           # None, a number, a path: one line, not AttributeError
        raise FkoptError(f"{what}: expected a registered mechanism name or a mechanism object, got "
                         f"{type(mechanism).__name__}")
    if not isinstance(mechanism, kind):
        other = "inverse" if what == "forward" else "forward"
        raise FkoptError(f"{what} needs a {'parallel mechanism' if kind is ParallelMechanism else 'serial arm'}; "
                         f"'{mechanism.name}' is {mechanism.kind} (use fkopt.{other})")
    return mechanism


#: A target frame's rotation may be this far from orthonormal (max |R R^T - I|).
FRAME_ORTHONORMAL_TOL = 1e-9


def _targets(m, poses) -> np.ndarray:
    """Targets of :func:`inverse` as rows: poses (..., 6) as they are, tip frames (..., 4, 4) as
    (..., 12) = (x, y, z, R row-major); a frame needs a finite, orthonormal rotation and the
    last row (0, 0, 0, 1)."""
    try:
        a = np.asarray(poses)
        if a.dtype != np.float64 or a.size == 0:      # complex, text, empty: api_bounds says why in one line
            a = check_array(a, f"{m.name} target pose")
    except (TypeError, ValueError):
        raise FkoptError(f"{m.name} target pose: expected numbers, (..., {len(m.pose_names)}) values "
                         f"({', '.join(m.pose_names)}) or (..., 4, 4) tip frames; got {type(poses).__name__}") from None
    if a.ndim < 2 or a.shape[-2:] != (4, 4):
        return _values(m, a, m.pose_names, "target pose")
    if a.ndim == 2:                                    # one frame: the same checks on floats (a few µs less)
        f = a.ravel().tolist()
        a0, a1, a2, x, b0, b1, b2, y, c0, c1, c2, z = f[:12]
        gap = max(abs(a0 * a0 + a1 * a1 + a2 * a2 - 1.0), abs(b0 * b0 + b1 * b1 + b2 * b2 - 1.0),
                  abs(c0 * c0 + c1 * c1 + c2 * c2 - 1.0), abs(a0 * b0 + a1 * b1 + a2 * b2),
                  abs(a0 * c0 + a1 * c1 + a2 * c2), abs(b0 * c0 + b1 * c1 + b2 * c2))
        if abs(x) + abs(y) + abs(z) <= MAX_API_VALUE and gap <= FRAME_ORTHONORMAL_TOL \
                and f[12:] == [0.0, 0.0, 0.0, 1.0]:
            return np.array([x, y, z, a0, a1, a2, b0, b1, b2, c0, c1, c2])
    if not (np.abs(a) <= MAX_API_VALUE).all():
        raise FkoptError(f"{m.name} target frame: values must be finite and within +-{MAX_API_VALUE:g}")
    R = a[..., :3, :3]
    gap = np.abs(R @ np.swapaxes(R, -1, -2) - np.eye(3)).max()
    if not gap <= FRAME_ORTHONORMAL_TOL or not (a[..., 3, :] == (0.0, 0.0, 0.0, 1.0)).all():
        raise FkoptError(f"{m.name} target frame: needs an orthonormal rotation (max |R R^T - I| "
                         f"<= {FRAME_ORTHONORMAL_TOL:g}, got {gap:.3g}) and last row 0 0 0 1")
    return np.concatenate([a[..., :3, 3], R.reshape(a.shape[:-2] + (9,))], axis=-1)


def _values(mechanism: Mechanism, values, names, what: str) -> np.ndarray:
    if isinstance(values, np.ndarray) and values.dtype == np.float64 and values.shape == (len(names),):
        row = values.tolist()          # a control loop's call: one real row, checked on Python floats
        if math.isfinite(sum(row)) and max(map(abs, row)) <= MAX_API_VALUE:
            return values
    a = check_array(values, f"{mechanism.name} {what}")        # real, not empty, |v| <= 1e9
    if a.ndim == 0 or a.shape[-1] != len(names):
        raise FkoptError(f"{mechanism.name} {what}: expected (..., {len(names)}) values "
                         f"({', '.join(names)}), got shape {a.shape}")
    bad = ~np.isfinite(a).all(axis=-1)
    if bad.any():
        row = a.reshape(-1, len(names))[int(np.flatnonzero(bad.ravel())[0])]
        raise FkoptError(f"{mechanism.name} {what}: values must be finite, got {row.tolist()}")
    return a


# ----------------------------------------------------------------------------------------------
# forward
# ----------------------------------------------------------------------------------------------
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


def _sumsq(r):
    return np.einsum("...i,...i->...", r, r)


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


def forward(mechanism, joints, *, start=None, tol: float = FORWARD_TOL, seed: int = 0,
            global_search: bool = True, table: int = FORWARD_TABLE,
            neighbours: int = FORWARD_NEIGHBOURS, candidates: int = FORWARD_CANDIDATES) -> ForwardResult:
    """Forward kinematics of a parallel mechanism for joints (..., m), batched over leading axes.

    ``mechanism``: a registered name or a :class:`ParallelMechanism`. ``start``: start pose(s)
    (n,) or (..., n) (default: centre of the bounds). ``tol``: largest accepted
    max |ik(pose) - joints|, joint units. ``seed``: the global stage's seed.
    ``global_search=False`` stops after the deterministic starts. ``table``: size of the start
    table (poses of the bounds and their joints, :func:`_forward_table`; 0: none, the behaviour
    before it); ``neighbours``: how many of its poses nearest to the joints a row not solved from
    ``start`` tries before the deterministic restarts; ``candidates``: how many of those (nearest
    first) all run, the row keeping the likeliest of their solutions (smallest Jacobian volume,
    :func:`_jacobian_volume`; 1: the first that solves). See the module docstring.
    """
    m = _mechanism(mechanism, ParallelMechanism, "forward")
    opts = check_options("forward", tol=tol, seed=seed, table=table, neighbours=neighbours, candidates=candidates)
    tol, seed, table, neighbours, candidates = (opts[k] for k in ("tol", "seed", "table", "neighbours", "candidates"))
    J0 = _values(m, joints, m.joint_names, "joints")
    shape = J0.shape[:-1]
    L = J0.reshape(-1, J0.shape[-1])
    N, n = len(L), len(m.pose_names)
    bounds = m.bounds
    centre = bounds.mean(axis=1)
    if start is None:
        x0 = np.broadcast_to(centre, (N, n))
    else:
        s = _values(m, start, m.pose_names, "start")
        x0 = np.broadcast_to(s, shape + (n,)).reshape(N, n)
    res = _Residuals(m, L)
    evals = (np.zeros(N, dtype=np.int64), np.zeros(N, dtype=np.int64))
    ftol = 0.01 * tol
    all_rows = np.arange(N)
    scalar = N == 1 and hasattr(m, "ik_jacobian1") and not res.angle.any()

    def local(s0, rows):
        """Newton from starts s0 on rows of L (scalar, one row or a batch), verified."""
        got = _newton_scalar(m, s0[0], L[rows[0]], ftol, evals) if scalar else None
        if got is not None:
            xs, rs = got
        elif N == 1:
            xs, rs = _newton1(res, np.array(s0[0], dtype=float), ftol, evals)
        else:
            xs, rs = _newton(res, s0, rows, ftol, evals)
        return _verify(m, L[rows], xs, rs, tol)

    with np.errstate(all="ignore"):
        x, resid, solved = local(x0, all_rows)
        stage = np.where(solved, 0, -1)
        todo = np.flatnonzero(~solved)
        if len(todo) and table and neighbours:          # the start table's poses nearest in joint space
            tab = _forward_table(m, int(table))
            k = min(int(neighbours), len(tab["pose"]))     # 0 when no table pose had finite joints
            first = min(max(int(candidates), 1), k)
            near = _nearest(tab, _joint_features(tab, L[todo]), k) if k else np.zeros((len(todo), 0), np.intp)
            # the first `candidates` starts all run; a row keeps its likeliest solution among them
            kept = np.full(len(todo), np.inf)             # the kept solution's Jacobian volume
            for j in range(first):
                xs, rs, ok = local(tab["pose"][near[:, j]], todo)
                vol = np.full(len(todo), np.inf)
                if ok.any():
                    vol[ok] = _jacobian_volume(res, xs[ok], todo[ok], evals)
                take = ok & (vol < kept)                  # ties: the nearer start's
                take |= ~solved[todo] & ~ok & (rs < resid[todo])
                x[todo[take]], resid[todo[take]] = xs[take], rs[take]
                kept = np.where(take & ok, vol, kept)
                solved[todo[ok]] = True
                stage[todo[ok]] = 1
            left = ~solved[todo]
            todo, near = todo[left], near[left]
            for j in range(first, k):                     # then one after another until one solves
                if not len(todo):
                    break
                xs, rs, ok = local(tab["pose"][near[:, j]], todo)
                better = ok | (rs < resid[todo])
                x[todo[better]], resid[todo[better]] = xs[better], rs[better]
                solved[todo[ok]] = True
                stage[todo[ok]] = 1
                todo, near = todo[~ok], near[~ok]
        if len(todo):                                   # deterministic restarts
            quarter = 0.25 * (bounds[:, 1] - bounds[:, 0])
            starts = np.concatenate([centre + np.diag(quarter), centre - np.diag(quarter)])
            for s in starts:
                if not len(todo):
                    break
                xs, rs = _newton(res, np.broadcast_to(s, (len(todo), n)), todo, ftol, evals)
                xs, rs, ok = _verify(m, L[todo], xs, rs, tol)
                better = ok | (~solved[todo] & (rs < resid[todo]))
                x[todo[better]], resid[todo[better]] = xs[better], rs[better]
                solved[todo[ok]] = True
                stage[todo[ok]] = 1
                todo = todo[~ok]
    if global_search and len(todo):
        for k in todo:
            problem = fk_problem(m, L[k])
            out = solve(problem, GABCLM(), **FORWARD_SWARM, runs=1, seed=seed, run_ids=[int(k)])
            evals[0][k] += int(out.evaluations[0])
            xs = out.x[:1]
            rs = np.abs(problem.residuals(xs)).max(axis=-1)
            xs, rs, ok = _verify(m, L[k:k + 1], xs, rs, tol)
            if ok[0] or rs[0] < resid[k]:
                x[k], resid[k] = xs[0], rs[0]
            if ok[0]:
                solved[k], stage[k] = True, 2
    return ForwardResult(
        mechanism=m.name, names=tuple(m.pose_names), units=tuple(m.pose_units),
        pose=x.reshape(shape + (n,)), residual=resid.reshape(shape), solved=solved.reshape(shape),
        stage=stage.reshape(shape),
        evaluations={"residual": evals[0].reshape(shape), "jacobian": evals[1].reshape(shape)},
        tol=float(tol))


# ----------------------------------------------------------------------------------------------
# inverse
# ----------------------------------------------------------------------------------------------
_D2R = np.pi / 180.0
_I6 = np.arange(6)


def _zyz_matrix(euler_deg: np.ndarray) -> np.ndarray:
    a, b, g = np.radians(euler_deg).T
    ca, sa, cb, sb, cg, sg = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(g), np.sin(g)
    R = np.empty((len(a), 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 0, 2] = ca * cb * cg - sa * sg, -ca * cb * sg - sa * cg, ca * sb
    R[:, 1, 0], R[:, 1, 1], R[:, 1, 2] = sa * cb * cg + ca * sg, -sa * cb * sg + ca * cg, sa * sb
    R[:, 2, 0], R[:, 2, 1], R[:, 2, 2] = -sb * cg, sb * sg, cb
    return R


def _solved1(p, R, pt, Rt, W, tol) -> bool:
    """Whether frame (p, R) on floats is within tol of target (pt, Rt), task mask W (or None)."""
    dp = [a - b for a, b in zip(p, pt)]
    e = _rotation_error1(R, Rt)
    if W is not None:
        dp, e = [v * w for v, w in zip(dp, W[:3])], [v * w for v, w in zip(e, W[3:])]
    return math.hypot(*dp) <= tol[0] and math.hypot(*e) <= tol[1]


def _zyz_matrix1(a: float, b: float, g: float) -> list[list[float]]:
    """:func:`_zyz_matrix` of one triple of Euler angles (deg) on Python floats (the same formulas)."""
    a, b, g = math.radians(a), math.radians(b), math.radians(g)
    ca, sa, cb, sb, cg, sg = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(g), math.sin(g)
    return [[ca * cb * cg - sa * sg, -ca * cb * sg - sa * cg, ca * sb],
            [sa * cb * cg + ca * sg, -sa * cb * sg + ca * cg, sa * sb],
            [-sb * cg, sb * sg, cb]]


def _rotation_error(R: np.ndarray, Rt: np.ndarray) -> np.ndarray:
    """Rotation vector (k, 3) of R Rt^T (base frame), angle in [0, pi] radians."""
    M = R @ np.swapaxes(Rt, -1, -2)
    v = np.stack([M[:, 2, 1] - M[:, 1, 2], M[:, 0, 2] - M[:, 2, 0], M[:, 1, 0] - M[:, 0, 1]], axis=-1)
    s = 0.5 * np.sqrt(_sumsq(v))                                   # sin(angle)
    c = 0.5 * (M[:, 0, 0] + M[:, 1, 1] + M[:, 2, 2] - 1.0)         # cos(angle)
    angle = np.arctan2(s, c)
    k = np.where(s > 1e-12, angle / np.where(s > 1e-12, 2.0 * s, 1.0), 0.5)
    return v * k[:, None]


def _internal(m, q):
    """Public joint values (deg, length unit) -> inverse's internal units (rad, length unit)."""
    a = m.angle_mask(m.joint_units)
    return np.where(a, np.radians(q), q) if not a.all() else np.radians(q)


def _public(m, u):
    """Inverse's internal units (rad, length unit) -> public joint values (deg, length unit)."""
    a = m.angle_mask(m.joint_units)
    return np.where(a, np.degrees(u), u) if not a.all() else np.degrees(u)


_M64 = np.uint64(0xFFFFFFFFFFFFFFFF)


def _uniform_hash(seed: int, row: np.ndarray, draw: np.ndarray, n: int) -> np.ndarray:
    """Uniforms in [0, 1) shaped (k, n), a pure function of (seed, row, draw, coordinate):
    SplitMix64's finaliser (Steele, Lea, Flood 2014) over a combined 64-bit counter. Each row
    of a batch thus gets the same restarts alone or in any batch."""
    with np.errstate(over="ignore"):
        c = (np.uint64(seed & 0xFFFFFFFF) * np.uint64(0x9E3779B97F4A7C15)
             ^ (row.astype(np.uint64) << np.uint64(20)) ^ (draw.astype(np.uint64) << np.uint64(4)))
        z = c[:, None] + np.arange(1, n + 1, dtype=np.uint64) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        z = z ^ (z >> np.uint64(31))
    return (z >> np.uint64(11)).astype(np.float64) * (1.0 / 9007199254740992.0)


_rotation_error1 = rotation_error1


_TABLES: dict = {}


def _start_table(m, size: int):
    """Joint configurations (size, n) in radians drawn uniformly inside the limits by a fixed
    hash (independent of ``seed``) and their tool features (position, w * rotation matrix
    entries; w = reach / (3 sqrt 2), so 1 rad of rotation weighs about reach / 3): ``inverse``
    starts from the configurations nearest to each target. Cached per arm (name, DH table,
    limits) as a dict with "q", "features", "w" (and "tree", see :func:`_nearest`). The arm's
    own forward map (``frame``) makes it, so it serves DH and URDF arms alike."""
    key = m.kinematic_key() + (m.bounds.tobytes(), size)
    got = _TABLES.get(key)
    if got is None:
        from fkopt.numerics.rotations import to_array
        lo, hi = _internal(m, m.bounds[:, 0]), _internal(m, m.bounds[:, 1])
        tq = lo + (hi - lo) * _uniform_hash(0x5EED, np.arange(size), np.zeros(size, dtype=np.int64), m.dof)
        p, R = m.frame(_public(m, tq))
        wf = m.reach / (3.0 * np.sqrt(2.0))
        feats = np.concatenate([np.stack(p, axis=-1), wf * to_array(R).reshape(size, 9)], axis=-1)
        got = _TABLES[key] = {"q": tq, "features": feats, "w": wf}
    return got


def _masked_table(tab: dict, W: np.ndarray) -> dict:
    """The start table compared on the selected task components: masked position features,
    and the rotation features only when all three rotation components count (a rotation
    matrix entry is not one rotation-vector axis). Cached beside the table."""
    fmask = np.concatenate([W[:3], np.full(9, float(W[3:].all()))])
    key = ("masked", fmask.tobytes())
    if key not in tab:
        tab[key] = {"q": tab["q"], "features": tab["features"] * fmask, "w": tab["w"], "mask": fmask}
    return tab[key]


#: Batches from this many rows query the start table through scipy's k-d tree (importing
#: scipy.spatial costs ~0.4 s once per process); smaller ones by exact brute force.
_TREE_MIN = 32


def _nearest(table: dict, feats: np.ndarray, k: int) -> np.ndarray:
    """Indices (N, k) of the table's k nearest configurations (Euclidean in the features),
    nearest first."""
    if len(feats) >= _TREE_MIN:
        if "tree" not in table:
            from scipy.spatial import cKDTree
            table["tree"] = cKDTree(table["features"])
        _, near = table["tree"].query(feats, k=k)
        return np.asarray(near, dtype=np.intp).reshape(len(feats), k)
    F = table["features"]
    if "norms" not in table:
        table["norms"] = _sumsq(F)
    out = np.empty((len(feats), k), dtype=np.intp)
    for i, f in enumerate(feats):
        d2 = table["norms"] - 2.0 * (F @ f)              # |F - f|^2 - |f|^2
        part = np.argpartition(d2, k - 1)[:k] if k < len(d2) else np.arange(len(d2))
        out[i] = part[np.argsort(d2[part], kind="stable")]
    return out


def _forward_table(m, size: int) -> dict:
    """forward's start table: ``size`` poses drawn uniformly inside ``m.bounds`` by a fixed hash
    (independent of ``seed``; the same counter-based draws as inverse's table) and their joints by
    the closed-form inverse map, with the features k-d tree queries compare (:func:`_joint_features`:
    each joint divided by its spread over the table, so legs of different ranges weigh alike; an
    angle joint as (cos, sin) divided by its spread in radians). Poses whose joints are not finite
    are left out. Cached per mechanism class, bounds and geometry -- the joints of a few fixed
    probe poses stand for the geometry, so a mechanism built again (``forward("6-sps", ...)``)
    finds its table. A dict with "pose", "joints", "features", "feature_scale", "angle" (and "tree")."""
    n = len(m.pose_names)
    lo, hi = m.bounds[:, 0], m.bounds[:, 1]
    probe = lo + (hi - lo) * _uniform_hash(0xF0D, np.arange(4), np.zeros(4, dtype=np.int64), n)
    with np.errstate(all="ignore"):
        key = ("forward", type(m).__module__, type(m).__qualname__, m.bounds.tobytes(), int(size),
               np.asarray(m.ik(probe), dtype=float).tobytes())
    got = _TABLES.get(key)
    if got is None:
        poses = lo + (hi - lo) * _uniform_hash(0xF0D, np.arange(size), np.ones(size, dtype=np.int64), n)
        with np.errstate(all="ignore"):
            joints = np.asarray(m.ik(poses), dtype=float)
        keep = np.isfinite(joints).all(axis=-1)
        poses, joints = poses[keep], joints[keep]
        angle = m.angle_mask(m.joint_units)
        tab = {"pose": poses, "joints": joints, "angle": angle}
        raw = _joint_features(tab, joints)
        spread = raw.std(axis=0) if len(raw) > 1 else np.ones(raw.shape[-1])     # (no pose: no table)
        spread = np.where(spread > 0, spread, 1.0)
        tab["feature_scale"] = 1.0 / spread
        tab["features"] = raw * tab["feature_scale"]
        got = _TABLES[key] = tab
    return got


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


def _joint_features(tab: dict, joints: np.ndarray) -> np.ndarray:
    """Joints (k, m) as the start table's features: lengths as they are, an angle joint (deg) as
    (cos, sin) (so 359 deg is near 1 deg), each times the table's ``feature_scale`` once built."""
    angle = tab["angle"]
    if angle.any():
        a = np.radians(joints[:, angle])
        f = np.concatenate([joints[:, ~angle], np.cos(a), np.sin(a)], axis=-1)
    else:
        f = np.array(joints, dtype=float)
    return f * tab["feature_scale"] if "feature_scale" in tab else f


#: Names of the six task components ``mask`` selects, in order.
TASK = ("x", "y", "z", "rx", "ry", "rz")


def _task_mask(mask) -> np.ndarray | None:
    """``mask`` as a (6,) array of 0/1 over (x, y, z, rx, ry, rz), or None for the full pose."""
    if mask is None:
        return None
    if isinstance(mask, str):
        mask = [name in {t.strip() for t in mask.split(",")} for name in TASK] \
            if all(t.strip() in TASK for t in mask.split(",")) else mask
    try:
        W = np.asarray(mask, dtype=float)
    except (TypeError, ValueError):
        W = None
    if W is None or W.shape != (6,) or not np.isin(W, (0.0, 1.0)).all() or not W.any():
        raise FkoptError(f"inverse mask: expected 6 flags 0/1 over ({', '.join(TASK)}) with at least one "
                         f"set, or names like 'x,y,z'; got {mask!r}")
    return None if W.all() else W


def _toward_start(m, q, q0, pt, Rt, L, W, tol, slo, shi, periodic, rounds: int = 30):
    """Rows q (k, n) of solved joints (internal units) moved along the arm's self-motion towards
    the starts q0 (k, n), staying solved: each round a null-space step dz = (I - J^+ J)(q0 - q)
    (J^+ = J^T (J J^T + eps I)^{-1}, the task rows of ``W`` only) clipped into the limits, then up
    to 3 damped least-squares corrections of the task; a row takes the round only if it is still
    within ``tol`` and nearer to its start (Euclidean in rad and length units; periodic joints by
    their angle difference wrapped into [-pi, pi)). A redundant arm (or a masked task) thus
    returns the solution locally nearest to the current joints; a 6-joint arm with a full pose has
    no self-motion and keeps its answer. Returns (q, Jacobian evaluations per row)."""
    k, n = q.shape
    to_pub = _public(m, np.ones(n))
    Wr = np.ones(6) if W is None else np.asarray(W, dtype=float)
    evals = np.zeros(k, dtype=np.int64)

    def gap(a):
        g = q0 - a
        if periodic.any():
            g[:, periodic] = (g[:, periodic] + np.pi) % (2 * np.pi) - np.pi
        return g

    def task(a):
        p, R, J = m.frame_jacobian(a * to_pub)
        e = _rotation_error(R, Rt)
        J = J * to_pub * Wr[:, None]
        J[:, 3:] *= L
        dp, e = (p - pt) * Wr[:3], e * Wr[3:]
        return np.concatenate([dp, L * e], axis=-1), J, np.sqrt(_sumsq(dp)), np.sqrt(_sumsq(e))

    act = np.arange(k)
    dist = np.sqrt(_sumsq(gap(q)))
    for _ in range(rounds):
        if not len(act):
            break
        qa = q[act]
        r, J, _, _ = task(qa)
        evals[act] += 1
        Jt = np.swapaxes(J, 1, 2)
        A = J @ Jt
        A[:, _I6, _I6] += 1e-9 * np.trace(A, axis1=1, axis2=2)[:, None] + 1e-300
        g = gap(qa)
        dz = g - (Jt @ np.linalg.solve(A, (J @ g[..., None])))[..., 0]
        qn = np.clip(qa + dz, slo, shi)
        for _ in range(3):                             # back onto the task
            r, J, pe, re = task(qn)
            evals[act] += 1
            if ((pe <= tol[0]) & (re <= tol[1])).all():
                break
            Jt = np.swapaxes(J, 1, 2)
            A = J @ Jt
            A[:, _I6, _I6] += 1e-9 * np.trace(A, axis1=1, axis2=2)[:, None] + 1e-300
            qn = np.clip(qn - (Jt @ np.linalg.solve(A, r[..., None]))[..., 0], slo, shi)
        else:
            r, J, pe, re = task(qn)
            evals[act] += 1
        dn = np.sqrt(_sumsq(gap(qn)))
        ok = (pe <= tol[0]) & (re <= tol[1]) & (dn < dist[act] - 1e-12)
        q[act[ok]], dist[act[ok]] = qn[ok], dn[ok]
        act = act[ok & (dn < dist[act] * (1 - 1e-6))] if ok.any() else act[:0]
    return q, evals


def _arm_constants(m) -> dict:
    """Per-arm values of a one-pose :func:`inverse` as Python floats, cached on the arm (keyed by
    its bounds, which a user may change): internal-unit limits, saturation limits (none for
    periodic joints), the periodic mask and the unit factors."""
    key = m.bounds.tobytes()
    got = m.__dict__.get("_inverse_constants")
    if got is None or got["key"] != key:
        lo, hi = _internal(m, m.bounds[:, 0]), _internal(m, m.bounds[:, 1])
        per = m.periodic_mask()
        got = m.__dict__["_inverse_constants"] = {
            "key": key, "lo": lo, "hi": hi, "slo": np.where(per, -np.inf, lo), "shi": np.where(per, np.inf, hi),
            "periodic": per.tolist(), "blo": m.bounds[:, 0].tolist(), "bhi": m.bounds[:, 1].tolist(),
            "angle": m.angle_mask(m.joint_units).tolist(), "mid": (0.5 * (lo + hi)).tolist()}
    return got


def _fast_context(m, table: int, W) -> dict:
    """Per-arm constants of the compiled one-pose call (:func:`fkopt.numerics.compiled.inverse_pose`),
    as typed arrays, cached beside :func:`_arm_constants` (so a change of the bounds renews them):
    the chain, limits, unit and periodic masks, and the start table (or its masked copy for task
    mask W) with its features transposed for the compiled nearest-neighbour search."""
    c = _arm_constants(m)
    key = ("fast", table, None if W is None else W.tobytes())
    got = c.get(key)
    if got is None:
        n = m.dof
        if table:
            tab = _start_table(m, table)
            if W is not None:
                tab = _masked_table(tab, W)
            if "norms" not in tab:
                tab["norms"] = _sumsq(tab["features"])
            tq, F, norms, w = tab["q"], tab["features"], tab["norms"], float(tab["w"])
            fmask = tab.get("mask", np.ones(12))
        else:
            tq, F, norms, w, fmask = np.zeros((0, n)), np.zeros((0, 12)), np.zeros(0), 0.0, np.ones(12)
        got = c[key] = {
            "n": n, "chain": m.chain().arrays(), "tq": np.ascontiguousarray(tq, dtype=float),
            "Ft": np.ascontiguousarray(F.T, dtype=float), "norms": np.ascontiguousarray(norms, dtype=float), "w": w,

            "fmask": np.ascontiguousarray(fmask, dtype=float), "W": np.ones(6) if W is None else np.asarray(W, float),
            "slo": np.asarray(c["slo"], dtype=float), "shi": np.asarray(c["shi"], dtype=float),
            "lo": np.asarray(c["lo"], dtype=float), "hi": np.asarray(c["hi"], dtype=float),
            "angle": np.array(c["angle"], dtype=np.bool_), "periodic": np.array(c["periodic"], dtype=np.bool_),
            "blo": np.array(c["blo"], dtype=float), "bhi": np.array(c["bhi"], dtype=float),
            "mid": np.array(c["mid"], dtype=float)}
        from fkopt.numerics.compiled import start_screen  # the compiled nearest-neighbour search's arguments
        got["table"] = start_screen(got["Ft"], got["norms"])
    return got


def _fast_result(m, answer, tp: float, tr: float) -> InverseResult:
    """The :class:`InverseResult` of one compiled call's (public joints, info)
    (:func:`fkopt.numerics.compiled.inverse_pose`)."""
    out, info = answer
    perr, rerr, used, ev = float(info[0]), float(info[1]), int(info[3]), np.array(int(info[4]), dtype=np.int64)
    return InverseResult(
        mechanism=m.name, names=tuple(m.joint_names), joints=out, position_error=np.array(perr),
        rotation_error=np.array(rerr), residual=np.array(max(perr / tp, rerr / tr)),
        solved=np.array(perr <= tp and rerr <= tr and info[2] > 0), restarts=np.array(used - 1, dtype=np.int64),
        evaluations={"residual": ev, "jacobian": ev.copy()}, tol=(tp, tr))


def _unreachable(m, x, y, z, dist) -> FkoptError:
    """The one-line error of a target farther from the base than the arm's reach."""
    unit = m.pose_units[0]
    return FkoptError(f"{m.name} target ({x:g}, {y:g}, {z:g}) unreachable "
                      f"(distance {dist:.1f} {unit} > reach {m.reach:.1f} {unit})")


def _inverse_one(m, pose, start, tol, seed, budget, table, kn, orientation_scale, iterations, damping,
                 down, up, step_cap, W=None, compiled=None) -> InverseResult:
    """:func:`inverse` of one pose (6,): the candidates of the batched loop one after another on
    Python floats (:func:`fkopt.numerics.damped_least_squares.inverse_candidates`, or its compiled twin), the same starts in the same order (``start``, then
    the table's ``kn`` configurations nearest to the target -- looked up only when a candidate
    first needs one -- then seeded random draws), with only the numpy calls it cannot avoid: a
    batch's bookkeeping costs more than the iteration itself for a single pose. The compiled call
    without a start is :meth:`InverseSolver._one`'s own; this one serves the rest (a start, or the
    Python reference)."""
    tp, tr = tol
    n = m.dof
    x, y, z = pose[:3].tolist()
    reach = m.reach
    dist = math.sqrt(x * x + y * y + z * z)
    if dist > reach * (1.0 + 1e-12):
        raise _unreachable(m, x, y, z, dist)
    L = float(orientation_scale) if orientation_scale else reach
    nn = min(table, kn) if table else 0
    fast = numerics_path.compiled(compiled) if hasattr(m, "chain") else None
    c = _arm_constants(m)
    lo, hi = c["lo"], c["hi"]
    blo, bhi, angle = c["blo"], c["bhi"], c["angle"]
    own0 = 1 if (start is not None or not table) else 0
    if start is None:
        q0 = c["mid"]
    else:
        s = _values(m, start, m.joint_names, "start")
        if s.size != n:
            raise FkoptError(f"{m.name} start: one pose takes one start ({n},), got shape {s.shape}")
        sl = s.reshape(n).tolist()
        if not all(a - 1e-9 <= v <= b + 1e-9 for v, a, b in zip(sl, blo, bhi)):
            box = ", ".join(f"{a} [{b[0]:g}, {b[1]:g}]" for a, b in zip(m.joint_names, m.bounds.tolist()))
            raise FkoptError(f"{m.name} start: joints must be inside the limits ({box})")
        q0 = [math.radians(v) if a else v for v, a in zip(sl, angle)]
    if fast is not None and n <= 6 and W is None:
        # a start, but no self-motion step after the loop: pose to answer in one compiled call
        ctx = _fast_context(m, int(table), W)
        return _fast_result(m, fast.inverse_pose(ctx, np.ascontiguousarray(pose, dtype=float), L, ctx["W"], np.array(q0), own0, nn, int(seed), int(budget),
                                                 tol, int(iterations), float(damping), float(down), float(up),
                                                 float(step_cap)), tp, tr)
    Rt = pose[3:].reshape(3, 3).tolist() if len(pose) == 12 else _zyz_matrix1(*pose[3:].tolist())
    near: list[int] = []

    def start_of(j):
        if j < own0:
            return q0
        if j < own0 + nn:
            if not near:
                tab = _start_table(m, table)
                f = np.concatenate([pose[:3], tab["w"] * np.array(Rt).reshape(9)])
                if W is not None:                      # nearest in the selected components only
                    tab = _masked_table(tab, W)
                    f = f * tab["mask"]
                near.extend(_nearest(tab, f[None], nn)[0].tolist())
                near.append(tab)
            return near[-1]["q"][near[j - own0]].tolist()
        return (lo + (hi - lo) * _uniform_hash(seed, np.zeros(1, dtype=np.intp),
                                               np.array([j - own0 - nn]), n)[0]).tolist()

    if fast is not None:
        # the same starts as start_of, as arrays: the table's neighbours looked up now
        if nn:
            start_of(own0)
            near_q = np.ascontiguousarray(near[-1]["q"][near[:-1]])
        else:
            near_q = np.empty((0, n))
        Wc = np.ones(6) if W is None else np.asarray(W, dtype=float)
        bq, used, ne = fast.inverse_one(m.chain(), np.asarray(pose[:3], dtype=float), np.array(Rt), L, Wc,
                                        np.asarray(q0, dtype=float), own0, near_q, seed, budget, tol, iterations,
                                        damping, down, up, step_cap, c["slo"], c["shi"], lo, hi)
    else:
        bq, used, ne = inverse_candidates(m.frame_jacobian1, [float(v) for v in pose[:3]], Rt, L, start_of, budget,
                                          tol, iterations, damping, down, up, step_cap, c["slo"].tolist(),
                                          c["shi"].tolist(), None if W is None else W.tolist())
        bq = np.array(bq)
    if start is not None and (n > 6 or W is not None):   # self-motion towards the start
        p1, R1, _ = m.frame_jacobian1(bq.tolist())
        if _solved1(p1, R1, (x, y, z), Rt, W, tol):
            q1, extra = _toward_start(m, bq[None].copy(), np.array([q0]), np.array([[x, y, z]]), np.array([Rt]),
                                      L, W, tol, c["slo"], c["shi"], np.array(c["periodic"]))
            bq, ne = q1[0], ne + int(extra[0])
    # public units; continuous joints wrapped into [-180, 180); clipped into the limits
    qd = [math.degrees(v) if a else v for v, a in zip(bq.tolist(), angle)]
    qd = [(v + 180.0) % 360.0 - 180.0 if p else v for v, p in zip(qd, c["periodic"])]
    qd = [min(max(v, a), b) for v, a, b in zip(qd, blo, bhi)]
    p1, R1, _ = m.frame_jacobian1([math.radians(v) if a else v for v, a in zip(qd, angle)])
    dp = [a - b for a, b in zip(p1, (x, y, z))]
    e = _rotation_error1(R1, Rt)
    if W is not None:
        dp, e = [v * w for v, w in zip(dp, W[:3])], [v * w for v, w in zip(e, W[3:])]
    perr, rerr = math.hypot(*dp), math.hypot(*e)
    inside = all(a <= v <= b for v, a, b in zip(qd, blo, bhi))
    ev = np.array(ne, dtype=np.int64)
    return InverseResult(
        mechanism=m.name, names=tuple(m.joint_names), joints=np.array(qd), position_error=np.array(perr),
        rotation_error=np.array(rerr), residual=np.array(max(perr / tp, rerr / tr)),
        solved=np.array(perr <= tp and rerr <= tr and inside), restarts=np.array(used - 1, dtype=np.int64),
        evaluations={"residual": ev, "jacobian": ev.copy()}, tol=(tp, tr))


def _inverse_arm(arm) -> SerialMechanism:
    """``arm`` of :func:`inverse` as a serial mechanism with an analytic frame Jacobian."""
    m = _mechanism(arm, SerialMechanism, "inverse")
    if not hasattr(m, "frame_jacobian"):
        raise FkoptError(f"inverse needs an arm with an analytic frame Jacobian; '{m.name}' has none "
                         "(use fkopt.solve with an ik_problem)")
    return m


def _tolerance(tol) -> tuple[float, float]:
    """``tol`` of :func:`inverse` as (position, orientation) positive finite floats."""
    try:
        if isinstance(tol, tuple) and len(tol) == 2:      # the common case, without numpy's broadcast
            tp, tr = float(tol[0]), float(tol[1])
        else:
            tp, tr = (float(t) for t in np.broadcast_to(np.asarray(tol, dtype=float), (2,)))
    except (TypeError, ValueError):
        raise FkoptError(f"inverse tol: expected (position, orientation), got {tol!r}") from None
    if not (0 < tp <= MAX_API_VALUE and 0 < tr <= MAX_API_VALUE):
        raise FkoptError(f"inverse tol: both tolerances must be positive and at most {MAX_API_VALUE:g}, got {tol!r}")
    return tp, tr


class InverseSolver:
    """:func:`inverse` prepared for one arm, one :class:`fkopt.numerics.InverseOptions`, one
    tolerance and one task mask: for a control loop that asks for one pose per tick.

    ``solver = fkopt.InverseSolver(arm, options, tol=..., mask=...)`` does the per-arm and
    per-option set-up once -- the options validated, the chain as arrays, the start table
    (``options.table`` FK evaluations) and its features, the limits in internal units, the
    compiled kernel's argument list -- and ``solver(target, seed=..., start=...)`` goes from the
    target straight to the compiled one-pose loop (:func:`fkopt.numerics.compiled.inverse_pose`).
    Per call it checks only the target (shape, finite, an orthonormal frame, within reach) and
    ``seed``. Its answers are :func:`inverse`'s bit for bit: ``inverse`` itself runs every one-pose
    call through a solver like this one (cached per arm, options, tol and mask), and sends
    batches and the options without a one-pose loop (``rest`` > 0, ``exact_rotation``) to its
    batched loop, as the solver does.

    ``target``: a tip frame (4, 4) in the base frame (cheapest: no Euler angles), or a pose (6,)
    as ``arm.fk`` gives it; a batch (..., 4, 4) / (..., 6) goes to :func:`inverse`'s batched loop.
    ``seed``: the restarts' stream (an int). ``start``: the current joints (deg), as in
    :func:`inverse` (the given start first, then the self-motion step on a redundant arm).

    The solver reads the arm's limits when it is made; if ``arm.bounds`` changes later it
    prepares again on the next call (one byte comparison per call keeps that honest)."""

    __slots__ = ("arm", "options", "tol", "mask", "_W", "_bounds", "_fast", "_one_pose", "_budget", "_table",
                 "_kn", "_L", "_kernel", "_reach")

    def __init__(self, arm, options: InverseOptions | None = None, *, tol=INVERSE_TOL, mask=None):
        self.arm = m = _inverse_arm(arm)
        if options is None:
            options = InverseOptions()
        elif not isinstance(options, InverseOptions):
            raise FkoptError(f"InverseSolver options: expected fkopt.numerics.InverseOptions, "
                             f"got {type(options).__name__}")
        self.options = options.validated()
        self.tol = _tolerance(tol)
        self.mask = mask
        self._W = _task_mask(mask)
        self._prepare()

    def _prepare(self) -> None:
        """Everything that depends on the arm's limits and the options, once."""
        m, o = self.arm, self.options
        self._bounds = m.bounds.tobytes()
        self._reach = float(m.reach)
        self._one_pose = o.rest <= 0 and not o.exact_rotation
        first = max(1, int(o.starts), o.fill)
        self._budget = first + max(0, int(o.restarts))
        self._table = int(o.table)
        # neighbours per pose: without / with a start (own0 = 1 when a start is given or there is no table)
        self._kn = (first - (0 if self._table else 1) + int(o.neighbours), first - 1 + int(o.neighbours))
        self._L = float(o.orientation_scale) if o.orientation_scale else m.reach
        self._fast = fast = numerics_path.compiled(o.compiled) if hasattr(m, "chain") else None
        self._kernel = None
        if fast is not None and self._one_pose:
            ctx = _fast_context(m, self._table, self._W)
            nn = min(self._table, self._kn[0]) if self._table else 0
            self._kernel = fast.bound_inverse_pose(ctx, float(self._L), ctx["W"], ctx["mid"], 0 if self._table else 1,
                                                   nn, self._budget, self.tol, int(o.iterations), float(o.damping),
                                                   float(o.down), float(o.up), float(o.step_cap))

    def __repr__(self) -> str:
        return f"InverseSolver({self.arm.name!r}, {self.options!r}, tol={self.tol!r}, mask={self.mask!r})"

    def __call__(self, target, *, seed: int = 0, start=None) -> InverseResult:
        if self.arm.bounds.tobytes() != self._bounds:
            self._prepare()
        P0 = _targets(self.arm, target)
        if P0.ndim == 1 and self._one_pose:
            return self._one(P0, start, seed)
        return inverse(self.arm, target, start=start, tol=self.tol, mask=self.mask, seed=seed, options=self.options)

    def _one(self, pose: np.ndarray, start, seed) -> InverseResult:
        """One checked target row (6,) or (12,): the compiled kernel straight away when there is no
        start (the common call), else :func:`_inverse_one` with the prepared options."""
        if type(seed) is not int or not 0 <= seed <= MAX_SEED:
            seed = check_integer("seed", seed, "inverse")
        if self._kernel is not None and start is None:
            if not pose.flags.c_contiguous:         # a strided view would compile another specialisation
                pose = np.ascontiguousarray(pose)
            x, y, z = pose[0], pose[1], pose[2]
            dist = math.sqrt(x * x + y * y + z * z)
            if dist > self._reach * (1.0 + 1e-12):
                raise _unreachable(self.arm, x, y, z, dist)
            return _fast_result(self.arm, self._kernel(pose, seed), *self.tol)
        o = self.options
        return _inverse_one(self.arm, pose, start, self.tol, seed, self._budget, self._table,
                            self._kn[0 if start is None else 1], o.orientation_scale, o.iterations, o.damping, o.down,
                            o.up, o.step_cap, self._W, o.compiled)


def inverse_solver(arm, *, tol=INVERSE_TOL, mask=None, **options) -> InverseSolver:
    """:class:`InverseSolver` from :func:`inverse`'s keyword options (``restarts=50``, ...)."""
    try:
        o = InverseOptions(**options)
    except TypeError:
        allowed = ", ".join(InverseOptions.__dataclass_fields__)
        raise FkoptError(f"inverse_solver: unknown option among {sorted(options)}; allowed: {allowed}") from None
    return InverseSolver(arm, o, tol=tol, mask=mask)


#: Prepared solvers kept per arm by :func:`inverse` (the oldest dropped beyond this many).
_SOLVERS_PER_ARM = 16


def _solver_for(m, options, tol: tuple[float, float], W) -> InverseSolver:
    """The :class:`InverseSolver` :func:`inverse` runs one pose through, cached on the arm by
    (options, tol, mask, numerics mode): ``FKOPT_NUMERICS`` may change between calls. ``options``:
    an :class:`InverseOptions`, or its field values in order as a tuple (inverse's keywords: the
    options object is made only when the solver is)."""
    key = (options, tol, None if W is None else W.tobytes(), numerics_path.requested())
    cache = m.__dict__.get("_inverse_solvers")
    if cache is None:
        cache = m.__dict__["_inverse_solvers"] = {}
    got = cache.get(key)
    if got is None:
        if len(cache) >= _SOLVERS_PER_ARM:
            cache.pop(next(iter(cache)))
        if not isinstance(options, InverseOptions):
            options = InverseOptions(*options)
        got = cache[key] = InverseSolver(m, options, tol=tol, mask=None if W is None else W)
    elif got._bounds != m.bounds.tobytes():
        got._prepare()
    return got


def inverse(arm, poses, *, start=None, tol=INVERSE_TOL, mask=None, seed: int = 0, restarts: int = 200,
            starts: int = 1, rest: float = 0.0, orientation_scale: float | None = None,
            iterations: int = 10, damping: float = 0.01, step_cap: float = 2.0,
            down: float = 0.1, up: float = 10.0, fill: int = 32, exact_rotation: bool = False,
            table: int = 4096, neighbours: int = 32, tail: int = 256, compiled: bool | None = None,
            options=None) -> InverseResult:
    """Inverse kinematics of a serial arm for poses (..., 6), batched over leading axes.

    ``arm``: a registered name or a frame arm (:class:`fkopt.mechanisms.base.FrameArm`: DH and
    URDF arms, through ``frame``, ``frame_jacobian``, ``frame_jacobian1``, ``kinematic_key`` and
    ``periodic_mask`` only). ``poses``: x, y, z (length unit of the arm) and Z-Y-Z Euler angles
    (deg), as ``arm.fk`` returns them; or tip frames (..., 4, 4) in the base frame, as
    ``arm.fk_matrix`` returns them, whose rotation is used as given (no Euler angles: no digits
    lost near their singularity at sin(beta) = 0, no conversion per call). ``start``: the current joints (n,) or (..., n) inside the
    limits (default mid-range): the first candidate begins there; when it is solved and the arm
    has self-motion (more than 6 joints, or a ``mask``), the answer is then moved along the
    self-motion to the solution locally nearest to ``start`` (Euclidean distance in rad and
    length units, continuous joints by their wrapped difference; :func:`_toward_start`). Nearest
    is local: another branch of solutions may hold a nearer one.
    ``tol``: (position, orientation in radians). ``mask``: the task components that count, 6
    flags over (x, y, z, rx, ry, rz) -- position and rotation-vector error in the base frame,
    as roboticstoolbox's ``we`` -- or their names (``"x,y,z"``: position only, for arms with
    fewer than 6 joints); the errors reported are those of the selected components. ``seed``:
    the restarts' stream. ``starts``:
    candidates solved side by side per row (the start and ``starts - 1`` random ones);
    ``restarts``: most random restarts per row. ``rest``: gain of the null-space pull towards
    mid-range (0: off). ``orientation_scale``: length units per radian weighing orientation
    against position in the least squares (default the arm's reach). ``iterations``: per
    candidate before it restarts. ``table``: size of the start table (0: no table, starts at
    ``start`` or mid-range, then random); ``neighbours``: table configurations kept per row for
    restarts beyond its first starts; ``fill`` / ``tail``: candidates side by side for small
    batches / when few remain. ``compiled``: one pose through the compiled loop
    (:mod:`fkopt.numerics.compiled`; None: when numba is there and ``FKOPT_NUMERICS`` is not
    ``numpy``; same answers as the Python loop). ``options``: an
    :class:`fkopt.numerics.InverseOptions` holding all of the above at once (it replaces the
    keywords). See the module docstring.
    """
    if options is not None:
        o = options.as_dict()
        restarts, starts, rest, orientation_scale = o["restarts"], o["starts"], o["rest"], o["orientation_scale"]
        iterations, damping, step_cap, down, up = o["iterations"], o["damping"], o["step_cap"], o["down"], o["up"]
        fill, exact_rotation, table, neighbours = o["fill"], o["exact_rotation"], o["table"], o["neighbours"]
        tail, compiled = o["tail"], o["compiled"]
    m = _inverse_arm(arm)
    tp, tr = _tolerance(tol)
    seed = check_integer("seed", seed, "inverse")
    P0 = _targets(m, poses)
    if P0.ndim == 1 and rest <= 0 and not exact_rotation:
        # one pose: through the prepared solver (cached per arm, options, tol and mask), the one code path
        o = options if options is not None else (restarts, starts, rest, orientation_scale, iterations, damping,
                                                 step_cap, down, up, fill, exact_rotation, table, neighbours, tail,
                                                 compiled)
        return _solver_for(m, o, (tp, tr), _task_mask(mask))._one(P0, start, seed)
    if options is None:                                # the same checks as a one-pose call's solver
        InverseOptions(restarts, starts, rest, orientation_scale, iterations, damping, step_cap, down, up, fill,
                       exact_rotation, table, neighbours, tail, compiled).validated()
    else:
        options.validated()
    shape = P0.shape[:-1]
    P = P0.reshape(-1, P0.shape[-1])
    N, n = len(P), m.dof
    reach = m.reach
    dist = np.sqrt(_sumsq(P[:, :3]))
    far = dist > reach * (1.0 + 1e-12)
    if far.any():
        k = int(np.flatnonzero(far)[0])
        raise _unreachable(m, P[k, 0], P[k, 1], P[k, 2], dist[k])
    lo, hi = _internal(m, m.bounds[:, 0]), _internal(m, m.bounds[:, 1])
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    # saturation bounds: none for periodic (continuous) joints, wrapped at the end
    periodic = m.periodic_mask()
    slo, shi = (np.where(periodic, -np.inf, lo), np.where(periodic, np.inf, hi)) if periodic.any() else (lo, hi)
    W = _task_mask(mask)
    if start is None:
        q0 = np.broadcast_to(mid, (N, n))
    else:
        s = _values(m, start, m.joint_names, "start")
        q0 = np.broadcast_to(s, shape + (n,)).reshape(N, n)
        if not m.in_bounds(q0).all():
            box = ", ".join(f"{a} [{b[0]:g}, {b[1]:g}]" for a, b in zip(m.joint_names, m.bounds.tolist()))
            raise FkoptError(f"{m.name} start: joints must be inside the limits ({box})")
        q0 = _internal(m, q0)
    fast = numerics_path.compiled(compiled) if hasattr(m, "chain") else None
    if fast is not None and rest <= 0 and not exact_rotation and (start is None or (n <= 6 and W is None)):
        # every row as its one-pose call (same starts, restarts and answer), rows on all cores
        own0 = 1 if (start is not None or not table) else 0
        first = max(1, int(starts), fill)
        nn = min(int(table), first - own0 + int(neighbours)) if table else 0
        ctx = _fast_context(m, int(table), W)
        out, info = fast.inverse_rows(ctx, np.ascontiguousarray(P, dtype=float),
                                      float(orientation_scale) if orientation_scale else reach, ctx["W"],
                                      np.ascontiguousarray(q0, dtype=float), own0, nn, int(seed),
                                      first + max(0, int(restarts)), (tp, tr), int(iterations), float(damping),
                                      float(down), float(up), float(step_cap))
        perr, rerr = info[:, 0], info[:, 1]
        ev = info[:, 4].astype(np.int64)
        return InverseResult(
            mechanism=m.name, names=tuple(m.joint_names), joints=out.reshape(shape + (n,)),
            position_error=perr.reshape(shape), rotation_error=rerr.reshape(shape),
            residual=np.maximum(perr / tp, rerr / tr).reshape(shape),
            solved=((perr <= tp) & (rerr <= tr) & (info[:, 2] > 0)).reshape(shape),
            restarts=(info[:, 3].astype(np.int64) - 1).reshape(shape),
            evaluations={"residual": ev.reshape(shape), "jacobian": ev.copy().reshape(shape)}, tol=(tp, tr))
    K = max(1, int(starts))
    if N * K < fill:                                   # small batches: more candidates per row
        K = max(K, fill // N)
    L = float(orientation_scale) if orientation_scale else reach
    pt, Rt = P[:, :3], (P[:, 3:].reshape(N, 3, 3) if P.shape[1] == 12 else _zyz_matrix(P[:, 3:]))
    to_deg = 180.0 / np.pi if m.angle_mask(m.joint_units).all() else _public(m, np.ones(n))
    budget = K + max(0, int(restarts))                 # starts per row, first ones included
    # start j of row i: the given start (j = 0, when given or without table), then the
    # table's configurations nearest to the target, then seeded random draws
    own0 = 1 if (start is not None or not table) else 0
    near = np.zeros((N, 0), dtype=np.intp)
    k0 = 0                                             # neighbours known for every row
    if table:
        tab = _start_table(m, int(table))
        if W is not None:                              # nearest in the selected components only
            tab = _masked_table(tab, W)
        tq = tab["q"]
        kn = min(int(table), K - own0 + int(neighbours))
        if kn > 0:
            # the first K - own0 neighbours of every row now; the full lists only for rows
            # that restart (most rows never need them)
            feats = np.concatenate([pt, tab["w"] * Rt.reshape(N, 9)], axis=-1)
            if W is not None:
                feats = feats * tab["mask"]
            k0 = kn if N < _TREE_MIN else max(0, min(kn, K - own0))   # brute force: all at once
            near = np.full((N, kn), -1, dtype=np.intp)
            if k0:
                near[:, :k0] = _nearest(tab, feats, k0)
            full = np.full(N, k0 == kn)
    nn = near.shape[1]

    def starts_for(rows, j):
        qs = np.empty((len(rows), n))
        a = j < own0
        if a.any():
            qs[a] = q0[rows[a]]
        b = (j >= own0) & (j < own0 + nn)
        if b.any():
            late = b & (j - own0 >= k0)                # beyond the neighbours every row has
            need = np.unique(rows[late][~full[rows[late]]])
            if len(need):
                near[need] = _nearest(tab, feats[need], nn)
                full[need] = True
            qs[b] = tq[near[rows[b], j[b] - own0]]
        c = j >= own0 + nn
        if c.any():
            qs[c] = lo + (hi - lo) * _uniform_hash(seed, rows[c], j[c] - own0 - nn, n)
        return qs

    evaluated: list[np.ndarray] = []

    def evaluate(qa, rows):
        p, R, J = m.frame_jacobian(qa * to_deg)
        evaluated.append(rows)                        # counted per row at the end
        e = _rotation_error(R, Rt[rows])
        dp = p - pt[rows]
        J *= to_deg                                    # per radian (per length unit) of joint motion
        if W is not None:                              # masked task: those rows do not count
            dp, e = dp * W[:3], e * W[3:]
            J *= W[:, None]
        r = np.concatenate([dp, L * e], axis=-1)
        # d e = J_l^{-1}(e) omega (left Jacobian of SO(3): e = log(R R_t^T), dR = [omega]x R)
        if exact_rotation:
            J[:, 3:] = so3_right_jacobian_inverse(-e) @ J[:, 3:]
        J[:, 3:] *= L
        return r, J, np.sqrt(_sumsq(dp)), np.sqrt(_sumsq(e))

    if N == 1 and rest <= 0 and not exact_rotation and W is None:
        def start_of(j):
            return starts_for(np.zeros(1, dtype=np.intp), np.array([j]))[0].tolist()

        bq, nused, ne = inverse_candidates(m.frame_jacobian1, pt[0].tolist(), Rt[0].tolist(), L, start_of, budget,
                                           (tp, tr), iterations, damping, down, up, step_cap, slo.tolist(),
                                           shi.tolist())
        bq = np.array(bq)
        best_q, used = bq[None], np.array([nused], dtype=np.int64)
        K = 1                                          # restarts: starts after the first
        ev_r = np.array([ne], dtype=np.int64)
        ev_j = ev_r.copy()
    else:
        best_q = np.array(q0, dtype=float)
        best_m = np.full(N, np.inf)
        done = np.zeros(N, dtype=bool)
        used = np.full(N, K, dtype=np.int64)               # starts used per row

        def fold(sl):
            """Fold slots ``sl`` into the best answer of their rows (smallest merit wins)."""
            merit = np.maximum(pe[sl] / tp, re[sl] / tr)
            o = own[sl]
            order = np.lexsort((merit, o))
            first = np.ones(len(sl), dtype=bool)
            first[1:] = o[order[1:]] != o[order[:-1]]
            top = order[first]
            better = merit[top] < best_m[o[top]]
            rows = o[top[better]]
            best_q[rows], best_m[rows] = q[sl[top[better]]], merit[top[better]]

        def rank_in_row(rows):
            """0, 1, ... for repeated entries of ``rows`` (in order of appearance)."""
            order = np.argsort(rows, kind="stable")
            srt = rows[order]
            newgrp = np.ones(len(rows), dtype=bool)
            newgrp[1:] = srt[1:] != srt[:-1]
            first = np.maximum.accumulate(np.where(newgrp, np.arange(len(rows)), 0))
            rank = np.empty(len(rows), dtype=np.int64)
            rank[order] = np.arange(len(rows)) - first
            return rank

        # slots: candidates side by side, slot s works for row own[s]
        own = np.repeat(np.arange(N), K)
        q = starts_for(own, np.tile(np.arange(K), N))
        r, J, pe, re = evaluate(q, own)
        S = _sumsq(r)
        lam = np.full(len(q), damping)
        age = np.zeros(len(q), dtype=np.int64)
        fresh = np.zeros(len(q), dtype=bool)               # restarted: q set, r and J not yet
        with np.errstate(all="ignore"):
            while True:
                # -- bookkeeping: solved rows retire, stuck slots restart in place ----------------
                conv = (pe <= tp) & (re <= tr) & ~fresh
                if conv.any():
                    cs = np.flatnonzero(conv)
                    fold(cs)
                    done[own[cs]] = True
                stuck = ((age >= iterations) | (lam > 1e6)) & ~fresh
                if conv.any() or stuck.any():
                    live = ~done[own]
                    sl = np.flatnonzero(stuck & live)
                    if len(sl):
                        fold(sl)
                        rows = own[sl]
                        j = used[rows] + rank_in_row(rows)
                        ok = j < budget
                        np.add.at(used, rows[ok], 1)
                        live[sl[~ok]] = False
                        sl, rows, j = sl[ok], rows[ok], j[ok]
                        q[sl] = starts_for(rows, j)
                        fresh[sl] = True
                    if not live.all():
                        own, q, r, J, pe, re, lam, S, age, fresh = (
                            a[live] for a in (own, q, r, J, pe, re, lam, S, age, fresh))
                if len(own) < tail:                        # few rows left: give each more candidates
                    rows_left = np.flatnonzero(~done & (used < budget))
                    extra = (tail - len(own)) // max(len(rows_left), 1)
                    if extra > 0 and len(rows_left):
                        give = np.minimum(extra, budget - used[rows_left])
                        rows = np.repeat(rows_left, give)
                        j = used[rows] + rank_in_row(rows)
                        used[rows_left] += give
                        k = len(rows)
                        own = np.concatenate([own, rows])
                        q = np.concatenate([q, starts_for(rows, j)])
                        r, J = np.concatenate([r, np.empty((k, 6))]), np.concatenate([J, np.empty((k, 6, n))])
                        pe, re = np.concatenate([pe, np.empty(k)]), np.concatenate([re, np.empty(k)])
                        lam, S = np.concatenate([lam, np.empty(k)]), np.concatenate([S, np.empty(k)])
                        age = np.concatenate([age, np.empty(k, dtype=np.int64)])
                        fresh = np.concatenate([fresh, np.ones(k, dtype=bool)])
                if not len(own):
                    break
                # -- one damped least-squares step with saturation in the null space --------------
                anyfresh = fresh.any()
                st = np.flatnonzero(~fresh) if anyfresh else slice(None)
                Js, rs, qs = J[st], r[st], q[st]
                Jt_ = np.swapaxes(Js, 1, 2)
                A = Js @ Jt_
                tr6 = np.trace(A, axis1=1, axis2=2) * (1.0 / 6.0)
                if rest > 0:                               # projector onto the null space of J
                    # fading as |r| drops below 1 length unit: at the end the task alone converges
                    z = (rest * np.minimum(1.0, np.sqrt(S[st])))[:, None] * (mid - qs) / (half * half)
                    A[:, _I6, _I6] += 1e-9 * tr6[:, None]
                    dz = z - (Jt_ @ np.linalg.solve(A, Js @ z[..., None]))[..., 0]
                    A[:, _I6, _I6] -= 1e-9 * tr6[:, None]
                mu = lam[st] * tr6                         # damping scaled to J
                A[:, _I6, _I6] += mu[:, None]
                d = (Jt_ @ np.linalg.solve(A, -rs[..., None]))[..., 0]
                if rest > 0:
                    d += dz
                d *= np.minimum(1.0, step_cap / np.abs(d).max(axis=-1))[:, None]
                qn = qs + d
                out = (qn < slo) | (qn > shi)
                sat = np.flatnonzero(out.any(axis=-1))
                if len(sat):                               # saturation in the null space, those rows only
                    Jv, qv, rv, muv, outv = Js[sat], qs[sat], rs[sat], mu[sat], out[sat]
                    free = (~outv).astype(float)
                    fixed = np.where(outv, np.clip(qn[sat], slo, shi) - qv, 0.0)
                    qv2 = np.empty_like(qv)
                    act = slice(None)                      # rows re-solved: all, then those with new violations
                    for _ in range(2):
                        Ja, fa = Jv[act], free[act]
                        Jf = Ja * fa[:, None, :]
                        rr = rv[act] + (Ja @ fixed[act][..., None])[..., 0]
                        Jft = np.swapaxes(Jf, 1, 2)
                        A = Jf @ Jft
                        A[:, _I6, _I6] += muv[act][:, None]
                        qa = qv[act] + (Jft @ np.linalg.solve(A, -rr[..., None]))[..., 0] + fixed[act]
                        qv2[act] = qa
                        outa = ((qa < slo) | (qa > shi)) & (fa > 0)
                        more = np.flatnonzero(outa.any(axis=-1))
                        if not len(more):
                            break
                        act = more if isinstance(act, slice) else act[more]
                        outa = outa[more]
                        fixed[act] = np.where(outa, np.clip(qa[more], slo, shi) - qv[act], fixed[act])
                        free[act] = np.where(outa, 0.0, free[act])
                    qn[sat] = np.clip(qv2, slo, shi)
                # -- evaluate the trial points and the restarted slots in one call ----------------
                if anyfresh:
                    qe = q.copy()
                    qe[st] = qn
                else:
                    qe = qn
                rt, Jn, pet, ret = evaluate(qe, own)
                St = _sumsq(rt)
                ok = (St < S) | fresh
                lam = np.where(ok, np.maximum(lam * down, 1e-12), lam * up)
                age += 1
                if anyfresh:
                    lam[fresh], age[fresh] = damping, 0
                    fresh[:] = False
                if ok.all():
                    q, r, J, pe, re, S = qe, rt, Jn, pet, ret, St
                else:
                    q[ok], r[ok], J[ok], pe[ok], re[ok], S[ok] = qe[ok], rt[ok], Jn[ok], pet[ok], ret[ok], St[ok]
        ev_r = np.bincount(np.concatenate(evaluated), minlength=N).astype(np.int64)
        ev_j = ev_r.copy()
        if start is not None and (n > 6 or W is not None):   # self-motion towards the starts
            good = np.flatnonzero(best_m <= 1.0)
            if len(good):
                qg, extra = _toward_start(m, best_q[good].copy(), q0[good], pt[good], Rt[good], L, W,
                                          (tp, tr), slo, shi, periodic)
                best_q[good] = qg
                ev_r[good] += extra
                ev_j[good] += extra
    # verdict from the arm's own closed form (its elementwise frame), not the solver's products
    from fkopt.numerics.rotations import to_array
    qd = _public(m, best_q)
    if periodic.any():                                 # continuous joints: into [-180, 180)
        qd = np.where(periodic, (qd + 180.0) % 360.0 - 180.0, qd)
    qd = np.clip(qd, m.bounds[:, 0], m.bounds[:, 1])
    if N == 1 and W is None:                           # one pose: the same formulas on floats
        p1, R1, _ = m.frame_jacobian1(_internal(m, qd[0]).tolist())
        perr = np.array([math.dist(p1, pt[0].tolist())])
        rerr = np.array([math.hypot(*_rotation_error1(R1, Rt[0].tolist()))])
    else:
        pf, Rf = m.frame(qd)
        pf, Rf = np.stack(pf, axis=-1), to_array(Rf)
        dpf, ef = pf - pt, _rotation_error(Rf, Rt)
        if W is not None:
            dpf, ef = dpf * W[:3], ef * W[3:]
        perr = np.sqrt(_sumsq(dpf))
        rerr = np.sqrt(_sumsq(ef))
    ok = (perr <= tp) & (rerr <= tr) & m.in_bounds(qd)
    return InverseResult(
        mechanism=m.name, names=tuple(m.joint_names), joints=qd.reshape(shape + (n,)),
        position_error=perr.reshape(shape), rotation_error=rerr.reshape(shape),
        residual=np.maximum(perr / tp, rerr / tr).reshape(shape), solved=ok.reshape(shape),
        restarts=(used - K).reshape(shape),
        evaluations={"residual": ev_r.reshape(shape), "jacobian": ev_j.reshape(shape)},
        tol=(tp, tr))
