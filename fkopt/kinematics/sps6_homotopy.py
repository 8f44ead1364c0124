"""Every forward solution of a general 6-SPS (6-6 Stewart-Gough) platform by a parameter homotopy:
the certificate path of :func:`fkopt.kinematics.assembly_modes.all_solutions` (compiled path).

Formulation (Wampler 1996, "Forward displacement analysis of general six-in-parallel SPS
(Stewart) platform manipulators using soma coordinates", Mech. Mach. Theory 31(3)): a rigid
motion x -> R x + t as Study coordinates z = (e, g) in C^8, e the rotation's quaternion and
g = t e / 2 (quaternion product, t pure), so that e.g = 0 (the Study quadric) and t = 2 vec(g e*) / e.e.
Multiplying leg i's equation |R a_i + t - b_i|^2 = L_i^2 by e.e and using e.g = 0 gives a
homogeneous quadric,

    d_i e.e - 2 (P(e) a_i).b_i + 4 [e0 g_v.(a_i - b_i) - g0 e_v.(a_i - b_i) + e_v.((a_i + b_i) x g_v)] + 4 g.g = 0,

d_i = |a_i|^2 + |b_i|^2 - L_i^2 and P(e) = (e.e) R(e) (quadratic in e): :func:`forms` writes it
as e^T A_i e + e^T K_i g + 4 g.g. Six such quadrics, the Study quadric and a random linear chart
h.z = 1 are eight equations in z. For general (complex) geometry and legs they have 40
nonsingular roots (Raghavan 1993; Ronga & Vust 1995; the 40 of Dietmaier 1998 all real).

Solving: one start system -- random complex geometry p0 with all 40 roots -- is found once per
process by monodromy (:func:`start_system`: one root by construction, then loops p0 -> p1 -> p2
-> p0 through random parameters until 40 distinct roots are known; at most 40 exist), and every
target platform p1 is reached by tracking those 40 roots along p(s) = p0 + s (p1 - p0)
(:func:`fkopt.numerics.compiled_homotopy.track`: the parameter homotopy of Morgan & Sommese 1989,
"Coefficient-parameter polynomial continuation", with a seeded gamma arc in s and a seeded chart).
Base and platform points are centred and scaled first (the roots map back exactly).

Certificate: when all 40 paths reach s = 1 at 40 distinct nonsingular roots, they are every
isolated root of the target (by the parameter homotopy theorem each isolated root, counted with
multiplicity, is the end of one of the generic number's paths, here 40), so every real
assembly mode is among them: the real ones are kept. Otherwise (a path failed, two ended at one
root, a special geometry such as collinear or coincident joints) :func:`solve` returns the reason
and ``all_solutions`` runs its restart search instead.
"""
from __future__ import annotations

import numpy as np

from fkopt.numerics import path as numerics_path, rotations

#: The generic number of complex forward solutions of the 6-6 platform.
GENERIC_ROOTS = 40
#: Seed of the one start system (its geometry and roots; any seed serves).
_START_SEED = 66
#: Endpoints closer than this (relative to 1 + |z|, in the chart's coordinates) are one root.
_DISTINCT = 1e-7
#: An endpoint is real when its imaginary part, after the phase that makes its largest
#: coordinate real, is at most this fraction of its size (a real root of a generic platform
#: ends at round-off; the real Newton polish and the residual test of all_solutions decide).
_REAL = 1e-6
#: The tracker's step aims at a first Newton correction of this size (relative).
_PREDICTOR_ERROR = 3e-3
#: Most step attempts per path.
_MAX_STEPS = 400


def _coefficients() -> np.ndarray:
    """C (3, 3, 4, 4): the symmetric 4x4 matrices of the entries P_jk(e) = e^T C_jk e of
    P(e) = (e.e) R(e), e = (e0, e1, e2, e3) with e0 the scalar part."""
    C = np.zeros((3, 3, 4, 4))
    C[0, 0], C[1, 1], C[2, 2] = np.diag([1, 1, -1, -1.]), np.diag([1, -1, 1, -1.]), np.diag([1, -1, -1, 1.])
    for (j, k), pairs in {(0, 1): ((1, 2, 1), (0, 3, -1)), (0, 2): ((1, 3, 1), (0, 2, 1)),
                          (1, 0): ((1, 2, 1), (0, 3, 1)), (1, 2): ((2, 3, 1), (0, 1, -1)),
                          (2, 0): ((1, 3, 1), (0, 2, -1)), (2, 1): ((2, 3, 1), (0, 1, 1))}.items():
        for a, b, v in pairs:
            C[j, k, a, b] += v
            C[j, k, b, a] += v
    return C


_C = _coefficients()


def forms(a: np.ndarray, b: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(A (6, 4, 4), K (6, 4, 4)) of the legs' quadrics e^T A_i e + e^T K_i g + 4 g.g (module
    docstring) for platform points a (6, 3), base points b (6, 3) and d_i = |a_i|^2 + |b_i|^2 - L_i^2."""
    dtype = np.result_type(a, b, d, float)
    A = -2.0 * np.einsum("ij,ik,jkab->iab", b, a, _C) + d[:, None, None] * np.eye(4)
    K = np.zeros((6, 4, 4), dtype=dtype)
    c, s = 4.0 * (a - b), 4.0 * (a + b)
    K[:, 0, 1:], K[:, 1:, 0] = c, -c
    K[:, 1, 2], K[:, 1, 3], K[:, 2, 3] = -s[:, 2], s[:, 1], -s[:, 0]        # 4 [a + b]_x
    K[:, 2, 1], K[:, 3, 1], K[:, 3, 2] = s[:, 2], -s[:, 1], s[:, 0]
    return A.astype(dtype), K


def _segment(p0, p1):
    """(P0, DP) (6, 7) complex: rows (a_i, b_i, d_i) of p0 and of p1 - p0 (the tracker's parameters)."""
    rows = [np.concatenate([np.asarray(a, dtype=complex), np.asarray(b, dtype=complex),
                            np.asarray(d, dtype=complex)[:, None]], axis=1) for a, b, d in (p0, p1)]
    return np.ascontiguousarray(rows[0]), np.ascontiguousarray(rows[1] - rows[0])


def _residual(Z, p, h):
    """max |H(z; p)| of roots Z (n, 8) (all eight equations)."""
    A, K = forms(*p)
    e, g = Z[:, :4], Z[:, 4:]
    legs = (np.einsum("na,iab,nb->ni", e, A, e) + np.einsum("na,iab,nb->ni", e, K, g)
            + 4.0 * np.einsum("na,na->n", g, g)[:, None])
    rest = np.stack([np.einsum("na,na->n", e, g), Z @ h - 1.0], axis=1)
    return np.abs(np.concatenate([legs, rest], axis=1)).max(-1)


def _track(kernel, p0, p1, h, gamma, Z0):
    """Endpoints (n, 8), status (n,) and accepted steps (n,) of the roots Z0 of p0 tracked to p1
    along the gamma arc (:func:`fkopt.numerics.compiled_homotopy.track`)."""
    n = len(Z0)
    Z = np.empty((n, 8), dtype=complex)
    status, steps, first = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64), np.empty(n)
    kernel.track_paths(*_segment(p0, p1), np.ascontiguousarray(h, dtype=complex), complex(gamma),
                       np.ascontiguousarray(Z0, dtype=complex), Z, status, steps, first, _MAX_STEPS, _PREDICTOR_ERROR)
    return Z, status, steps


def _distinct(Z: np.ndarray, known: np.ndarray) -> np.ndarray:
    """known (k, 8) extended by the rows of Z farther than _DISTINCT from every known root and each other."""
    for z in Z:
        if not len(known) or (np.abs(known - z).max(-1) > _DISTINCT * (1.0 + np.abs(z).max())).all():
            known = np.concatenate([known, z[None]])
    return known


def _random_parameters(rng):
    """Random complex geometry (a (6, 3), b (6, 3), d (6,)), standard normal parts."""
    def c(*shape):
        return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)
    return c(6, 3), c(6, 3), c(6)


_START: dict = {}


def start_system(kernel) -> tuple[tuple, np.ndarray, np.ndarray]:
    """(p0, Z0 (40, 8), h0): random complex geometry p0 = (a, b, d), all its 40 roots, the chart
    h0 they satisfy; by monodromy (module docstring), once per process, from :data:`_START_SEED`."""
    if "p0" in _START:
        return _START["p0"], _START["Z0"], _START["h0"]
    rng = np.random.default_rng(_START_SEED)
    a, b, _ = _random_parameters(rng)
    e = rng.standard_normal(4) + 1j * rng.standard_normal(4)
    g = rng.standard_normal(4) + 1j * rng.standard_normal(4)
    g = g - (e @ g) / (e @ e) * e                                   # on the Study quadric
    h0 = rng.standard_normal(8) + 1j * rng.standard_normal(8)
    z = np.concatenate([e, g])
    z = z / (h0 @ z)
    e, g = z[:4], z[4:]
    A, K = forms(a, b, np.zeros(6, dtype=complex))
    rest = np.einsum("a,iab,b->i", e, A, e) + np.einsum("a,iab,b->i", e, K, g) + 4.0 * (g @ g)
    p0 = (a, b, -rest / (e @ e))                                    # d chosen so that z is a root
    known = z[None]
    for _ in range(200):
        if len(known) >= GENERIC_ROOTS:
            break
        p1, p2 = _random_parameters(rng), _random_parameters(rng)
        Z = known
        for q0, q1 in ((p0, p1), (p1, p2), (p2, p0)):
            Z, status, _ = _track(kernel, q0, q1, h0, 1.0, Z)
            Z = Z[status == 0]
        Z = Z[_residual(Z, p0, h0) <= 1e-10 * (1.0 + np.abs(Z).max(-1))] if len(Z) else Z
        known = _distinct(Z, known)
    if len(known) != GENERIC_ROOTS:
        raise RuntimeError(f"the 6-SPS start system has {len(known)} roots after monodromy, not {GENERIC_ROOTS}")
    _START.update(p0=p0, Z0=known, h0=h0)
    return p0, _START["Z0"], h0


def prepare() -> None:
    """Load the compiled tracker and find the start system now (both once per process)."""
    from fkopt.numerics import compiled_homotopy as kernel    # lazy: numba
    start_system(kernel)


def available() -> bool:
    """True when the tracker runs here (the compiled path; ``FKOPT_NUMERICS=numpy`` is the restart search)."""
    return numerics_path.compiled() is not None


def solve(base: np.ndarray, platform: np.ndarray, legs: np.ndarray, seed: int = 0) -> dict:
    """Every real root of the 6-SPS leg equations |R q_i + t - b_i| = L_i (base points b (6, 3),
    platform points q (6, 3) about the pose's point, legs L (6,)) by the parameter homotopy.

    Returns ``{"states": (n, 12) rows (t, R row-major) of the real roots, "certified": bool,
    "reason": why not (or ""), "roots": distinct finite roots reached, "paths": 40, "steps":
    accepted steps over all paths}``. ``seed`` draws the chart and the gamma arc."""
    from fkopt.numerics import compiled_homotopy as kernel    # lazy: numba
    try:
        p0, Z0, h0 = start_system(kernel)
    except RuntimeError as err:                                # no start system: the caller's restarts run
        return {"paths": 0, "roots": 0, "steps": 0, "certified": False, "reason": str(err),
                "states": np.empty((0, 12))}
    cb, ca = base.mean(0), platform.mean(0)
    b, a = base - cb, platform - ca
    scale = max(float(np.abs(a).max()), float(np.abs(b).max()), float(np.abs(legs).max()), 1e-300)
    a, b = a / scale, b / scale
    d = (a * a).sum(1) + (b * b).sum(1) - (legs / scale) ** 2
    rng = np.random.default_rng([int(seed), 6])
    h = rng.standard_normal(8) + 1j * rng.standard_normal(8)
    theta = rng.uniform(0.3, 1.3) * rng.choice([-1.0, 1.0])
    Z0 = Z0 / (Z0 @ h)[:, None]                                    # the same roots in the chart h.z = 1
    Z, status, steps = _track(kernel, p0, (a, b, d), h, np.exp(1j * theta), Z0)
    ok = status == 0
    Zok = Z[ok]
    # squared distances |z_i - z_j|^2 from one Gram matrix (a 40x40x8 difference costs ~10x more)
    n2 = (Zok.real ** 2 + Zok.imag ** 2).sum(-1)
    d2 = n2[:, None] + n2[None] - 2.0 * (Zok @ Zok.conj().T).real
    near = d2 <= (_DISTINCT * (1.0 + np.sqrt(n2)))[:, None] ** 2
    apart = near.sum() == len(Zok)                                 # each endpoint near itself only
    roots = Zok if apart else _distinct(Zok, np.empty((0, 8), dtype=complex))
    out = {"paths": len(Z0), "roots": len(roots), "steps": int(steps.sum()), "certified": False, "reason": ""}
    if not ok.all():
        out["reason"] = f"{int((~ok).sum())} of {len(Z0)} paths did not end at a nonsingular root"
    elif len(roots) != len(Z0):
        out["reason"] = f"the {len(Z0)} paths ended at {len(roots)} distinct roots"
    else:
        out["certified"] = True
    Zr = roots
    k = np.abs(Zr).argmax(-1)
    pivot = Zr[np.arange(len(Zr)), k]
    Zr = Zr * (np.conj(pivot) / np.abs(pivot))[:, None]           # largest coordinate real and positive
    real = np.abs(Zr.imag).max(-1) <= _REAL * np.abs(Zr).max(-1)
    Zr = Zr[real].real
    e, g = Zr[:, :4], Zr[:, 4:]
    norm = np.sqrt((e * e).sum(-1))[:, None]
    e, g = e / norm, g / norm
    R = rotations.unit_quaternion_rows(e[:, 0], e[:, 1], e[:, 2], e[:, 3])
    u = e[:, :1] * g[:, 1:] - g[:, :1] * e[:, 1:] + np.cross(e[:, 1:], g[:, 1:])
    t = 2.0 * u * scale - np.einsum("njk,k->nj", R, ca) + cb      # back from the centred, scaled frames
    out["states"] = np.concatenate([t, R.reshape(-1, 9)], axis=1)
    return out
