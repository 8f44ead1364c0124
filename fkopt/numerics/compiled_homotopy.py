"""Compiled path tracker of the 6-SPS parameter homotopy (:mod:`fkopt.kinematics.sps6_homotopy`).

The system, in the Study (soma) coordinates z = (e, g) of a rigid motion (e the rotation's
quaternion, g = t e / 2; Wampler 1996, "Forward displacement analysis of general six-in-parallel
SPS (Stewart) platform manipulators using soma coordinates", Mech. Mach. Theory 31(3)), is seven
homogeneous quadrics and one random linear chart:

    H_i(z; s) = d_i e.e - 2 (P(e) a_i).b_i + B_i(e, g) + 4 g.g     (the six legs, i = 0..5)
    H_6(z)    = e.g                                      (the Study quadric)
    H_7(z)    = h.z - 1                                  (the chart)

with (a_i, b_i, d_i) = P0_i + s DP_i (the legs' geometry interpolated linearly between two parameter
points; e^T A_i e + e^T K_i g are :func:`fkopt.kinematics.sps6_homotopy.forms`' quadrics, evaluated
here without the matrices: (P(e) a).b = -e.(b e a) in quaternion products, its gradient -2 b e a).
:func:`track` follows each start z0 (a root at s = 0) to s = 1 along s(tau) = gamma tau / (1 +
(gamma - 1) tau), tau in [0, 1] (for |gamma| = 1 an arc of a circle through 0 and 1: the "gamma
trick", Morgan & Sommese 1987, so a path avoids the finitely many singular points of the complex
s-line with probability one): a classical Runge-Kutta predictor on dz/dtau = -H_z^-1 H_s ds/dtau,
a Newton corrector at the new tau (at most three steps; the factors of its last step give the next
predictor's first stage), the step grown or shrunk by the size of the first correction (the
predictor's error, fifth order in the step), and at tau = 1 Newton until the correction is at
round-off. Complex 8x8 systems are factored by Gaussian elimination with partial pivoting (LAPACK's
call costs more than the solve at this size).

Importing this module imports numba.
"""
from __future__ import annotations

import math

import numpy as np
from numba import prange, set_parallel_chunksize

from fkopt.numerics.jit import njit                 # numba.njit with a cache that a corrupted file cannot break

#: path status written by :func:`track`
TRACKED, STEP_FAILED, DIVERGED, SINGULAR_END = 0, 1, 2, 3


@njit(cache=True)
def _lu8(M, piv):
    """M (complex 8x8) overwritten by its LU factors with partial pivoting (row swaps in piv);
    False when singular."""
    n = 8
    for c in range(n):
        p = c
        best = abs(M[c, c].real) + abs(M[c, c].imag)
        for r in range(c + 1, n):
            v = abs(M[r, c].real) + abs(M[r, c].imag)
            if v > best:
                best, p = v, r
        if best == 0.0 or not math.isfinite(best):
            return False
        piv[c] = p
        if p != c:
            for k in range(n):
                M[c, k], M[p, k] = M[p, k], M[c, k]
        inv = 1.0 / M[c, c]
        for r in range(c + 1, n):
            f = M[r, c] * inv
            M[r, c] = f
            if f != 0.0:
                for k in range(c + 1, n):
                    M[r, k] -= f * M[c, k]
    return True


@njit(cache=True)
def _lu_solve8(M, piv, rhs, x):
    """x = M^-1 rhs from :func:`_lu8`'s factors (rhs kept)."""
    n = 8
    for i in range(n):
        x[i] = rhs[i]
    for c in range(n):                     # the row swaps first (rows swapped whole, as LAPACK)
        p = piv[c]
        if p != c:
            x[c], x[p] = x[p], x[c]
    for c in range(n):
        for r in range(c + 1, n):
            x[r] -= M[r, c] * x[c]
    for c in range(n - 1, -1, -1):
        acc = x[c]
        for k in range(c + 1, n):
            acc -= M[c, k] * x[k]
        x[c] = acc / M[c, c]


@njit(cache=True)
def _system(z, s, P0, DP, h, H, J, Hs):
    """H(z; s) (8,), its Jacobian J (8, 8) in z and dH/ds Hs (8,); the legs' parameters at s are
    P0[i] + s DP[i], rows (a (3), b (3), d) of leg i (module docstring)."""
    e0, e1, e2, e3 = z[0], z[1], z[2], z[3]
    g0, g1, g2, g3 = z[4], z[5], z[6], z[7]
    E = e0 * e0 + e1 * e1 + e2 * e2 + e3 * e3
    G = g0 * g0 + g1 * g1 + g2 * g2 + g3 * g3
    # P(e) = (e.e) R(e), for dH/ds
    p00, p11, p22 = e0 * e0 + e1 * e1 - e2 * e2 - e3 * e3, e0 * e0 - e1 * e1 + e2 * e2 - e3 * e3, \
        e0 * e0 - e1 * e1 - e2 * e2 + e3 * e3
    p01, p10 = 2.0 * (e1 * e2 - e0 * e3), 2.0 * (e1 * e2 + e0 * e3)
    p02, p20 = 2.0 * (e1 * e3 + e0 * e2), 2.0 * (e1 * e3 - e0 * e2)
    p12, p21 = 2.0 * (e2 * e3 - e0 * e1), 2.0 * (e2 * e3 + e0 * e1)
    for i in range(6):
        ax, ay, az = P0[i, 0] + s * DP[i, 0], P0[i, 1] + s * DP[i, 1], P0[i, 2] + s * DP[i, 2]
        bx, by, bz = P0[i, 3] + s * DP[i, 3], P0[i, 4] + s * DP[i, 4], P0[i, 5] + s * DP[i, 5]
        d = P0[i, 6] + s * DP[i, 6]
        cx, cy, cz = ax - bx, ay - by, az - bz
        sx, sy, sz = ax + bx, ay + by, az + bz
        # w = b e a (quaternion products, a and b pure): (P(e) a).b = -e.w, its gradient -2 w
        q0 = -(e1 * ax + e2 * ay + e3 * az)
        qx = e0 * ax + e2 * az - e3 * ay
        qy = e0 * ay + e3 * ax - e1 * az
        qz = e0 * az + e1 * ay - e2 * ax
        w0 = -(bx * qx + by * qy + bz * qz)
        wx = q0 * bx + by * qz - bz * qy
        wy = q0 * by + bz * qx - bx * qz
        wz = q0 * bz + bx * qy - by * qx
        # B = 4 [e0 gv.c - g0 ev.c + ev.(s x gv)]
        gc = g1 * cx + g2 * cy + g3 * cz
        ec = e1 * cx + e2 * cy + e3 * cz
        sgx, sgy, sgz = sy * g3 - sz * g2, sz * g1 - sx * g3, sx * g2 - sy * g1       # s x gv
        esx, esy, esz = e2 * sz - e3 * sy, e3 * sx - e1 * sz, e1 * sy - e2 * sx       # ev x s
        B = 4.0 * (e0 * gc - g0 * ec + e1 * sgx + e2 * sgy + e3 * sgz)
        H[i] = d * E + 2.0 * (e0 * w0 + e1 * wx + e2 * wy + e3 * wz) + B + 4.0 * G
        J[i, 0] = 2.0 * d * e0 + 4.0 * w0 + 4.0 * gc
        J[i, 1] = 2.0 * d * e1 + 4.0 * wx + 4.0 * (sgx - g0 * cx)
        J[i, 2] = 2.0 * d * e2 + 4.0 * wy + 4.0 * (sgy - g0 * cy)
        J[i, 3] = 2.0 * d * e3 + 4.0 * wz + 4.0 * (sgz - g0 * cz)
        J[i, 4] = -4.0 * ec + 8.0 * g0
        J[i, 5] = 4.0 * (e0 * cx + esx) + 8.0 * g1
        J[i, 6] = 4.0 * (e0 * cy + esy) + 8.0 * g2
        J[i, 7] = 4.0 * (e0 * cz + esz) + 8.0 * g3
        # dH/ds: d' E - 2 ((P da).b + (P a).db) + B(c', s')
        dax, day, daz = DP[i, 0], DP[i, 1], DP[i, 2]
        dbx, dby, dbz = DP[i, 3], DP[i, 4], DP[i, 5]
        pax, pay, paz = p00 * ax + p01 * ay + p02 * az, p10 * ax + p11 * ay + p12 * az, p20 * ax + p21 * ay + p22 * az
        pdx = p00 * dax + p01 * day + p02 * daz
        pdy = p10 * dax + p11 * day + p12 * daz
        pdz = p20 * dax + p21 * day + p22 * daz
        cx, cy, cz = dax - dbx, day - dby, daz - dbz
        sx, sy, sz = dax + dbx, day + dby, daz + dbz
        Bs = 4.0 * (e0 * (g1 * cx + g2 * cy + g3 * cz) - g0 * (e1 * cx + e2 * cy + e3 * cz)
                    + e1 * (sy * g3 - sz * g2) + e2 * (sz * g1 - sx * g3) + e3 * (sx * g2 - sy * g1))
        Hs[i] = DP[i, 6] * E - 2.0 * (pdx * bx + pdy * by + pdz * bz + pax * dbx + pay * dby + paz * dbz) + Bs
    H[6] = e0 * g0 + e1 * g1 + e2 * g2 + e3 * g3
    H[7] = -1.0
    for a in range(4):
        J[6, a] = z[4 + a]
        J[6, 4 + a] = z[a]
    for a in range(8):
        J[7, a] = h[a]
        H[7] += h[a] * z[a]
    Hs[6] = 0.0
    Hs[7] = 0.0


@njit(cache=True)
def _norm(v):
    """Euclidean norm of a complex vector."""
    acc = 0.0
    for k in range(v.shape[0]):
        acc += v[k].real * v[k].real + v[k].imag * v[k].imag
    return math.sqrt(acc)


@njit(cache=True)
def _arc(tau, gamma):
    """(s, ds/dtau) on the gamma arc s = gamma tau / (1 + (gamma - 1) tau)."""
    den = 1.0 + (gamma - 1.0) * tau
    return gamma * tau / den, gamma / (den * den)


@njit(cache=True)
def _velocity(z, tau, gamma, P0, DP, h, H, J, Hs, piv, out):
    """dz/dtau at (z, tau) into out; False when H_z is singular."""
    s, ds = _arc(tau, gamma)
    _system(z, s, P0, DP, h, H, J, Hs)
    if not _lu8(J, piv):
        return False
    for k in range(8):
        Hs[k] = -Hs[k] * ds
    _lu_solve8(J, piv, Hs, out)
    return True


@njit(cache=True)
def _newton_step(z, tau, gamma, P0, DP, h, H, J, Hs, piv, dz, velocity):
    """One Newton step at tau: z += dz; with the same factors, dz/dtau at the point before the step
    into velocity (the next step's first predictor stage; the step is at round-off of the
    tracking tolerance). False when H_z is singular."""
    s, ds = _arc(tau, gamma)
    _system(z, s, P0, DP, h, H, J, Hs)
    if not _lu8(J, piv):
        return False
    for k in range(8):
        H[k] = -H[k]
        Hs[k] = -Hs[k] * ds
    _lu_solve8(J, piv, H, dz)
    _lu_solve8(J, piv, Hs, velocity)
    for k in range(8):
        z[k] += dz[k]
    return True


@njit(cache=True)
def _track_path(P0, DP, h, gamma, z, max_steps, predictor_error):
    """Follow the root z (overwritten) from tau = 0 to 1 (:func:`track`); (status, accepted steps,
    largest first correction)."""
    H = np.empty(8, dtype=np.complex128)
    Hs = np.empty(8, dtype=np.complex128)
    J = np.empty((8, 8), dtype=np.complex128)
    piv = np.empty(8, dtype=np.int64)
    y = np.empty(8, dtype=np.complex128)
    zc = np.empty(8, dtype=np.complex128)
    k1 = np.empty(8, dtype=np.complex128)
    k2 = np.empty(8, dtype=np.complex128)
    k3 = np.empty(8, dtype=np.complex128)
    k4 = np.empty(8, dtype=np.complex128)
    v = np.empty(8, dtype=np.complex128)
    dz = np.empty(8, dtype=np.complex128)
    tau = 0.0
    dt = 0.1
    taken = 0
    worst = 0.0
    tries = 0
    have_k1 = False
    while tau < 1.0:
        tries += 1
        if tries > max_steps or dt < 1e-12:
            return STEP_FAILED, taken, worst
        if dt > 1.0 - tau:
            dt = 1.0 - tau
        # classical Runge-Kutta predictor; k1 from the last corrector step's factors
        ok = True
        if not have_k1:
            ok = _velocity(z, tau, gamma, P0, DP, h, H, J, Hs, piv, k1)
            have_k1 = ok
        if ok:
            for k in range(8):
                y[k] = z[k] + 0.5 * dt * k1[k]
            ok = _velocity(y, tau + 0.5 * dt, gamma, P0, DP, h, H, J, Hs, piv, k2)
        if ok:
            for k in range(8):
                y[k] = z[k] + 0.5 * dt * k2[k]
            ok = _velocity(y, tau + 0.5 * dt, gamma, P0, DP, h, H, J, Hs, piv, k3)
        if ok:
            for k in range(8):
                y[k] = z[k] + dt * k3[k]
            ok = _velocity(y, tau + dt, gamma, P0, DP, h, H, J, Hs, piv, k4)
        if not ok:
            dt *= 0.5
            continue
        for k in range(8):
            zc[k] = z[k] + dt / 6.0 * (k1[k] + 2.0 * k2[k] + 2.0 * k3[k] + k4[k])
        # Newton corrector at the new tau
        t1 = tau + dt
        scale = 1.0 + _norm(zc)
        first = -1.0
        previous = 0.0
        good = False
        for it in range(3):
            if not _newton_step(zc, t1, gamma, P0, DP, h, H, J, Hs, piv, dz, v):
                break
            size = _norm(dz) / scale
            if it == 0:
                first = size
                if size > 100.0 * predictor_error:
                    break
            elif size > 0.25 * previous and size > 1e-13:
                break
            previous = size
            if size <= (1e-6 if it > 0 else 1e-8):      # quadratic convergence: the error left is ~size^2
                good = True
                break
        if not good:
            dt *= 0.5
            continue
        for k in range(8):
            z[k] = zc[k]
            k1[k] = v[k]
        have_k1 = True
        tau = t1
        taken += 1
        if first > worst:
            worst = first
        if scale > 1e8:
            return DIVERGED, taken, worst
        grow = 2.0 if first <= 0.0 else 0.9 * (predictor_error / first) ** 0.2     # RK4: error ~ dt^5
        dt *= min(2.0, max(0.5, grow))
    # at s = 1: Newton until the correction is at round-off (1e-13), or stays at most 1e-9 after
    # eight steps (an ill-conditioned root's round-off floor; a multiple root's paths end together,
    # which the caller's distinctness test sees)
    size = 1.0
    for it in range(8):
        if not _newton_step(z, 1.0, gamma, P0, DP, h, H, J, Hs, piv, dz, v):
            return SINGULAR_END, taken, worst
        size = _norm(dz) / (1.0 + _norm(z))
        if size <= 1e-13:
            return TRACKED, taken, worst
    return (TRACKED if size <= 1e-9 else SINGULAR_END), taken, worst


@njit(cache=True, parallel=True)
def track(P0, DP, h, gamma, Z0, Z, status, steps, first_error, max_steps, predictor_error):
    """Follow every start Z0[k] (a root at s = 0) to s = 1 (module docstring), the paths spread
    over numba's threads (``NUMBA_NUM_THREADS``; each path is independent, so the endpoints do not
    depend on the thread count); endpoints into Z, :data:`TRACKED`/:data:`STEP_FAILED`/
    :data:`DIVERGED`/:data:`SINGULAR_END` into status, accepted steps into steps.
    ``predictor_error``: the first correction (relative to 1 + |z|) the step size aims at; a step
    whose first correction exceeds 100x that, whose corrector needs more than three steps, or
    whose second correction is not a quarter of the first, is refused and halved.
    ``first_error[k]``: the largest first correction of an accepted step of path k."""
    for p in prange(Z0.shape[0]):
        z = np.empty(8, dtype=np.complex128)
        for k in range(8):
            z[k] = Z0[p, k]
        state, taken, worst = _track_path(P0, DP, h, gamma, z, max_steps, predictor_error)
        for k in range(8):
            Z[p, k] = z[k]
        status[p] = state
        steps[p] = taken
        first_error[p] = worst


def track_paths(*args):
    """:func:`track`, its paths handed one at a time to whichever thread is free (numba's chunk
    size 1 for this call: a path's cost varies ~5x, so equal blocks of paths leave a thread idle)."""
    previous = set_parallel_chunksize(1)
    try:
        track(*args)
    finally:
        set_parallel_chunksize(previous)
