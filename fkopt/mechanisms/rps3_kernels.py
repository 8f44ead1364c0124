"""The 3-RPS fitness of :class:`fkopt.mechanisms.rps3.ThreeRPS` compiled by numba, around numpy's own
``np.tan``: the numpy path's bits on any build.

Importing this module imports numba (:mod:`fkopt.numerics.jit`); :meth:`ThreeRPS.compiled_fitness`
and :meth:`ThreeRPS.compiled_swarm_fitness` import it only once the compiled path runs
(:func:`fkopt.numerics.path.compiled`). Kernels compile with ``error_model="numpy"``: a float
division by zero gives numpy's inf/NaN instead of a Python exception, so no check guards each
division (half of the fitness' time, measured: 57 -> 29 ns per point); the values are the same
wherever the divisor is not zero.

Why numpy's tangents. A swarm turns an ulp into another run, and numpy's tan (SIMD code on some
machines) may be an ulp from the C library's on ~0.7 % of inputs. So compiled code stops where the
numpy path calls np.tan: :func:`prepare` writes the half-angle arguments of the poses into a buffer
laid out as the numpy path's own call sees them (:meth:`ThreeRPS.ik_columns`: per block of at most
``block`` poses of one fitness call, the block's alphas, then its betas, contiguous), :func:`numpy_tan`
runs np.tan on each such block, and :func:`value` computes the rest of the fitness from the tangents
(:func:`fitness_from_tangents`). The same ufunc on the same values at the same positions of arrays of
the same lengths: the numpy path's bits, whether its SIMD loop has a scalar tail or not.

* :func:`fitness` -- the fitness of a batch of poses (``FKOPT_NUMERICS=compiled``'s single calls);
* :func:`prepare`, :func:`numpy_tan`, :func:`value` -- the three stages the compiled swarm
  iterations of :mod:`fkopt.algorithms.pso_kernels` and :mod:`fkopt.algorithms.abc_kernels` take
  (wired as function objects: :class:`fkopt.mechanisms.base.CompiledFitness`); :func:`numpy_tan_loop`
  -- :func:`numpy_tan` from compiled code, numpy's own loop called by address
  (:mod:`fkopt.numerics.ufunc_loop`), so several iterations run in one compiled call;
* :func:`point_fitness` -- one pose with the C library's ``tan`` (pygmo's one-point fitness in
  ``fkopt bench``).
"""
from __future__ import annotations

import math

import numpy as np

from fkopt.numerics.jit import njit                 # numba.njit with a cache that a corrupted file cannot break
from fkopt.numerics.ufunc_loop import call_unary_loop, unary_loop

#: Degrees -> half-angle in radians (the factor :meth:`fkopt.mechanisms.rps3.ThreeRPS._legs` uses).
HALF_DEG = math.pi / 360.0


@njit(cache=True, error_model="numpy")
def fitness_from_tangents(ta, tb, z, j0, j1, j2, ra, rb, absolute):
    """Fitness of one 3-RPS pose from its half-angle tangents ta = tan(alpha/2), tb = tan(beta/2)
    (alpha, beta in rad) and z, against legs (j0, j1, j2): the operations of
    :meth:`fkopt.mechanisms.rps3.ThreeRPS._legs` after its ``np.tan`` in their order (mao2017
    eqs. 6 and 10), then :meth:`fkopt.problems.FKProblem.fitness` (sum of squared or absolute
    residuals, mao2017 eq. 12)."""
    s3 = 0.5 * math.sqrt(3.0)
    pm_rb, pm_2 = s3 * rb, -2.0 * s3
    ta2, tb2 = ta * ta, tb * tb
    ra_, rb_ = 1.0 / (1.0 + ta2), 1.0 / (1.0 + tb2)
    sa, sb = (ta + ta) * ra_, (tb + tb) * rb_
    ca, cb = (1.0 - ta2) * ra_, (1.0 - tb2) * rb_
    sbsa = sb * sa
    tg = sbsa / (ca + cb)
    cg = 1.0 / math.sqrt(1.0 + tg * tg)
    sg = tg * cg
    R00, R10 = cg * cb, sg * cb
    R11 = sg * sbsa + cg * ca
    R01 = cg * sbsa - sg * ca
    h = (0.5 * rb) * R11
    e = (1.5 * rb) * R00 - h - ra
    f = z - rb * sb
    d1 = math.sqrt(e * e + f * f)
    ax = 0.5 * ra - h
    bx = pm_rb * R01
    ay = (-1.5 * rb) * R10
    by = pm_2 * ax
    az = z + (0.5 * rb) * sb
    bz = pm_rb * (cb * sa)
    u, v, w = ax + bx, ay + by, az + bz
    d2 = math.sqrt((u * u + v * v) + w * w)
    u, v, w = ax + (-bx), ay + (-by), az + (-bz)
    d3 = math.sqrt((u * u + v * v) + w * w)
    r1, r2, r3 = d1 - j0, d2 - j1, d3 - j2
    if absolute:
        return (abs(r1) + abs(r2)) + abs(r3)
    return (r1 * r1 + r2 * r2) + r3 * r3


@njit(cache=True, error_model="numpy")
def point_fitness(p0, p1, z, j0, j1, j2, ra, rb, absolute):
    """Fitness of one 3-RPS pose (alpha, beta in deg, z) against legs (j0, j1, j2) with the C
    library's ``tan`` (:func:`fitness_from_tangents`): numpy's (SIMD) may differ from it by an ulp,
    so this serves only callers that want one point per call (the pygmo bench row); :func:`fitness`
    and the swarm iterations take numpy's tangents (:func:`numpy_tan`)."""
    return fitness_from_tangents(math.tan(p0 * HALF_DEG), math.tan(p1 * HALF_DEG), z, j0, j1, j2, ra, rb, absolute)


@njit(cache=True)
def slot(c, s0, sl, block):
    """(position of alpha's argument, offset of beta's from it) in the tangent buffer of pose c
    of a fitness call over poses [s0, s0 + sl), cut into blocks of ``block`` poses."""
    k = c - s0
    if sl <= block:                    # one block (the usual case): no integer division
        return 2 * s0 + k, sl
    first = (k // block) * block
    return 2 * (s0 + first) + (k - first), min(block, sl - first)


def numpy_tan(arg, out, segments, block):
    """``np.tan`` of the argument buffer ``arg`` into ``out`` as the numpy path calls it: for each
    fitness call (start pose, poses) in ``segments``, one call per block of at most ``block``
    poses on that block's contiguous [alphas, betas]."""
    tan = np.tan
    for s0, sl in segments:
        if sl <= block:                # one block (the usual case)
            tan(arg[2 * s0:2 * (s0 + sl)], out[2 * s0:2 * (s0 + sl)])
            continue
        for b0 in range(0, sl, block):
            s, e = 2 * (s0 + b0), 2 * (s0 + min(b0 + block, sl))
            tan(arg[s:e], out[s:e])


@njit(cache=True)
def numpy_tan_loop(loop, data, arg, out, s0, sl, block):
    """:func:`numpy_tan` of one fitness call (poses [s0, s0 + sl)) from compiled code: numpy's own
    ``np.tan`` loop (``loop``, ``data``: :func:`fkopt.numerics.ufunc_loop.unary_loop`) on the same
    blocks, the same values at the same positions of runs of the same lengths -- np.tan's bits."""
    if sl <= block:                    # one block (the usual case)
        call_unary_loop(loop, data, arg, out, 2 * s0, 2 * sl)
        return
    for b0 in range(0, sl, block):
        s, e = 2 * (s0 + b0), 2 * (s0 + min(b0 + block, sl))
        call_unary_loop(loop, data, arg, out, s, e - s)


def numpy_tan_address():
    """(loop, data) of numpy's float64 ``np.tan`` loop for :func:`numpy_tan_loop`, or None where it
    cannot be read or differs from ``np.tan`` on the probe (:func:`fkopt.numerics.ufunc_loop.unary_loop`)."""
    return unary_loop(np.tan)


@njit(cache=True, error_model="numpy")
def prepare(x0, x1, x2, arg, c, s0, sl, block):
    """The half-angle arguments of pose (x0, x1, x2), pose c of a fitness call over poses
    [s0, s0 + sl), into ``arg`` (:func:`slot`)."""
    p, off = slot(c, s0, sl, block)
    arg[p] = x0 * HALF_DEG
    arg[p + off] = x1 * HALF_DEG


@njit(cache=True, error_model="numpy")
def value(tan, c, s0, sl, block, x0, x1, x2, j0, j1, j2, params, absolute):
    """The fitness of pose (x0, x1, x2), pose c of a fitness call over poses [s0, s0 + sl), from
    numpy's tangents ``tan`` of :func:`prepare`'s arguments, against legs (j0, j1, j2);
    ``params``: the geometry (r_a, r_b)."""
    p, off = slot(c, s0, sl, block)
    return fitness_from_tangents(tan[p], tan[p + off], x2, j0, j1, j2, params[0], params[1], absolute)


@njit(cache=True, error_model="numpy")
def _arguments(P, arg, block):
    """The half-angle arguments of poses P (n, 3) into ``arg`` as one fitness call."""
    n = P.shape[0]
    for i in range(n):
        prepare(P[i, 0], P[i, 1], P[i, 2], arg, i, 0, n, block)


@njit(cache=True, error_model="numpy")
def _from_tangents(P, tan, J, params, absolute, out, block):
    """:func:`value` of poses P (n, 3) with numpy's tangents ``tan`` (:func:`_arguments`' layout)
    against leg rows J (3, 1) or (3, n) into out (n,)."""
    n = P.shape[0]
    one = J.shape[1] == 1
    for i in range(n):
        c = 0 if one else i
        out[i] = value(tan, i, 0, n, block, P[i, 0], P[i, 1], P[i, 2], J[0, c], J[1, c], J[2, c], params, absolute)


def fitness(P, J, ra, rb, absolute, block):
    """The 3-RPS fitness of poses (n, 3) against leg rows J (3, 1) or (3, n): fitness (n,), the
    numpy path's bits (numpy's tangents in its layout, :func:`numpy_tan`; ``block``: the poses
    per block of the numpy fitness)."""
    P = np.ascontiguousarray(P, dtype=float)
    n = P.shape[0]
    out, arg, tan = np.empty(n), np.empty(2 * n), np.empty(2 * n)
    _arguments(P, arg, block)
    numpy_tan(arg, tan, ((0, n),), block)
    _from_tangents(P, tan, np.ascontiguousarray(J, dtype=float), (float(ra), float(rb)), bool(absolute), out, block)
    return out
