"""One iteration of :meth:`fkopt.algorithms.pso.PSO.iterate` compiled by numba, every run and particle
in one pass, on a mechanism's compiled fitness (:class:`fkopt.mechanisms.base.CompiledFitness`, wired
as function objects: this module knows no mechanism): the same draws, the same operations in numpy's
order, the mechanism's numpy ufunc between the kernels, the evaluation log's bookkeeping and the
best-so-far inside -- the numpy path's bits (tests/test_numerics.py).

Importing this module imports numba: :meth:`fkopt.algorithms.pso.PSO.iterate` imports it only once
the compiled path runs (:func:`fkopt.algorithms.base.compiled_step`).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from fkopt.algorithms.kernels import fold_best, kept, log_points, scratch_arrays
from fkopt.numerics.jit import njit


@lru_cache(maxsize=8)
def _kernels(prepare, value):
    """The move and finish kernels on the fitness stages ``prepare`` and ``value`` (compiled once
    per process and fitness; numba's cache keys them by those kernels' code,
    :func:`fkopt.numerics.jit.njit`)."""

    @njit(cache=True, error_model="numpy")
    def move(x, pos, vel, g, r, w, c1, c2, limit, bounds, npos, nvel, arg, block):
        """Velocity w v + (c1 r1)(p - x) + (c2 r2)(g - x) (numpy's operations in their order),
        clamp, move, clip onto the box (velocity zeroed where clipped) into npos, nvel; the
        fitness arguments of the new positions into ``arg`` (one fitness call)."""
        runs, pop, dim = pos.shape
        n = runs * pop
        for a in range(runs):
            for i in range(pop):
                for d in range(dim):
                    v = vel[a, i, d] * w + (r[a, 0, i, d] * c1) * (x[a, i, d] - pos[a, i, d])
                    v = v + (r[a, 1, i, d] * c2) * (g[a, d] - pos[a, i, d])
                    v = min(max(v, -limit[d]), limit[d])
                    mv = pos[a, i, d] + v
                    cp = min(max(mv, bounds[d, 0]), bounds[d, 1])
                    nvel[a, i, d] = 0.0 if cp != mv else v
                    npos[a, i, d] = cp
                prepare(npos[a, i, 0], npos[a, i, 1], npos[a, i, 2], arg, a * pop + i, 0, n, block)

    @njit(cache=True, error_model="numpy")
    def finish(x, fb, npos, out, J, params, absolute, nx, nf, fout, best_x, best_f, lbest, lcount, lactive, hr,
               he, hf, block):
        """After the ufunc: the fitness of the positions into fout, the personal bests into nx, nf,
        the fitness reported to the evaluation log held as arrays (:func:`log_points`), and the
        personal bests folded into the best-so-far best_x, best_f (:func:`fold_best`). Returns the
        number of improvements the log keeps."""
        runs, pop, dim = npos.shape
        n = runs * pop
        one = J.shape[1] == 1
        nh = 0
        for a in range(runs):
            for i in range(pop):
                c = 0 if one else a * pop + i
                f = value(out, a * pop + i, 0, n, block, npos[a, i, 0], npos[a, i, 1], npos[a, i, 2], J[0, c],
                          J[1, c], J[2, c], params, absolute)
                fout[a, i] = f
                if f < fb[a, i]:
                    nf[a, i] = f
                    for d in range(dim):
                        nx[a, i, d] = npos[a, i, d]
                else:
                    nf[a, i] = fb[a, i]
                    for d in range(dim):
                        nx[a, i, d] = x[a, i, d]
            nh = log_points(a, fout[a], lbest, lcount, lactive, hr, he, hf, nh)
            fold_best(a, nx, nf, best_x, best_f)
        return nh

    return move, finish


def pso_iteration(fitness):
    """One PSO iteration on ``fitness`` (a :class:`fkopt.mechanisms.base.CompiledFitness`):
    ``step(x, fb, pos, vel, g, g_f, r, w, c1, c2, limit, bounds, J, absolute, log)`` -> (personal
    bests x, their fitness, positions, velocities, best-so-far point and fitness (``g`` with the
    new personal bests folded in: :meth:`fkopt.algorithms.base.Algorithm.update_best`)), all new
    arrays, and (rows, evaluation numbers, values) of the improvements kept by ``log`` (best,
    count, active arrays, updated in place). ``g``, ``g_f``: the best-so-far point and fitness (the
    global best); ``limit``, ``bounds``: C-contiguous float arrays (dim,), (dim, 2); ``J``: the
    target rows (3, 1) or (3, rows * population)."""
    move, finish = _kernels(fitness.prepare, fitness.value)
    ufunc, width, block, params = fitness.ufunc, fitness.width, fitness.block, fitness.params

    def step(x, fb, pos, vel, g, g_f, r, w, c1, c2, limit, bounds, J, absolute, log):
        nx, nf, npos, nvel = np.empty_like(x), np.empty_like(fb), np.empty_like(pos), np.empty_like(vel)
        n = fb.size
        fout, arg, out, hr, he, hf = scratch_arrays(
            ("pso", fb.shape, width), lambda: (np.empty(fb.shape), np.empty(width * n), np.empty(width * n),
                                               np.empty(n, dtype=np.intp), np.empty(n, dtype=np.int64), np.empty(n)))
        best, count, active = log
        best_x, best_f = np.array(g, dtype=float, order="C"), np.array(g_f, dtype=float)
        move(x, pos, vel, best_x, r, float(w), float(c1), float(c2), limit, bounds, npos, nvel, arg, block)
        ufunc(arg, out, ((0, n),), block)
        nh = finish(x, fb, npos, out, J, params, bool(absolute), nx, nf, fout, best_x, best_f, best, count, active,
                    hr, he, hf, block)
        return nx, nf, npos, nvel, best_x, best_f, kept(hr, he, hf, nh)
    return step
