"""``fkopt.inverse`` of a batch of poses (or of one pose with ``rest`` > 0 or ``exact_rotation``):
every row as its compiled one-pose call when it can (:func:`fkopt.numerics.compiled_ik.inverse_rows`,
rows shared by ``threads`` threads), else the vectorised damped least-squares loop on numpy, candidates of many
rows side by side (see :mod:`fkopt.kinematics.solvers`).

Its restarts are the one restart loop's (:mod:`fkopt.numerics.restart_loop`) -- a row's starts in the
same order (``start``, the start table's nearest, seeded draws), the first converged answer
retiring the row, the best by max(pe / tol[0], re / tol[1]) kept -- but asynchronous: a candidate
that stalls restarts in place while the others step on, and small batches run several candidates
of a row at once (``fill``, ``tail``). Which candidate of a row converges first thus depends on
the batch, so this loop is not the sequential one driven row by row: that would move the answers
of stored batches (tests/inverse_bits, results/).
"""
from __future__ import annotations

import math

import numpy as np

from fkopt.files.host import available_cpus
from fkopt.kinematics.inverse_pose import _I6, _fast_context, _toward_start
from fkopt.kinematics.results import InverseResult
from fkopt.kinematics.inputs import _internal, _public
from fkopt.kinematics.start_tables import _TREE_MIN, _masked_table, _nearest, _start_table, _sumsq, _uniform_hash
from fkopt.numerics import path as numerics_path
from fkopt.numerics import rotations
from fkopt.numerics.damped_least_squares import inverse_candidates
from fkopt.numerics.rotations import rotation_error1, so3_right_jacobian_inverse


def inverse_batch(m, P, shape, q0, start, W, tol, seed, lo, hi, mid, half, periodic, slo, shi, *, restarts, starts,
                  rest, orientation_scale, iterations, damping, step_cap, down, up, stall, fill, exact_rotation, table,
                  neighbours, tail, compiled, threads=None) -> InverseResult:
    """Rows P (N, 6 or 12) of checked targets (within reach) from start rows q0 (N, n) in internal
    units, task mask W (or None), limits and saturation bounds in internal units: the answer as
    :func:`fkopt.kinematics.solvers.inverse` returns it, reshaped to ``shape``. ``threads``: threads
    sharing the rows of the compiled path (None: the CPUs this process may run on); the answers
    do not depend on it, and the numpy path runs on this thread alone."""
    tp, tr = tol
    N, n = len(P), m.dof
    reach = m.reach
    fast = numerics_path.compiled_ik(compiled) if hasattr(m, "chain") else None
    if fast is not None and rest <= 0 and not exact_rotation and (start is None or (n <= 6 and W is None)):
        # every row as its one-pose call (same starts, restarts and answer), rows shared by threads
        own0 = 1 if (start is not None or not table) else 0
        first = max(1, int(starts), fill)
        nn = min(int(table), first - own0 + int(neighbours)) if table else 0
        ctx = _fast_context(m, int(table), W)
        out, info = fast.inverse_rows(ctx, np.ascontiguousarray(P, dtype=float),
                                      float(orientation_scale) if orientation_scale else reach, ctx["W"],
                                      np.ascontiguousarray(q0, dtype=float), own0, nn, int(seed),
                                      first + max(0, int(restarts)), (tp, tr), int(iterations), float(damping),
                                      float(down), float(up), float(step_cap), float(stall),
                                      available_cpus() if threads is None else int(threads))
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
    pt, Rt = P[:, :3], (P[:, 3:].reshape(N, 3, 3) if P.shape[1] == 12 else rotations.zyz_rows(P[:, 3:]))
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
        e = rotations.rotation_error_rows(R, Rt[rows])
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

    def trial(Js, rs, qs, lam_s, S_s):
        """The damped least-squares trial points of slots (J, r, q, lambda, |r|^2): one step with
        the null-space pull (``rest``), the step cap and saturation in the null space."""
        Jt_ = np.swapaxes(Js, 1, 2)
        A = Js @ Jt_
        tr6 = np.trace(A, axis1=1, axis2=2) * (1.0 / 6.0)
        if rest > 0:                               # projector onto the null space of J
            # fading as |r| drops below 1 length unit: at the end the task alone converges
            z = (rest * np.minimum(1.0, np.sqrt(S_s)))[:, None] * (mid - qs) / (half * half)
            A[:, _I6, _I6] += 1e-9 * tr6[:, None]
            dz = z - (Jt_ @ np.linalg.solve(A, Js @ z[..., None]))[..., 0]
            A[:, _I6, _I6] -= 1e-9 * tr6[:, None]
        mu = lam_s * tr6                           # damping scaled to J
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
        return qn

    if N == 1 and rest <= 0 and not exact_rotation and W is None:
        def start_of(j):
            return starts_for(np.zeros(1, dtype=np.intp), np.array([j]))[0].tolist()

        bq, nused, ne = inverse_candidates(m.frame_jacobian1, pt[0].tolist(), Rt[0].tolist(), L, start_of, budget,
                                           (tp, tr), iterations, damping, down, up, step_cap, stall, slo.tolist(),
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
        s1, s2 = np.full(len(q), np.inf), np.full(len(q), np.inf)   # |r|^2 one and two evaluations before
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
                if stall > 0:                              # the stall test, but not on a row's last start
                    stuck |= (S > stall * s2) & (used[own] < budget) & ~fresh
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
                        own, q, r, J, pe, re, lam, S, s1, s2, age, fresh = (
                            a[live] for a in (own, q, r, J, pe, re, lam, S, s1, s2, age, fresh))
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
                        s1, s2 = np.concatenate([s1, np.empty(k)]), np.concatenate([s2, np.empty(k)])
                        age = np.concatenate([age, np.empty(k, dtype=np.int64)])
                        fresh = np.concatenate([fresh, np.ones(k, dtype=bool)])
                if not len(own):
                    break
                # -- one damped least-squares step with saturation in the null space --------------
                anyfresh = fresh.any()
                st = np.flatnonzero(~fresh) if anyfresh else slice(None)
                Js, rs, qs = J[st], r[st], q[st]
                qn = trial(Js, rs, qs, lam[st], S[st])
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
                s1, s2 = S.copy(), s1
                if anyfresh:
                    lam[fresh], age[fresh] = damping, 0
                    s1[fresh], s2[fresh] = np.inf, np.inf
                    fresh[:] = False
                if ok.all():
                    q, r, J, pe, re, S = qe, rt, Jn, pet, ret, St
                else:
                    q[ok], r[ok], J[ok], pe[ok], re[ok], S[ok] = qe[ok], rt[ok], Jn[ok], pet[ok], ret[ok], St[ok]
        fail = np.flatnonzero(~done)
        if stall > 0 and budget > 1 and len(fail):
            # every start of these rows failed: their best answers, most likely ended by the stall
            # test, go on without it (the one-pose loop's last step, fkopt.numerics.compiled_ik)
            q = best_q[fail].copy()
            r, J, pe, re = evaluate(q, fail)
            S, lam = _sumsq(r), np.full(len(fail), damping)
            with np.errstate(all="ignore"):
                for _ in range(iterations):
                    a = np.flatnonzero(((pe > tp) | (re > tr)) & (lam <= 1e6))
                    if not len(a):
                        break
                    qn = trial(J[a], r[a], q[a], lam[a], S[a])
                    rt, Jn, pet, ret = evaluate(qn, fail[a])
                    St = _sumsq(rt)
                    ok = St < S[a]
                    lam[a] = np.where(ok, np.maximum(lam[a] * down, 1e-12), lam[a] * up)
                    u = a[ok]
                    q[u], r[u], J[u], pe[u], re[u], S[u] = qn[ok], rt[ok], Jn[ok], pet[ok], ret[ok], St[ok]
            merit = np.maximum(pe / tp, re / tr)
            better = merit < best_m[fail]
            best_q[fail[better]], best_m[fail[better]] = q[better], merit[better]
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
    qd = _public(m, best_q)
    if periodic.any():                                 # continuous joints: into [-180, 180)
        qd = np.where(periodic, (qd + 180.0) % 360.0 - 180.0, qd)
    qd = np.clip(qd, m.bounds[:, 0], m.bounds[:, 1])
    if N == 1 and W is None:                           # one pose: the same formulas on floats
        p1, R1, _ = m.frame_jacobian1(_internal(m, qd[0]).tolist())
        perr = np.array([math.dist(p1, pt[0].tolist())])
        rerr = np.array([math.hypot(*rotation_error1(R1, Rt[0].tolist()))])
    else:
        pf, Rf = m.frame(qd)
        pf, Rf = np.stack(pf, axis=-1), rotations.to_array(Rf)
        dpf, ef = pf - pt, rotations.rotation_error_rows(Rf, Rt)
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
