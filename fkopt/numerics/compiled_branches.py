"""Compiled kernels of :mod:`fkopt.kinematics.branches`: every IK solution of one pose by seeded restarts of
the one-pose loop, and branch following along a path.

Both are built on :func:`fkopt.numerics.compiled_ik._inverse_one` (the damped least-squares loop of
``fkopt.inverse``), one start per call:

* :func:`search` -- starts from the start table's configurations nearest to the target, then
  seeded hash draws (revolute joints over one turn, prismatic joints inside their limits); each
  start runs the loop without revolute limits (a solution is a solution modulo 2 pi; the limits
  are applied by the caller, which maps every solution into them), converged answers are wrapped
  into [-pi, pi) and merged when every joint agrees within ``merge_tol``; derived starts from
  each solution found (a window of joints drawn afresh, the others held) run window by window;
  the search stops at Pieper's bound (a certificate), or after ``patience`` consecutive starts
  that found nothing new when the count is a multiple of the chain's (the stopping rule, whose
  miss rate docs/robots.md measures against EAIK's analytic sets), or after ``max_starts``.
* :func:`into_limits` -- each solution's in-limit copy nearest 0, verified by FK of its public row.
* :func:`track` -- one path: each waypoint's loop starts at the previous answer (no table, no
  restarts), a waypoint passes when it converges and no joint moved more than ``max_step``; the
  first waypoint that does not pass is returned for the caller to explain (limit, singularity,
  unreachable) and re-seat.

Importing this module imports numba (as :mod:`fkopt.numerics.compiled`).
"""
from __future__ import annotations

import math

import numpy as np

from fkopt.numerics.compiled import _evaluate, _geodesic, _rotation_target, _uniform_hash
from fkopt.numerics.compiled_ik import _inverse_one, _nearest_into, _table_features
from fkopt.numerics.jit import njit                 # numba.njit with a cache that a corrupted file cannot break

TWO_PI = 2.0 * math.pi


@njit(cache=True)
def _wrap(x):
    """x into [-pi, pi)."""
    return (x + math.pi) % TWO_PI - math.pi


@njit(cache=True)
def _no_start_table(n):
    """_inverse_one's start arguments with no start table (these loops give their own starts):
    no neighbour rows, the table's arrays empty (compiled_ik.NO_TABLE), no features, screen or joints."""
    no_table = (np.zeros((12, 0)), np.zeros(0), np.zeros((12, 0), dtype=np.float32), np.zeros(0, dtype=np.float32),
                0.0, np.zeros((0, 12)), np.zeros((7, 0), dtype=np.float32), np.zeros(0, dtype=np.float32), 0.0)
    return np.empty((0, n)), no_table, np.zeros(12), np.zeros(0, dtype=np.float32), np.zeros((0, n))


@njit(cache=True)
def _search(chain, pose, Lw, W, tq, Ft, norms, wf, fmask, nn, seed, max_starts, patience, tp, tr, accept_p,
            accept_r, iterations, damping, down, up, step_cap, slo, shi, glo, ghi, revolute, merge_tol, growth,
            wfirst, wlast, hold, two_solution, bound, multiple, held_draws, held_iterations, polish,
            polish_iterations, sols, found_at, info):
    """Distinct converged solutions of one pose (internal units, revolute joints wrapped into
    [-pi, pi)) into ``sols`` (cap, n); returns how many. ``info`` = (starts run, converged
    starts, evaluations, starts after the last new solution, the start that found the last new
    one, 1 when ``bound`` > 0 distinct solutions were found -- all there are -- else 0);
    ``found_at[s]`` the start that found solution s (its gaps measure the stopping rule).
    ``two_solution[w]``: window w's subproblem has at most two solutions, so its derived starts from
    a solution are skipped once another known solution shares its held joints
    (:mod:`fkopt.kinematics.branch_structure`)."""
    n = glo.shape[0]
    m = chain[0].shape[0]
    T = np.empty((3, 3))
    _rotation_target(pose, T)
    pt = pose[:3].copy()
    near_idx = np.empty(nn, dtype=np.int64)
    if nn > 0:
        f = np.empty(12)
        _table_features(pt, T, wf, fmask, f)
        _nearest_into(Ft, norms, f, near_idx, np.empty(nn))
    q0, best, u, w = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    empty, no_table, no_feat, no_v32, no_tq = _no_start_table(n)
    r, J = np.empty(6), np.empty((6, n))
    p, R, ax, e = np.empty(3), np.empty((3, 3)), np.empty((m, 6)), np.empty(3)
    cap = sols.shape[0]
    k = 0
    since = 0
    converged = 0
    evals = 0
    last_new = -1
    runs = 0
    nw = wfirst.shape[0]                         # windows: joints wfirst[w] .. wlast[w] drawn afresh
    hlo, hhi = np.empty(n), np.empty(n)
    wdone = np.zeros(nw, dtype=np.int64)         # per window: the solutions whose derived starts are done
    cs, cw = -1, -1                              # the current (solution, window) pair; -1: none
    tries = 0                                    # draws of the current pair
    nb = 0                                       # table neighbours run so far
    draw = 0
    complete = 0
    for j in range(max_starts):
        if tries == 0:
            # the next pair: the first window (in the caller's order) with a solution not done, so
            # that a new solution takes the flips that reach most in one start before the rest;
            # a two-solution window whose other solution is known has nothing left to reach
            cs = -1
            for v in range(nw):
                while wdone[v] < k and two_solution[v] and _sibling_known(sols, k, wdone[v], wfirst[v], wlast[v],
                                                                           revolute, merge_tol):
                    wdone[v] += 1
                if wdone[v] < k:
                    cs, cw = wdone[v], v
                    break
        held = cs >= 0
        if held:
            # a found solution with one window of joints drawn afresh and the others held at its
            # values (their limits set to the value): the solutions that share the held joints
            # with it (a wrist flip, an elbow flip of three parallel axes) are the window's own
            # small subproblem, reached in a few steps, where uniform starts rarely land
            # (the window's values: the farthest from the solution's of 4 hash draws, so that the
            # start leaves its basin)
            s_, w_ = cs, cw
            far = -1.0
            for c in range(4):
                _uniform_hash(seed, 1 + w_ + nw * (4 * tries + c), s_, u)
                acc = 0.0
                for i in range(wfirst[w_], wlast[w_] + 1):
                    d = glo[i] + (ghi[i] - glo[i]) * u[i] - sols[s_, i]
                    if revolute[i]:
                        d = _wrap(d)
                    acc += d * d
                if acc > far:
                    far = acc
                    for i in range(n):
                        q0[i] = glo[i] + (ghi[i] - glo[i]) * u[i]
            for i in range(n):
                if wfirst[w_] <= i <= wlast[w_]:
                    hlo[i], hhi[i] = slo[i], shi[i]
                else:
                    q0[i] = sols[s_, i]
                    if hold[w_]:
                        hlo[i], hhi[i] = q0[i], q0[i]
                    else:
                        hlo[i], hhi[i] = slo[i], shi[i]
            if wfirst[w_] == 0 and wlast[w_] == n - 1 and revolute[0]:
                # the whole arm free, from the solution's first joint turned by pi: the other
                # shoulder side (its solutions share no joint with this one)
                q0[0] = sols[s_, 0] + math.pi
            tries += 1
        elif nb < nn:
            q0[:] = tq[near_idx[nb]]
            nb += 1
        else:
            _uniform_hash(seed, 0, draw, u)
            draw += 1
            for i in range(n):
                q0[i] = glo[i] + (ghi[i] - glo[i]) * u[i]
        if held:
            _, ev = _inverse_one(chain, pt, T, Lw, W, q0, 1, empty, 0, no_table, no_feat, no_v32, no_tq, seed, 0, 1,
                                 tp, tr, held_iterations, damping, down,
                                 up, step_cap, 0.0, hlo, hhi, glo, ghi, best)
        else:
            _, ev = _inverse_one(chain, pt, T, Lw, W, q0, 1, empty, 0, no_table, no_feat, no_v32, no_tq, seed, 0, 1,
                                 tp, tr, iterations, damping, down,
                                 up, step_cap, 0.0, slo, shi, glo, ghi, best)
        pe, re, _ = _evaluate(chain, best, pt, T, Lw, W, r, J, p, R, ax, e)
        if W[3] * W[4] * W[5] != 0.0:
            re = max(re, _geodesic(R, T))
        evals += ev + 1
        if not (pe <= accept_p and re <= accept_r) and pe + Lw * re <= polish * Lw:
            # close but not converged: a solution next to a singular configuration, where the
            # loop's steps shrink (two joints nearly aligned, a solution nearly double); the
            # loop goes on from there, unlimited (held joints freed: the answer is checked the same)
            q0[:] = best
            _, ev = _inverse_one(chain, pt, T, Lw, W, q0, 1, empty, 0, no_table, no_feat, no_v32, no_tq, seed, 0, 1,
                                 tp, tr, polish_iterations, damping, down, up, step_cap, 0.0, slo, shi, glo, ghi, best)
            pe, re, _ = _evaluate(chain, best, pt, T, Lw, W, r, J, p, R, ax, e)
            if W[3] * W[4] * W[5] != 0.0:
                re = max(re, _geodesic(R, T))
            evals += ev + 1
        runs += 1
        new = False
        if pe <= accept_p and re <= accept_r:
            converged += 1
            for i in range(n):
                w[i] = _wrap(best[i]) if revolute[i] else best[i]
            dup = False
            for s in range(k):
                if _agree(w, sols[s], revolute, merge_tol, n, n):
                    dup = True
                    break
            if not dup and k < cap:
                sols[k, :] = w
                found_at[k] = j
                k += 1
                new = True
                last_new = j
                if bound > 0 and k >= bound:
                    complete = 1
                    break
        if held and (new or tries >= held_draws[cw]):  # next pair after a new solution or the window's draws
            wdone[cw] += 1
            tries = 0
        # the stopping rule counts the neighbour and hash-draw starts only: the derived starts are
        # bounded (windows per solution) and run before them
        since = 0 if new else (since if held else since + 1)
        # nothing found yet: four times the patience before giving a pose up
        # a chain with Pieper's bound has a multiple of ``multiple`` distinct solutions
        # (branch_structure.structure): a count that is not has some missing, so its search goes on
        # (to max_starts)
        if since >= (patience if k > 0 else 4 * patience) and since >= growth * (last_new + 1) and \
                not (multiple > 1 and k % multiple != 0):
            break
    info[0], info[1], info[2], info[3], info[4], info[5] = runs, converged, evals, since, last_new, complete
    return k


@njit(cache=True)
def _agree(a, b, revolute, merge_tol, first, last):
    """Whether joints a and b agree within merge_tol (revolute ones modulo 2 pi) outside first..last."""
    for i in range(a.shape[0]):
        if first <= i <= last:
            continue
        d = a[i] - b[i]
        if revolute[i]:
            d = _wrap(d)
        if abs(d) > merge_tol:
            return False
    return True


@njit(cache=True)
def _sibling_known(sols, k, s, first, last, revolute, merge_tol):
    """Whether a known solution other than s agrees with s on every joint outside first..last."""
    for o in range(k):
        if o != s and _agree(sols[o], sols[s], revolute, merge_tol, first, last):
            return True
    return False


def search_plan(windows, hold, two_solution, draws, bound, multiple, held_iterations, polish, polish_iterations,
                revolute, lo, hi) -> dict:
    """The per-arm arrays of :func:`search`, built once per arm context: windows (first, last joint
    drawn afresh), whether the others are held, whether its subproblem has two solutions, draws
    per (solution, window) pair, Pieper's bound (0: none) and the number the count of solutions is
    a multiple of (1: none known), iterations of a derived start, the residual below which a start
    that did not converge is iterated on (``polish``, in length units: position + scaled
    rotation) and how far, and the unlimited saturation bounds of revolute joints (the search
    solves modulo 2 pi)."""
    return {"wfirst": np.array([w[0] for w in windows], dtype=np.int64),
            "wlast": np.array([w[1] for w in windows], dtype=np.int64),
            "hold": np.array(hold, dtype=np.bool_).reshape(len(windows)),
            "two": np.array(two_solution, dtype=np.bool_).reshape(len(windows)),
            "draws": np.array(draws, dtype=np.int64).reshape(len(windows)), "bound": int(bound),
            "multiple": int(multiple), "held_iterations": int(held_iterations), "polish": float(polish),
            "polish_iterations": int(polish_iterations),
            "slo": np.where(revolute, -np.inf, lo), "shi": np.where(revolute, np.inf, hi)}


def search(ctx, plan, pose, L, W, nn, seed, max_starts, patience, tol, accept, iterations, damping, down, up,
           step_cap, glo, ghi, revolute, merge_tol, cap, growth):
    """:func:`_search` of one pose row with the per-arm constants ``ctx``
    (:func:`fkopt.kinematics.branches._context`) and its :func:`search_plan`:
    (solutions (k, n) internal units, the start that found each (k,), info (6,))."""
    n = ctx["n"]
    sols, info, found_at = np.empty((cap, n)), np.zeros(6), np.zeros(cap, dtype=np.int64)
    k = _search(ctx["chain"], pose, float(L), W, ctx["tq"], ctx["Ft"], ctx["norms"], ctx["w"], ctx["fmask"], int(nn),
                int(seed), int(max_starts), int(patience), float(tol[0]), float(tol[1]), float(accept[0]),
                float(accept[1]), int(iterations), float(damping), float(down), float(up), float(step_cap),
                plan["slo"], plan["shi"], glo, ghi, revolute, float(merge_tol), float(growth), plan["wfirst"],
                plan["wlast"], plan["hold"], plan["two"], plan["bound"], plan["multiple"], plan["draws"],
                plan["held_iterations"],
                plan["polish"], plan["polish_iterations"], sols, found_at, info)
    return sols[:k].copy(), found_at[:k].copy(), info


@njit(cache=True)
def _into_limits(sols, k, free, full, angle, revolute, periodic, lo, hi, blo, bhi, chain, pose, W, rows, errs,
                 status):
    """Each of the first k wrapped solutions (free joints, internal units) as one public row
    (deg / length unit, the locked joints' values from ``full``) into ``rows``: every revolute
    joint moved by whole turns to its in-limit value nearest 0 (a periodic joint as it is), then
    verified by FK of that public row against ``pose`` -- (position, rotation) errors into
    ``errs``, the rotation error the larger of the rotation vector's norm and the geodesic angle
    when the whole rotation is asked for. ``status``: 0 a row, 1 out of the limits (a joint with
    no in-limit copy). :func:`fkopt.kinematics.branches._in_limit_copies` and ``_verify`` do the
    same in Python for ``copies=True``."""
    n = full.shape[0]
    m = chain[0].shape[0]
    T = np.empty((3, 3))
    _rotation_target(pose, T)
    pt = pose[:3].copy()
    t = np.empty(n)
    r, J = np.empty(6), np.empty((6, n))
    p, R, ax, e = np.empty(3), np.empty((3, 3)), np.empty((m, 6)), np.empty(3)
    d2r, r2d = math.pi / 180.0, 180.0 / math.pi
    for s in range(k):
        status[s] = 0
        for i in range(free.shape[0]):
            v = sols[s, i]
            if periodic[i]:
                x = v
            elif not revolute[i]:
                if not (lo[i] - 1e-12 <= v <= hi[i] + 1e-12):
                    status[s] = 1
                    break
                x = v
            else:
                k0 = math.ceil((lo[i] - v) / TWO_PI - 1e-12)
                k1 = math.floor((hi[i] - v) / TWO_PI + 1e-12)
                if k1 < k0:
                    status[s] = 1
                    break
                x = min(max(v + TWO_PI * k0, lo[i]), hi[i])
                for c in range(k0 + 1, k1 + 1):
                    y = min(max(v + TWO_PI * c, lo[i]), hi[i])
                    if abs(y) < abs(x):
                        x = y
            full[free[i]] = x
        if status[s] == 1:
            continue
        for i in range(n):
            u = full[i] * r2d if angle[i] else full[i]
            u = min(max(u, blo[i]), bhi[i])
            rows[s, i] = u
            t[i] = u * d2r if angle[i] else u
        pe, re, _ = _evaluate(chain, t, pt, T, 1.0, W, r, J, p, R, ax, e)
        if W[3] * W[4] * W[5] != 0.0:
            re = max(re, _geodesic(R, T))
        errs[s, 0], errs[s, 1] = pe, re
    return 0


def into_limits(sols, free, full, angle, revolute, periodic, lo, hi, blo, bhi, chain, pose, W):
    """:func:`_into_limits` of the solutions ``sols`` (k, free): (rows (k, n) public, errors (k, 2), status (k,))."""
    k = len(sols)
    rows, errs, status = np.empty((k, len(full))), np.zeros((k, 2)), np.zeros(k, dtype=np.int64)
    _into_limits(np.ascontiguousarray(sols), k, free, full.copy(), angle, revolute, periodic, lo, hi, blo, bhi, chain,
                 pose, W, rows, errs, status)
    return rows, errs, status


@njit(cache=True)
def _track(chain, poses, first, q, Lw, W, tp, tr, iterations, damping, down, up, step_cap, lo, hi, slo, shi,
           max_step, predict, out, errs):
    """Follow the branch through waypoints first, first + 1, ... of ``poses`` from joints ``q``
    (internal units, updated in place): each waypoint's loop starts at the previous answer plus
    the previous step (a linear predictor), saturating at [slo, shi] (a redundant arm's self-motion then keeps off its limits; +-inf
    for a non-redundant arm, which has none), the limits [lo, hi] checked after. Answers into ``out`` rows and their
    (position, rotation) errors into ``errs``; returns the first waypoint that did not pass
    (no convergence within tol, a joint step above ``max_step``, or a joint outside [lo, hi]),
    or len(poses) when all passed. ``out`` of the failing row holds the loop's answer."""
    n = q.shape[0]
    m = chain[0].shape[0]
    T = np.empty((3, 3))
    best = np.empty(n)
    empty, no_table, no_feat, no_v32, no_tq = _no_start_table(n)
    r, J = np.empty(6), np.empty((6, n))
    p, R, ax, e = np.empty(3), np.empty((3, 3)), np.empty((m, 6)), np.empty(3)
    vel = np.zeros(n)
    q0 = np.empty(n)
    for k in range(first, poses.shape[0]):
        _rotation_target(poses[k], T)
        pt = poses[k, :3].copy()
        # predictor: the previous step continued (zero on the first waypoint of a call), then the
        # loop corrects; where two branches meet at a singularity (an elbow passing straight) the
        # predicted start lies on the branch the path was on, where the previous answer alone is
        # as near to the other
        for i in range(n):
            q0[i] = q[i] + vel[i]
        _inverse_one(chain, pt, T, Lw, W, q0, 1, empty, 0, no_table, no_feat, no_v32, no_tq, 0, 0, 1, tp, tr,
                     iterations, damping, down, up, step_cap, 0.0,
                     slo, shi, lo, hi, best)
        pe, re, _ = _evaluate(chain, best, pt, T, Lw, W, r, J, p, R, ax, e)
        if W[3] * W[4] * W[5] != 0.0:
            re = max(re, _geodesic(R, T))
        out[k, :] = best
        errs[k, 0], errs[k, 1] = pe, re
        big = 0.0
        inside = True
        for i in range(n):
            big = max(big, abs(best[i] - q[i]))
            inside = inside and lo[i] <= best[i] <= hi[i]
        if not (pe <= tp and re <= tr) or big > max_step or not inside:
            return k
        if predict:
            for i in range(n):
                vel[i] = best[i] - q[i]
        q[:] = best
    return poses.shape[0]


def track(chain, poses, first, q, L, W, tol, iterations, damping, down, up, step_cap, lo, hi, slo, shi, max_step,
          out, errs, predict=True):
    """:func:`_track` with typed arguments; returns the first waypoint that did not pass."""
    return _track(chain, poses, int(first), q, float(L), W, float(tol[0]), float(tol[1]), int(iterations),
                  float(damping), float(down), float(up), float(step_cap), lo, hi, slo, shi, float(max_step),
                  bool(predict), out, errs)
