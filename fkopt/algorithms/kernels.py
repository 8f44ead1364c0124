"""What every compiled swarm iteration shares (:mod:`fkopt.algorithms.pso_kernels`,
:mod:`fkopt.algorithms.abc_kernels`): :class:`fkopt.algorithms.base.EvaluationLog`'s bookkeeping and
:meth:`fkopt.algorithms.base.Algorithm.update_best` compiled, and the per-thread scratch arrays.

Importing this module imports numba (:mod:`fkopt.numerics.jit`): the algorithms import it only
once the compiled path runs (:func:`fkopt.algorithms.base.compiled_step`).
"""
from __future__ import annotations

import threading

import numpy as np

from fkopt.numerics.jit import njit                 # numba.njit with a cache that a corrupted file cannot break

_scratch = threading.local()


def scratch_arrays(key, make):
    """This thread's scratch arrays for ``key`` (the kind and shape of an iteration), made by
    ``make()`` on first use: a swarm iteration's buffers are the same every iteration, and a
    dozen allocations cost about as much as a kernel's call. Nothing returned to a caller
    lives in them (see :func:`kept`)."""
    cache = getattr(_scratch, "arrays", None)
    if cache is None:
        cache = _scratch.arrays = {}
    got = cache.get(key)
    if got is None:
        if len(cache) >= 16:           # a few shapes at a time (memory stays bounded)
            cache.clear()
        got = cache[key] = make()
    return got


_NONE_KEPT = (np.empty(0, dtype=np.intp), np.empty(0, dtype=np.int64), np.empty(0))


def kept(hr, he, hf, nh):
    """The log's improvements (rows, evaluation numbers, values) out of the scratch arrays, as new
    arrays (most iterations keep none: then shared empty arrays, which the log never stores)."""
    if nh == 0:
        return _NONE_KEPT
    return hr[:nh].copy(), he[:nh].copy(), hf[:nh].copy()


@njit(cache=True, error_model="numpy")
def log_points(a, vals, lbest, lcount, lactive, hr, he, hf, nh):
    """:meth:`fkopt.algorithms.base.EvaluationLog.add` of the values ``vals`` (k,) that run ``a``
    just evaluated, in order: an improvement of the running best is kept as (row, evaluation
    number, value) in hr, he, hf from position nh while the run is active; the log's best and
    count advance either way. Returns the new nh."""
    run_best = lbest[a]
    for c in range(vals.shape[0]):
        g = vals[c]
        if g < run_best:
            if lactive[a]:
                hr[nh] = a
                he[nh] = lcount[a] + c + 1
                hf[nh] = g
                nh += 1
            run_best = g
    lbest[a] = run_best
    lcount[a] += vals.shape[0]
    return nh


@njit(cache=True, error_model="numpy")
def fold_best(a, x, f, best_x, best_f):
    """:meth:`fkopt.algorithms.base.Algorithm.update_best` of run ``a``: its first minimum of f
    (a NaN first, as ``argmin``), if below best_f[a], into best_x[a], best_f[a]."""
    pop, dim = x.shape[1], x.shape[2]
    b = 0
    for i in range(pop):
        if f[a, i] != f[a, i]:
            b = i
            break
        if f[a, i] < f[a, b]:
            b = i
    if f[a, b] < best_f[a]:
        best_f[a] = f[a, b]
        for d in range(dim):
            best_x[a, d] = x[a, b, d]
