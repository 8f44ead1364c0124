"""What the geometry of a serial chain tells the all-solutions search (:mod:`fkopt.kinematics.branches`),
detected numerically from the chain's joint axes (Plücker lines from its geometric Jacobian).

* **Pieper's bound.** A 6R chain (six revolute unknowns, each driving one joint) with three
  consecutive axes meeting in one point or parallel decouples into a position problem of three
  joints (a quartic: at most 4 solutions) and an orientation problem of the other three (at most 2
  each), so a pose has at most 8 solutions modulo 2 pi (Pieper, "The kinematics of manipulators
  under computer control", 1968; Siciliano et al., Robotics, 2009, sec. 2.12). When the search has
  8 distinct solutions it has all of them: that is a certificate, not a stopping rule. (Any
  three consecutive joints of the closed loop 1..6 and the tool: a triple in the middle decouples
  as well, the point -- or the direction, for parallel axes -- being fixed in the links on both
  sides of it.) The general 6R has at most 16 (Raghavan and Roth 1993), a bound the search does
  not use: the arms that attain it are rare and no count certifies fewer.
* **Counts.** Generically the count is a multiple of 4 with a concurrent triple: the position
  problem reduces to one angle whose equation is a real trigonometric polynomial, whose simple
  zeros on the circle are even in number (its sign changes around a period pair up), and each
  gives two orientations (the two roots of subproblem 2 are both real once one is). With a
  parallel triple (the UR family: shoulder, wrist and elbow each give 0 or 2) it is even. A count
  found that is not such a multiple is incomplete: the search goes on.
* **Two-solution windows.** Three consecutive revolute joints with the others held have at most
  two solutions when no two neighbours among them are parallel (the orientation alone is a
  rotation about each of three axes, Paden-Kahan subproblem 2: two values of the first two, the
  third then fixed) or when all three are parallel (a planar two-link elbow with the angle sum
  fixed by the orientation). When the search knows two solutions that share the held joints, the
  window's subproblem is complete, and derived starts on it are skipped.

Parallelism of neighbouring axes and concurrency of three consecutive axes do not change with the
joints, so one generic configuration decides them.
"""
from __future__ import annotations

import numpy as np

from fkopt.numerics.chain import Chain, frame_jacobian1

#: The bound of a 6R chain with a Pieper triple (module docstring).
PIEPER_BOUND = 8
#: Axes are parallel / lines meet when the sine / the distance (in units of the chain's size) is below this.
GEOMETRY_TOL = 1e-9


def axis_lines(chain: Chain) -> tuple[np.ndarray, np.ndarray] | None:
    """Unit directions (n, 3) and a point of each (n, 3) of the joint axes of the chain's unknowns
    at a generic configuration, or None when an unknown is prismatic or drives other than exactly one
    joint (mimic joints: no axis line of its own)."""
    moving = chain.mult != 0.0
    if chain.prismatic[moving].any():
        return None
    counts = np.bincount(chain.var[moving], minlength=chain.dof)
    if chain.dof == 0 or (counts != 1).any() or list(chain.var[moving]) != sorted(chain.var[moving]):
        return None
    t = [0.41 + 0.53 * k for k in range(chain.dof)]          # generic: no coincidences of axes
    p, _, J = frame_jacobian1(chain, t)
    J = np.array(J)
    sign = np.sign(chain.mult[moving])
    z = J[3:].T * sign[:, None]
    lin = J[:3].T * sign[:, None]
    # column = (z x (p - o), z): the moment o x z = lin - z x p; the point of the line nearest the origin z x (o x z)
    moment = lin - np.cross(z, np.asarray(p))
    return z, np.cross(z, moment)


def _parallel(a, b) -> bool:
    return float(np.linalg.norm(np.cross(a, b))) < GEOMETRY_TOL


def _concurrent(z, o, scale: float) -> bool:
    """Three lines through one point: the point nearest all three lies on each."""
    A = sum(np.eye(3) - np.outer(d, d) for d in z)
    b = sum((np.eye(3) - np.outer(d, d)) @ x for d, x in zip(z, o))
    if np.linalg.cond(A) > 1e12:
        return False
    c = np.linalg.solve(A, b)
    return all(np.linalg.norm(np.cross(d, c - x)) < GEOMETRY_TOL * scale for d, x in zip(z, o))


def structure(chain: Chain, windows: list[tuple[int, int]], scale: float) -> dict:
    """``bound``: :data:`PIEPER_BOUND` for a 6R chain with a Pieper triple, else 0 (none);
    ``triple``: its joints and kind; ``multiple``: the number the count of solutions is a multiple
    of (module docstring; 1: none known); ``pair_window``: the triple's window (its other solution
    always exists); ``free_window``: the other three joints when they are consecutive (drawn
    afresh from a solution with the triple free: the position subproblem's other roots);
    ``two_solution``: per window, whether its subproblem has at most two solutions.
    ``scale``: the chain's size (its reach)."""
    lines = axis_lines(chain)
    out = {"bound": 0, "multiple": 1, "triple": None, "pair_window": None, "free_window": None,
           "two_solution": [False] * len(windows)}
    if lines is None:
        return out
    z, o = lines
    n = chain.dof
    par = [_parallel(z[i], z[i + 1]) for i in range(n - 1)]
    for i, (a, b) in enumerate(windows):
        if b - a == 2:
            out["two_solution"][i] = (par[a] and par[a + 1]) or not (par[a] or par[a + 1])
    if n == 6:
        for i in range(n - 2):
            kind = "parallel" if par[i] and par[i + 1] else (
                "concurrent" if _concurrent(z[i:i + 3], o[i:i + 3], scale) else None)
            if kind:
                out["bound"], out["triple"] = PIEPER_BOUND, (i, i + 1, i + 2, kind)
                out["multiple"] = 4 if kind == "concurrent" else 2
                out["pair_window"] = (i, i + 2)
                if i in (0, n - 3):
                    out["free_window"] = (3, 5) if i == 0 else (0, 2)
                break
    return out


def reversed_chain(chain: Chain) -> Chain:
    """The same chain walked from the tool to the base, its unknowns renumbered from the tool:
    FK of the result at the reversed unknowns t[::-1] is the inverse of the chain's tool frame at
    t. With joint i's axis frame G_i = F_(i-1) C_i and F_i = G_i Rz(q_i), walking back gives
    F_(i-1) = G_i Rz(-q_i) C_i^T and p_(i-1) = p_i - F_(i-1) v_i, which is the chain form again
    with C' = C_(i+1)^T, v' = -C_(i+1)^T v_(i+1) (the tail's for the first), q' = -q; the base
    is the tail (C_0^T, -C_0^T v_0). A base triple of concurrent axes becomes a wrist triple."""
    m = len(chain.prismatic)
    order = np.arange(m)[::-1]
    Cn = np.concatenate([chain.C, chain.tail_C[None]])         # C_(i+1) for i = m - 1 is the tail's
    vn = np.concatenate([chain.v, chain.tail_v[None]])
    C = np.array([Cn[i + 1].T for i in order]).reshape(m, 3, 3)
    v = np.array([-Cn[i + 1].T @ vn[i + 1] for i in order]).reshape(m, 3)
    moving = chain.mult[order] != 0.0
    var = np.where(moving, chain.dof - 1 - chain.var[order], 0)
    return Chain(prismatic=chain.prismatic[order].copy(), C=C, v=v, var=var.astype(np.int64),
                 mult=-chain.mult[order], off=-chain.off[order], tail_C=chain.C[0].T.copy(),
                 tail_v=-chain.C[0].T @ chain.v[0], dof=chain.dof)
