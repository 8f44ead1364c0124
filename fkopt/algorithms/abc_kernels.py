"""One iteration of :meth:`fkopt.algorithms.abc.ABC.iterate` (scout, employed, onlooker; GABC's
best-so-far refreshed between the phases) compiled by numba, every run in one pass per phase, on a
mechanism's compiled fitness (:class:`fkopt.mechanisms.base.CompiledFitness`, wired as function
objects: this module knows no mechanism): the same draws in one block per iteration, the same
operations in numpy's order, the mechanism's numpy ufunc between the kernels, the evaluation log's
bookkeeping and the best-so-far inside -- the numpy path's bits (tests/test_numerics.py).
:func:`abc_iterations` runs many such iterations per call, numpy's ufunc loop called from compiled
code between the phases (:mod:`fkopt.numerics.ufunc_loop`), with
:meth:`fkopt.algorithms.base.Algorithm.minimize`'s bookkeeping after each: at 30 runs the dispatch
and the Python around the kernels were half an iteration's time.

Importing this module imports numba: :meth:`fkopt.algorithms.abc.ABC.iterate` imports it only once
the compiled path runs (:func:`fkopt.algorithms.base.compiled_step`).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from fkopt.algorithms.kernels import fold_best, kept, log_points, scratch_arrays
from fkopt.numerics.jit import njit


@njit(cache=True, error_model="numpy")
def _move(xs, xk, xb, phi, psi, rule):
    """The neighbour move of :meth:`fkopt.algorithms.abc.ABC.move` (rule 0) and
    :meth:`fkopt.algorithms.gabc.GABC.move` (1: mao2017 eq. 19, 2: zhu2010 with psi = C u) on one
    coordinate, numpy's operations in their order, before clipping."""
    out = (xs - xk) * phi
    if rule == 1:
        out = out + (xb - xk) * phi
    elif rule == 2:
        out = out + (xb - xs) * psi
    return xs + out


@lru_cache(maxsize=8)
def _kernels(prepare, value):
    """The phase kernels on the fitness stages ``prepare`` and ``value`` (compiled once per
    process and fitness; numba's cache keys them by those kernels' code, :func:`fkopt.numerics.jit.njit`)."""

    @njit(cache=True, error_model="numpy")
    def moves(x, best_x, u, o, a, src, rule, C, lo, hi, jj, mv, arg, base, n, block, y):
        """The moves of one phase of run ``a`` (uniforms of the block at ``u[a, o:]``): bee i moves
        coordinate j of source src[i] against a neighbour k != src[i], clipped, into jj[a], mv[a];
        the candidate (the source with that coordinate moved) is pose base + i of a fitness call
        over poses [0, n), whose fitness arguments go into ``arg``. ``y``: a scratch pose (3,)."""
        pop, dim = x.shape[1], x.shape[2]
        zhu = rule == 2
        for i in range(pop):
            s = src[i]
            j = int(u[a, o + i] * dim)
            k = int(u[a, o + pop + i] * (pop - 1))
            k += k >= s                # branch-free: a random comparison mispredicts half the time
            phi = u[a, o + 2 * pop + i] * 2.0 - 1.0
            psi = C * u[a, o + 3 * pop + i] if zhu else 0.0
            m = _move(x[a, s, j], x[a, k, j], best_x[a, j], phi, psi, rule)
            m = min(max(m, lo[j]), hi[j])
            jj[a, i] = j
            mv[a, i] = m
            # the candidate through memory, not `m if j == 0 else ...`: LLVM makes those branches, and a
            # random coordinate mispredicts (~5 ns a move, measured)
            y[0], y[1], y[2] = x[a, s, 0], x[a, s, 1], x[a, s, 2]
            y[j] = m
            prepare(y[0], y[1], y[2], arg, base + i, 0, n, block)

    @njit(cache=True, error_model="numpy")
    def employed_move(x, trial, best_x, u, limit, rule, C, lo, hi, separate, jj, mv, scout, arg, block):
        """Scout and employed moves for every run, up to the ufunc. ``u`` (runs, D): the iteration's
        uniforms of each run in the order of the abc module's docstring (scout dim, employed 3 SN
        [+ SN psi], onlooker SN roulette, 3 SN [+ SN psi]). The scout (the source with the most
        trials, first of equals, if they exceed limit) is placed in x, its trials reset, scout[a]
        its source's index or -1; the employed bees' moves go into jj, mv (all from the sources as
        they stand, the scout's fresh one included). The arguments go into ``arg`` as the numpy
        path's fitness calls see them: candidates as poses [0, runs SN), the fresh scouts, in run
        order, after them in the same call (``separate`` False) or in a call of their own (True: a
        target per row). Returns the number of scouts."""
        runs, pop, dim = x.shape
        n = runs * pop
        src = np.arange(pop)
        y = np.empty(3)
        ns = 0
        for a in range(runs):
            scout[a] = -1
            s = 0
            over = False
            for i in range(pop):
                if trial[a, i] > limit:
                    over = True
                if trial[a, i] > trial[a, s]:
                    s = i
            if over:
                for d in range(dim):
                    x[a, s, d] = lo[d] + u[a, d] * (hi[d] - lo[d])
                trial[a, s] = 0
                scout[a] = s
                ns += 1
        # the calls' extents chosen once, outside the loops (a conditional expression among a
        # call's arguments in the loop doubled a move's time, measured)
        sl = n if separate else n + ns                     # the employed candidates' call
        s0, sl_scout = (n, ns) if separate else (0, n + ns)   # the scouts' call
        for a in range(runs):
            moves(x, best_x, u, dim, a, src, rule, C, lo, hi, jj, mv, arg, a * pop, sl, block, y)
        c = n
        for a in range(runs):
            s = scout[a]
            if s >= 0:
                prepare(x[a, s, 0], x[a, s, 1], x[a, s, 2], arg, c, s0, sl_scout, block)
                c += 1
        return ns

    @njit(cache=True, error_model="numpy")
    def employed_finish(x, f, trial, best_x, best_f, u, rule, C, lo, hi, J, params, absolute, separate, ns, jj, mv,
                        scout, out, fe, fo_src, fo_jj, fo_mv, arg, lbest, lcount, lactive, hr, he, hf, nh, block):
        """After the ufunc on :func:`employed_move`'s arguments, for every run: the fitness of the
        fresh scout and of the employed candidates (NaN read as +inf, as ``np.fmin(f, inf)``) into
        fe, the greedy selection, the reports to the evaluation log held as arrays (employed, then
        the scout: :func:`log_points`), GABC's best-so-far (rules 1, 2), the onlookers' roulette
        into fo_src and their moves into fo_jj, fo_mv with their arguments in ``arg`` (one call of
        runs SN poses). ``nh``: the improvements kept so far in hr, he, hf; returns their number after
        this phase."""
        runs, pop, dim = x.shape
        n = runs * pop
        one = J.shape[1] == 1
        block4 = (4 if rule == 2 else 3) * pop
        cdf = np.empty(pop)
        fs = np.empty(1)
        y = np.empty(3)
        c_scout = n
        sl = n if separate else n + ns                     # as employed_move: outside the loops
        s0, sl_scout = (n, ns) if separate else (0, n + ns)
        for a in range(runs):
            c = 0 if one else a * pop
            j0, j1, j2 = J[0, c], J[1, c], J[2, c]
            s = scout[a]
            if s >= 0:
                g = value(out, c_scout, s0, sl_scout, block, x[a, s, 0], x[a, s, 1], x[a, s, 2], j0, j1, j2, params,
                          absolute)
                c_scout += 1
                if g != g:
                    g = np.inf
                fs[0] = g
                f[a, s] = g
            # candidate i is source i with coordinate jj[i] moved; the greedy step of bee i changes
            # source i only (the moves read the sources before any of them changed, as numpy's
            # vectorised phase)
            for i in range(pop):
                j = jj[a, i]
                y[0], y[1], y[2] = x[a, i, 0], x[a, i, 1], x[a, i, 2]
                y[j] = mv[a, i]
                g = value(out, a * pop + i, 0, sl, block, y[0], y[1], y[2], j0, j1, j2, params, absolute)
                if g != g:
                    g = np.inf
                fe[a, i] = g
                # the greedy step as selects on loaded values (a branch on a random win mispredicts)
                fi, xi, ti = f[a, i], x[a, i, j], trial[a, i]
                win = g < fi
                f[a, i] = g if win else fi
                x[a, i, j] = mv[a, i] if win else xi
                trial[a, i] = 0 if win else ti + 1
            nh = log_points(a, fe[a], lbest, lcount, lactive, hr, he, hf, nh)
            if s >= 0:
                nh = log_points(a, fs, lbest, lcount, lactive, hr, he, hf, nh)
            if rule != 0:     # Algorithm.update_best between the phases (f holds no NaN: fmin'd, g's NaN is inf)
                fold_best(a, x, f, best_x, best_f)
            # -- onlookers: roulette on the qualities 1/(1+f) (1-f below 0), cumulated in order
            o = dim + block4
            acc = 0.0
            for i in range(pop):
                q = 1.0 / (1.0 + f[a, i]) if f[a, i] >= 0 else 1.0 - f[a, i]
                acc = acc + q
                cdf[i] = acc
            src = fo_src[a]
            for i in range(pop):
                w = u[a, o + i] * cdf[pop - 1]
                # the first index with cdf > w = the count of cdf <= w (cdf is sorted): a branch-free
                # count for small colonies (a binary search mispredicts a branch per level), a binary
                # search for large ones, as abc.roulette
                if pop <= 32:
                    n_le = 0
                    for q_i in range(pop):
                        n_le += cdf[q_i] <= w
                else:
                    n_le, hi_i = 0, pop
                    while n_le < hi_i:
                        mid = (n_le + hi_i) // 2
                        if cdf[mid] <= w:
                            n_le = mid + 1
                        else:
                            hi_i = mid
                src[i] = 0 if n_le == pop else n_le
            moves(x, best_x, u, o + pop, a, src, rule, C, lo, hi, fo_jj, fo_mv, arg, a * pop, n, block, y)
        return nh

    @njit(cache=True, error_model="numpy")
    def onlooker_finish(x, f, trial, J, params, absolute, src_all, jj_all, mv_all, out, fo, best_x, best_f, lbest,
                        lcount, lactive, hr, he, hf, nh, block, scout, evals, new_evals):
        """After the ufunc on the onlookers' candidates, for every run: their fitness into fo, the
        reports to the log, then the synchronous onlookers -- per source the lowest candidate, the
        first onlooker reaching it, if it beats the source; a trial per attempt -- and the sources
        folded into the best-so-far (:func:`fold_best`, what minimize's update_best does next); the
        runs' evaluations after the iteration (2 SN, one more where a scout flew) into new_evals.
        Returns nh."""
        runs, pop, dim = x.shape
        n = runs * pop
        one = J.shape[1] == 1
        bs = np.empty(pop)
        first = np.empty(pop, dtype=np.int64)
        y = np.empty(3)
        for a in range(runs):
            c = 0 if one else a * pop
            j0, j1, j2 = J[0, c], J[1, c], J[2, c]
            src, jj, mv = src_all[a], jj_all[a], mv_all[a]
            for i in range(pop):
                s = src[i]
                y[0], y[1], y[2] = x[a, s, 0], x[a, s, 1], x[a, s, 2]
                y[jj[i]] = mv[i]
                g = value(out, a * pop + i, 0, n, block, y[0], y[1], y[2], j0, j1, j2, params, absolute)
                if g != g:
                    g = np.inf
                fo[a, i] = g
            nh = log_points(a, fo[a], lbest, lcount, lactive, hr, he, hf, nh)
            for i in range(pop):
                bs[i] = np.inf
                first[i] = pop
            for i in range(pop):         # selects on loaded values, as the employed phase's greedy step
                s, g = src[i], fo[a, i]
                b = bs[s]
                bs[s] = g if g < b else b
            for i in range(pop):
                s = src[i]
                fs_ = first[s]
                first[s] = i if (fo[a, i] == bs[s]) & (fs_ == pop) else fs_
                trial[a, s] += 1
            for s in range(pop):
                if bs[s] < f[a, s]:
                    w_ = first[s]
                    x[a, s, jj[w_]] = mv[w_]
                    f[a, s] = bs[s]
                    trial[a, s] = 0
            fold_best(a, x, f, best_x, best_f)
            new_evals[a] = evals[a] + (2 * pop + (1 if scout[a] >= 0 else 0))
        return nh

    return employed_move, employed_finish, onlooker_finish


def _phase_arrays(runs, pop, width, bounds, room):
    """The phase kernels' scratch (jj, fo_jj, fo_src, mv, fo_mv, fe, fo, scout, the ufunc's argument and
    value buffers, the log's improvements hr, he, hf with ``room`` places, lo, hi)."""
    n = runs * pop
    return ([np.empty((runs, pop), dtype=np.int64) for _ in range(3)]
            + [np.empty((runs, pop)) for _ in range(4)]
            + [np.empty(runs, dtype=np.int64), np.empty(width * (n + runs)), np.empty(width * (n + runs)),
               np.empty(room, dtype=np.intp), np.empty(room, dtype=np.int64), np.empty(room),
               np.ascontiguousarray(bounds[:, 0], dtype=float), np.ascontiguousarray(bounds[:, 1], dtype=float)])


def abc_iteration(fitness):
    """One ABC or GABC iteration on ``fitness`` (a :class:`fkopt.mechanisms.base.CompiledFitness`):
    ``step(x, f, trial, best_x, best_f, u, limit, rule, C, bounds, J, absolute, log, separate, evaluations)`` runs
    :func:`employed_move`, the ufunc, :func:`employed_finish`, the ufunc, :func:`onlooker_finish` on
    the state arrays x, f, trial (C-contiguous, updated in place) and best_x, best_f (updated in
    place: pass copies; GABC's refresh between the phases and minimize's update_best after the
    iteration both folded in), reporting to ``log`` (best (runs,) float, count (runs,) int64, active
    (runs,) bool, updated in place). ``rule``: the move (0 ABC, 1 GABC mao2017, 2 GABC zhu2010);
    ``separate``: the numpy path evaluates the fresh scouts in a fitness call of their own (a target
    per row); ``evaluations``: the runs' counts before the iteration. Returns (the counts after it,
    a new array; (rows, evaluation numbers, values) of the improvements the log keeps)."""
    employed_move, employed_finish, onlooker_finish = _kernels(fitness.prepare, fitness.value)
    ufunc, width, block, params = fitness.ufunc, fitness.width, fitness.block, fitness.params

    def step(x, f, trial, best_x, best_f, u, limit, rule, C, bounds, J, absolute, log, separate, evaluations):
        runs, pop = f.shape
        n = runs * pop
        separate = bool(separate)
        J = np.ascontiguousarray(J, dtype=float)
        absolute, C, limit, rule = bool(absolute), float(C), int(limit), int(rule)

        jj, fo_jj, fo_src, mv, fo_mv, fe, fo, scout, arg, out, hr, he, hf, lo, hi = scratch_arrays(
            ("abc", runs, pop, width, bounds.tobytes()),
            lambda: _phase_arrays(runs, pop, width, bounds, runs * (2 * pop + 1)))
        best, count, active = log
        ns = employed_move(x, trial, best_x, u, limit, rule, C, lo, hi, separate, jj, mv, scout, arg, block)
        ufunc(arg, out, ((0, n), (n, ns)) if separate else ((0, n + ns),), block)
        nh = employed_finish(x, f, trial, best_x, best_f, u, rule, C, lo, hi, J, params, absolute, separate, ns, jj,
                             mv, scout, out, fe, fo_src, fo_jj, fo_mv, arg, best, count, active, hr, he, hf, 0, block)
        ufunc(arg, out, ((0, n),), block)
        new_evals = np.empty(runs, dtype=np.int64)
        nh = onlooker_finish(x, f, trial, J, params, absolute, fo_src, fo_jj, fo_mv, out, fo, best_x, best_f, best,
                             count, active, hr, he, hf, nh, block, scout, evaluations, new_evals)
        return new_evals, kept(hr, he, hf, nh)
    return step


#: Places for the log's improvements in one :func:`abc_iterations` call, (per, extra): per times
#: one iteration's evaluations of every run, plus extra. Improvements are rare after the first
#: iterations; a call ends early (the caller calls again) when the next iteration's might not fit.
LOG_ROOM = (2, 4096)
#: x_history of a solve that keeps none (the kernel writes it only when it has columns).
_NO_X = np.empty((1, 0, 3))

#: The uniforms one :func:`abc_iterations` call takes at most, over all runs (values; 256 kB): the
#: block stays in cache beside the state, and at many rows a call is one iteration anyway.
ITERATIONS_UNIFORMS = 1 << 15


@lru_cache(maxsize=8)
def _iterations_kernel(prepare, value, ufunc_compiled):
    """Several whole iterations in one compiled call: :func:`_kernels`' phases with numpy's ufunc
    loop called from compiled code (``ufunc_compiled``: :class:`fkopt.mechanisms.base.CompiledFitness`),
    and what :meth:`fkopt.algorithms.base.Algorithm.minimize` does after each iteration (the log's
    start and finish, the records)."""
    employed_move, employed_finish, onlooker_finish = _kernels(prepare, value)

    @njit(cache=True, error_model="numpy")
    def ufunc_calls(loop, data, arg, out, separate, n, ns, block):
        """The ufunc on the candidates' arguments as the numpy path's fitness calls see them:
        poses [0, n) then the ns scouts in a call of their own (``separate``), or [0, n + ns)."""
        if separate:
            ufunc_compiled(loop, data, arg, out, 0, n, block)
            ufunc_compiled(loop, data, arg, out, n, ns, block)
        else:
            ufunc_compiled(loop, data, arg, out, 0, n + ns, block)

    @njit(cache=True, error_model="numpy")
    def iterations(x, f, trial, best_x, best_f, u, width, limit, rule, C, lo, hi, J, params, absolute, separate,
                   evaluations, lbest, lcount, lactive, hr, he, hf, jj, fo_jj, fo_src, mv, fo_mv, fe, fo, scout, arg,
                   out, loop, data, history, ev_history, x_history, t0, block):
        """Iterations t0, t0 + 1, ... of every run, one per ``width`` uniforms of ``u`` (runs,
        k width), as :func:`abc_iteration`'s step followed by minimize's bookkeeping: the log's
        count set to the runs' evaluations (EvaluationLog.start), the iteration, an improvement of
        best_f that no reported value reached kept at the iteration's last evaluation
        (EvaluationLog.finish), and best_f, the evaluations and (x_history not empty) best_x
        recorded in column t of the histories. Stops early when the log's arrays hr, he, hf might
        not hold another iteration's improvements. Returns (iterations done, improvements kept)."""
        runs, pop, dim = x.shape
        n = runs * pop
        most = runs * (2 * pop + 1)
        keep_x = x_history.shape[1] > 0
        nh = 0
        count = u.shape[1] // width
        for it in range(count):
            if nh + most > hr.shape[0]:
                return it, nh
            ui = u[:, it * width:(it + 1) * width]
            for a in range(runs):
                lcount[a] = evaluations[a]
            ns = employed_move(x, trial, best_x, ui, limit, rule, C, lo, hi, separate, jj, mv, scout, arg, block)
            ufunc_calls(loop, data, arg, out, separate, n, ns, block)
            nh = employed_finish(x, f, trial, best_x, best_f, ui, rule, C, lo, hi, J, params, absolute, separate, ns,
                                 jj, mv, scout, out, fe, fo_src, fo_jj, fo_mv, arg, lbest, lcount, lactive, hr, he, hf,
                                 nh, block)
            ufunc_calls(loop, data, arg, out, False, n, 0, block)
            nh = onlooker_finish(x, f, trial, J, params, absolute, fo_src, fo_jj, fo_mv, out, fo, best_x, best_f,
                                 lbest, lcount, lactive, hr, he, hf, nh, block, scout, evaluations, evaluations)
            t = t0 + it
            for a in range(runs):
                if best_f[a] < lbest[a] and lactive[a]:       # EvaluationLog.finish
                    hr[nh] = a
                    he[nh] = evaluations[a]
                    hf[nh] = best_f[a]
                    nh += 1
                    lbest[a] = best_f[a]
                history[a, t] = best_f[a]
                ev_history[a, t] = evaluations[a]
                if keep_x:
                    for d in range(dim):
                        x_history[a, t, d] = best_x[a, d]
        return count, nh

    return iterations


def abc_iterations(fitness):
    """Several ABC or GABC iterations per call on ``fitness`` (a :class:`fkopt.mechanisms.base.CompiledFitness`
    whose ufunc loop numpy's object gave, ``fitness.ufunc_loop``), or None without that loop:
    ``advance(x, f, trial, best_x, best_f, u, width, limit, rule, C, bounds, J, absolute, log, separate,
    evaluations, history, ev_history, x_history, t0)`` runs iterations t0, t0 + 1, ... on ``width``
    uniforms each of ``u`` (:func:`abc_iteration`'s arguments; x, f, trial, best_x, best_f,
    evaluations and the log's arrays updated in place) and records them in the histories
    (:meth:`fkopt.algorithms.base.Algorithm.minimize`'s arrays; x_history None: not kept). Returns
    (iterations done, which may be fewer than u holds: call again on the rest; (rows, evaluation
    numbers, values) of the improvements the log keeps). Same draws, same operations, same bits
    as :func:`abc_iteration` followed by minimize's bookkeeping (tests/test_numerics.py)."""
    if fitness.ufunc_loop is None or fitness.ufunc_compiled is None:
        return None
    kernel = _iterations_kernel(fitness.prepare, fitness.value, fitness.ufunc_compiled)
    width_f, block, params = fitness.width, fitness.block, fitness.params
    loop, data = fitness.ufunc_loop

    def advance(x, f, trial, best_x, best_f, u, width, limit, rule, C, bounds, J, absolute, log, separate,
                evaluations, history, ev_history, x_history, t0):
        runs, pop = f.shape
        per, extra = LOG_ROOM
        room = per * runs * (2 * pop + 1) + extra
        jj, fo_jj, fo_src, mv, fo_mv, fe, fo, scout, arg, out, hr, he, hf, lo, hi = scratch_arrays(
            ("abc-iterations", runs, pop, width_f, room, bounds.tobytes()),
            lambda: _phase_arrays(runs, pop, width_f, bounds, room))
        best, count, active = log
        done, nh = kernel(x, f, trial, best_x, best_f, u, int(width), int(limit), int(rule), float(C), lo, hi,
                          np.ascontiguousarray(J, dtype=float), params, bool(absolute), bool(separate), evaluations,
                          best, count, active, hr, he, hf, jj, fo_jj, fo_src, mv, fo_mv, fe, fo, scout, arg, out,
                          loop, data, history, ev_history, _NO_X if x_history is None else x_history, int(t0), block)
        return done, kept(hr, he, hf, nh)
    return advance
