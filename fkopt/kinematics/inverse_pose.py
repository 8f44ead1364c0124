"""``fkopt.inverse`` of one pose: the candidates of the one restart loop one after another on
Python floats (:func:`fkopt.numerics.damped_least_squares.inverse_candidates`) or compiled
(:func:`fkopt.numerics.compiled_ik.inverse_pose`), the per-arm constants both take, and the
self-motion step towards a given start (:func:`_toward_start`, shared with the batched loop)."""
from __future__ import annotations

import math

import numpy as np

from fkopt.errors import FkoptError
from fkopt.kinematics.inputs import _internal, _public, _unreachable, _values
from fkopt.kinematics.results import InverseResult
from fkopt.kinematics.start_tables import _masked_table, _nearest, _start_table, _sumsq, _uniform_hash
from fkopt.numerics import path as numerics_path
from fkopt.numerics import rotations
from fkopt.numerics.damped_least_squares import inverse_candidates
from fkopt.numerics.rotations import rotation_error1

_I6 = np.arange(6)


def _solved1(p, R, pt, Rt, W, tol) -> bool:
    """Whether frame (p, R) on floats is within tol of target (pt, Rt), task mask W (or None)."""
    dp = [a - b for a, b in zip(p, pt)]
    e = rotation_error1(R, Rt)
    if W is not None:
        dp, e = [v * w for v, w in zip(dp, W[:3])], [v * w for v, w in zip(e, W[3:])]
    return math.hypot(*dp) <= tol[0] and math.hypot(*e) <= tol[1]


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
        e = rotations.rotation_error_rows(R, Rt)
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
    """Per-arm constants of the compiled one-pose call (:func:`fkopt.numerics.compiled_ik.inverse_pose`),
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
        from fkopt.numerics.compiled_ik import start_screen  # lazy: numba (the compiled nearest-neighbour search)
        got["table"] = start_screen(got["Ft"], got["norms"], w)
    return got


def _fast_result(m, answer, tp: float, tr: float) -> InverseResult:
    """The :class:`InverseResult` of one compiled call's (public joints, info)
    (:func:`fkopt.numerics.compiled_ik.inverse_pose`)."""
    out, info = answer
    perr, rerr, used, ev = float(info[0]), float(info[1]), int(info[3]), np.array(int(info[4]), dtype=np.int64)
    return InverseResult(
        mechanism=m.name, names=tuple(m.joint_names), joints=out, position_error=np.array(perr),
        rotation_error=np.array(rerr), residual=np.array(max(perr / tp, rerr / tr)),
        solved=np.array(perr <= tp and rerr <= tr and info[2] > 0), restarts=np.array(used - 1, dtype=np.int64),
        evaluations={"residual": ev, "jacobian": ev.copy()}, tol=(tp, tr))


def _inverse_one(m, pose, start, tol, seed, budget, table, kn, orientation_scale, iterations, damping,
                 down, up, step_cap, stall, W=None, compiled=None) -> InverseResult:
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
    fast = numerics_path.compiled_ik(compiled) if hasattr(m, "chain") else None
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
                                                 float(step_cap), float(stall)), tp, tr)
    Rt = pose[3:].reshape(3, 3).tolist() if len(pose) == 12 else rotations.zyz1(*pose[3:].tolist())
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
                                        damping, down, up, step_cap, stall, c["slo"], c["shi"], lo, hi)
    else:
        bq, used, ne = inverse_candidates(m.frame_jacobian1, [float(v) for v in pose[:3]], Rt, L, start_of, budget,
                                          tol, iterations, damping, down, up, step_cap, stall, c["slo"].tolist(),
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
    e = rotation_error1(R1, Rt)
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
