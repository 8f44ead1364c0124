"""Every IK solution of a pose (``fkopt.inverse(arm, pose, solutions="all")``) and IK along a path
that stays on one branch (``fkopt.inverse_path``), for any frame arm fkopt reads (DH, URDF, MJCF).

**All solutions.** A numeric search over the branches, built on ``fkopt.inverse``'s compiled
one-pose loop (:mod:`fkopt.numerics.compiled_branches`): seeded starts, first the start table's
configurations nearest to the target in tool pose, then counter-based hash draws (revolute
joints over one turn, prismatic joints inside their limits); each start runs the damped
least-squares loop without revolute limits to ``SEARCH_TOL`` (a solution is one modulo 2 pi per
revolute joint), converged answers are wrapped and merged when every joint agrees within
``MERGE_TOL``; a start that ends close to a solution without converging (next to a singular
configuration, where the loop's steps shrink) is iterated on (``POLISH``). Each solution found
adds *derived* starts (:func:`_windows`): a window of joints drawn afresh with the others held at
its values, which reach the solutions sharing those joints with it (wrist and elbow flips, the
other shoulder side) where uniform starts rarely land; they run window by window across the
solutions (the flips that reach most in one start first), and a window whose subproblem has at
most two solutions is skipped once both are known (:mod:`fkopt.kinematics.branch_structure`
detects these from the chain's axes). A chain whose Pieper triple is at the base (the Panda with
joint 7 locked) is searched walked from the tool, where the triple is a wrist.
**When it stops.** A 6R chain with three consecutive axes parallel or meeting in a point has at
most 8 solutions (Pieper): when 8 distinct ones are found the search stops with a *certificate*.
Otherwise it stops after ``patience`` consecutive table or hash starts that found nothing new
(four times that while none is found; ``PIEPER_PATIENCE`` on such a chain, whose complete poses
end at the bound anyway), unless the count is not a multiple of what such a chain's counts are
(4 with a concurrent triple, 2 with a parallel one: some are missing), or after ``max_starts``.
That rule is not a certificate: a branch whose basin of attraction is small can be missed; its
measured miss rate against EAIK's analytic sets is in docs/robots.md, and ``result.search``
reports the rule that ended it, the starts run and the starts since the last new solution, so a
caller can ask for a larger ``patience``.

Each distinct solution is then mapped into the limits: every revolute joint takes the in-limit
value congruent modulo 2 pi that is nearest 0 (a continuous joint: its value wrapped into
[-180, 180)); a solution with a joint that has no in-limit copy is out of the limits and is
dropped (counted in ``result.search["out_of_limits"]``). A joint whose limits span more than
2 pi has several in-limit copies of one solution; ``copies=True`` lists every combination of
them as its own row (distinct configurations of the same branch), default off. Every row is
then verified: FK of the public answer against the target, position error <= tol[0] and
geodesic rotation error <= tol[1] (default 1e-9 m, 1e-9 rad); a row that fails is dropped
(``result.search["unverified"]``), never returned.

**Redundant arms** (more unknowns than task components) have infinitely many solutions:
``fixed={"joint": value}`` locks joints (public units) so that a finite set remains, as EAIK's
locked joints; ``spread=K`` samples the self-motion instead: the locked joints (``spread_joints``,
default the redundant count of joints from the third joint on, IKFast's usual free joint of a
7-joint arm) each take K values at the centres of K equal bins of their limits, every
combination is searched, and the union is returned, each row with its locked values.

**Paths.** ``inverse_path(arm, poses, start=q0)`` follows one branch: waypoint k's loop starts at
waypoint k-1's answer plus the step that reached it (a linear predictor, so that where two branches
meet at a singularity -- an elbow passing straight -- the path stays on its own; no table, no
restarts). A redundant arm starts from the previous answer alone (the minimum-norm step; with the
predictor its self-motion drifted further: 6 of 20 Panda paths broke against 4) and saturates at
its limits, its self-motion absorbing them; it is re-seated after a break by ``fkopt.inverse``
from the previous answer (then along the self-motion to the locally nearest solution). The answer passes when it converges within
``tol``, stays inside the limits, and no joint moves more than ``max_step`` (radians, or length
units for a prismatic joint). A waypoint that does not pass is tried again through ``substeps``
intermediate poses (position linear, rotation along the geodesic) from the previous answer,
which follows a branch through a larger gap; when that passes too the waypoint passes. When it
does not, the path leaves its branch there and ``result.breaks`` says why: ``unreachable`` (no
solution of the waypoint at all, limits ignored), ``joint limit`` (the followed branch reaches
the waypoint only outside a joint's limits), ``singularity`` (the branch stops converging or its
joints move faster than ``max_step`` near a configuration whose smallest singular value of the
Jacobian is below ``SINGULAR``), or ``step`` (the branch moves more than ``max_step`` between two
waypoints away from a singularity: waypoints too far apart for the bound). After a break the path
continues from the waypoint's solution nearest the previous answer (from :func:`all_solutions`),
so the flip is explicit; an unreachable waypoint keeps the previous joints and its errors say so.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from fkopt.errors import FkoptError
from fkopt.kinematics.branch_structure import reversed_chain, structure
from fkopt.kinematics.inputs import (_internal, _inverse_arm, _public, _targets, _task_mask, _tolerance,
                                     _unreachable, _values)
from fkopt.kinematics.results import INVERSE_TOL
from fkopt.kinematics.solvers import inverse
from fkopt.kinematics.start_tables import _sumsq, _uniform_hash
from fkopt.mechanisms.base import SerialMechanism
from fkopt.numerics import path as numerics_path, rotations
from fkopt.numerics.rotations import rotation_error1
from fkopt.numerics.chain import Chain

#: Tolerances of the solutions returned by ``solutions="all"`` unless ``tol`` is given
#: (position in the arm's length unit, geodesic rotation in radians).
ALL_TOL = (1e-9, 1e-9)
#: The loop of each start iterates to this (position, rotation); a start counts as converged at
#: ``ACCEPT_TOL`` (answers are then verified at the caller's ``tol`` in public units).
SEARCH_TOL = (1e-12, 1e-12)
ACCEPT_TOL = (1e-10, 1e-10)
#: Two converged answers are one solution when every joint agrees within this (rad / length unit;
#: revolute joints modulo 2 pi). Near a singularity (an elbow within 0.01 deg of straight) the
#: loop's answers of one solution scatter by a few 1e-6 rad while still verifying at 1e-9, and the
#: two solutions on either side of it are ~1e-4 rad apart (EAIK's pair on the Kinova, docs/robots.md).
MERGE_TOL = 1e-5
#: Stopping rule defaults: consecutive starts without a new solution, most starts per pose; on a
#: chain with Pieper's bound (branch_structure) a pose with all its solutions stops at the bound, so
#: the larger patience there costs only on the poses with fewer.
PATIENCE = 32
PIEPER_PATIENCE = 128
#: ... and at least this many times the starts it took to find the last new solution.
GROWTH = 0.0
MAX_STARTS = 400
#: Start-table neighbours tried before the hash draws.
NEIGHBOURS = 16
#: Loop iterations per start (a far start needs more than inverse's 10).
ITERATIONS = 20
#: Derived starts: draws per (solution, window) pair (a two-solution window / the others) and loop
#: iterations of each (a held start either lies in a sibling's basin, reached in a few, or in none).
TWO_DRAWS = 2
#: ... the window of a Pieper triple, whose other solution always exists (branch_structure)
PAIR_DRAWS = 12
POLISH = 1e-3
POLISH_ITERATIONS = 100
HELD_DRAWS = 4
HELD_ITERATIONS = 10
#: Most distinct solutions kept per pose (a generic 6R arm has at most 16).
CAP = 64
#: inverse_path: default largest joint step between waypoints (rad / length unit), intermediate
#: poses tried across a waypoint that does not pass, and the smallest singular value of the
#: (orientation-scaled) Jacobian below which a break is called a singularity.
MAX_STEP = 0.05
SUBSTEPS = 16
SINGULAR = 1e-3
#: inverse_path's predictor on a redundant arm (module docstring: off, measured).
PREDICT = False


@dataclass
class AllSolutions:
    """Every solution found for one pose: ``solutions`` (k, n) in the arm's public units (deg,
    length unit), each inside the limits and verified; ``position_error`` (k,) and
    ``rotation_error`` (k,) of FK of each row against the target; ``fixed`` the locked joints'
    public values (per row, (k, r), for ``spread``); ``search`` how the search decided it had them
    all (rule, starts run, converged starts, starts since the last new solution, evaluations,
    distinct solutions before the limits, out of limits, unverified)."""

    mechanism: str
    names: tuple[str, ...]
    solutions: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    fixed: dict = field(default_factory=dict)
    search: dict = field(default_factory=dict)
    tol: tuple[float, float] = ALL_TOL

    def __len__(self) -> int:
        return len(self.solutions)

    def as_dict(self) -> dict:
        return {"solutions": [dict(zip(self.names, map(float, row))) for row in self.solutions],
                "position_error": [float(v) for v in self.position_error],
                "rotation_error_rad": [float(v) for v in self.rotation_error],
                "fixed": {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in self.fixed.items()},
                "search": dict(self.search), "tol": list(self.tol)}


@dataclass
class PathResult:
    """One branch along a path (or a batch of paths: leading axes first). ``joints`` (..., w, n)
    public units; ``position_error`` / ``rotation_error`` (..., w); ``solved`` (..., w) bool;
    ``breaks``: per path a list of (waypoint index, reason, detail) where the path left its
    branch (reasons: 'unreachable', 'joint limit', 'singularity', 'step'); ``max_step`` the bound
    held between waypoints without a break."""

    mechanism: str
    names: tuple[str, ...]
    joints: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    solved: np.ndarray
    breaks: list
    max_step: float
    tol: tuple[float, float]


# ----------------------------------------------------------------------------------------------
# per-arm context (the chain with locked joints, its start table)
# ----------------------------------------------------------------------------------------------
def _arm(arm) -> SerialMechanism:
    m = _inverse_arm(arm)
    if not hasattr(m, "chain"):
        raise FkoptError(f"inverse solutions='all' needs a frame arm with a chain (DH, URDF, MJCF); "
                         f"'{m.name}' has none")
    return m


def _locked(m, fixed) -> dict[int, float]:
    """``fixed`` {joint name: public value} as {index: internal value}, checked."""
    if not fixed:
        return {}
    if not isinstance(fixed, dict):
        raise FkoptError(f"{m.name} fixed: expected {{joint name: value}}, got {fixed!r}")
    out = {}
    angle = m.angle_mask(m.joint_units)
    for name, value in fixed.items():
        if name not in m.joint_names:
            raise FkoptError(f"{m.name} fixed: unknown joint {name!r}; joints: {', '.join(m.joint_names)}")
        i = m.joint_names.index(name)
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise FkoptError(f"{m.name} fixed {name}: expected a number, got {value!r}") from None
        lo, hi = m.bounds[i]
        if not (math.isfinite(v) and lo - 1e-9 <= v <= hi + 1e-9):
            raise FkoptError(f"{m.name} fixed {name}: {value!r} outside the joint's limits [{lo:g}, {hi:g}]")
        out[i] = math.radians(v) if angle[i] else v
    if len(out) >= m.dof:
        raise FkoptError(f"{m.name} fixed: locks all {m.dof} joints; leave at least one free")
    return out


def _reduced_chain(chain, locked: dict[int, float]):
    """The chain with unknowns ``locked`` {index: internal value} turned into constants: every
    moving joint driven by a locked unknown gets multiplier 0 and offset mult * value + offset,
    the remaining unknowns renumbered in order."""
    if not locked:
        return chain
    keep = [k for k in range(chain.dof) if k not in locked]
    new_index = {k: i for i, k in enumerate(keep)}
    var, mult, off = chain.var.copy(), chain.mult.copy(), chain.off.copy()
    for j in range(len(var)):
        k = int(var[j])
        if k in locked:
            off[j] = mult[j] * locked[k] + off[j]
            mult[j] = 0.0
            var[j] = 0
        else:
            var[j] = new_index[k]
    return Chain(prismatic=chain.prismatic, C=chain.C, v=chain.v, var=var, mult=mult, off=off,
                 tail_C=chain.tail_C, tail_v=chain.tail_v, dof=len(keep))


_CONTEXTS_PER_ARM = 64
#: Start-table size of the search (as inverse's default table).
TABLE = 4096


def _context(m, locked: dict[int, float], W) -> dict:
    """The search's constants for arm m with joints ``locked``: the reduced chain as arrays, the
    free joints' internal limits, revolute mask, draw box, and a start table of ``TABLE`` free
    configurations drawn by inverse's fixed hash inside the limits, with their tool features as inverse's table. Cached on
    the arm by (bounds, locked values, mask)."""
    key = (m.bounds.tobytes(), tuple(sorted(locked.items())), None if W is None else W.tobytes())
    cache = m.__dict__.setdefault("_branch_contexts", {})
    got = cache.get(key)
    if got is not None:
        return got
    if len(cache) >= _CONTEXTS_PER_ARM:
        cache.pop(next(iter(cache)))
    n = m.dof
    free = np.array([k for k in range(n) if k not in locked], dtype=np.intp)
    chain = _reduced_chain(m.chain(), locked)
    lo, hi = _internal(m, m.bounds[:, 0]), _internal(m, m.bounds[:, 1])
    angle = m.angle_mask(m.joint_units)
    # revolute = an angle unknown that drives revolute joints (prismatic joints have length units)
    revolute = angle.copy()
    # draws: a revolute joint over one whole turn (the search solves modulo 2 pi, limits after),
    # a prismatic one inside its limits
    glo = np.where(revolute, -np.pi, lo)
    ghi = np.where(revolute, np.pi, hi)
    full = lo + (hi - lo) * _uniform_hash(0x5EED, np.arange(TABLE), np.zeros(TABLE, dtype=np.int64), n)
    for k, v in locked.items():
        full[:, k] = v
    p, R = m.frame(_public(m, full))
    wf = m.reach / (3.0 * np.sqrt(2.0))
    feats = np.concatenate([np.stack(p, axis=-1), wf * rotations.to_array(R).reshape(TABLE, 9)], axis=-1)
    Wf = np.ones(6) if W is None else np.asarray(W, dtype=float)
    fmask = np.concatenate([Wf[:3], np.full(9, float(Wf[3:].all()))])
    feats = feats * fmask
    tq = full[:, free]
    shape = _shape(chain, m.reach, Wf)
    got = {"structure": shape, "n": len(free), "chain": chain.arrays(), "chain_obj": chain, "free": free,
           "locked": dict(locked), "tq": np.ascontiguousarray(tq), "Ft": np.ascontiguousarray(feats.T),
           "norms": _sumsq(feats), "w": float(wf), "fmask": fmask, "W": Wf,
           "lo": np.ascontiguousarray(lo[free]), "hi": np.ascontiguousarray(hi[free]),
           "glo": np.ascontiguousarray(glo[free]), "ghi": np.ascontiguousarray(ghi[free]),
           "revolute": np.ascontiguousarray(revolute[free]), "angle": angle,
           "periodic": np.ascontiguousarray(m.periodic_mask()[free]), "full_lo": lo, "full_hi": hi,
           "full_chain": m.chain().arrays(), "reversed": False}
    if shape["bound"] and shape["triple"][0] == 0:
        # the Pieper triple at the base (the Panda with joint 7 locked): the search runs on the
        # chain walked from the tool (branch_structure.reversed_chain), where it is a wrist, and
        # the derived starts (the wrist's flip, the solutions sharing the first joint, the other
        # side of it) reach the branches as on a wrist-partitioned arm; the target is the inverse
        # pose, the start table's features those of the inverse frames, the unknowns reversed
        back = reversed_chain(chain)
        Ri = np.swapaxes(rotations.to_array(R).reshape(TABLE, 3, 3), 1, 2)
        pi = -np.einsum("kij,kj->ki", Ri, np.stack(p, axis=-1))
        fb = np.concatenate([pi, wf * Ri.reshape(TABLE, 9)], axis=-1) * fmask
        rev = {key: np.ascontiguousarray(got[key][::-1]) for key in ("lo", "hi", "glo", "ghi", "revolute", "periodic")}
        got["search"] = dict(got, **rev, structure=_shape(back, m.reach, Wf), chain=back.arrays(), chain_obj=back,
                             tq=np.ascontiguousarray(tq[:, ::-1]), Ft=np.ascontiguousarray(fb.T), norms=_sumsq(fb),
                             reversed=True)
    else:
        got["search"] = got
    cache[key] = got
    return got


def _shape(chain, reach: float, Wf: np.ndarray) -> dict:
    """The chain's structure (branch_structure.structure) with the derived starts' windows in the
    order the search takes them."""
    windows = _windows(chain.dof)
    shape = structure(chain, windows, reach)
    # the Pieper triple's window first (its flip always exists), then the wide ones (the other
    # shoulder side, the solutions sharing the base joint), then the other windows whose subproblem
    # has two solutions (a wrist or elbow flip, one start), the rest last
    rank = [0 if w == shape["pair_window"] else 1 if w[1] - w[0] > 2 else 2 if two else 3
            for w, two in zip(windows, shape["two_solution"])]
    order = sorted(range(len(windows)), key=lambda i: (rank[i], -windows[i][1] + windows[i][0], i))
    shape["windows"] = [windows[i] for i in order]
    shape["two_solution"] = [shape["two_solution"][i] for i in order]
    shape["hold"] = [True] * len(order)
    if shape["free_window"] is not None:
        shape["windows"].append(shape["free_window"])
        shape["two_solution"].append(False)
        shape["hold"].append(False)
    if not Wf.all():
        shape["bound"] = 0                        # a masked pose: fewer equations, Pieper's count does not hold
    return shape


def _kernels():
    if numerics_path.compiled(True) is None:          # FKOPT_NUMERICS=numpy
        raise FkoptError("inverse solutions='all' and inverse_path run on the compiled kernels; "
                         "they need numba (pip install numba) and FKOPT_NUMERICS other than numpy")
    from fkopt.numerics import compiled_branches     # lazy: numba, an optional package
    return compiled_branches


# ----------------------------------------------------------------------------------------------
# all solutions
# ----------------------------------------------------------------------------------------------
def _in_limit_copies(w: np.ndarray, ctx: dict, copies: bool) -> list[np.ndarray]:
    """The in-limit representatives of one wrapped solution (free joints, internal units): per
    revolute joint the congruent values inside [lo, hi] (nearest 0 first; all of them with
    ``copies``, else that one); none when some joint has no in-limit value."""
    per = []
    for i, v in enumerate(w.tolist()):
        lo, hi = float(ctx["lo"][i]), float(ctx["hi"][i])
        if ctx["periodic"][i]:
            per.append([v])
            continue
        if not ctx["revolute"][i]:
            per.append([v] if lo - 1e-12 <= v <= hi + 1e-12 else [])
        else:
            k0, k1 = math.ceil((lo - v) / (2 * math.pi) - 1e-12), math.floor((hi - v) / (2 * math.pi) + 1e-12)
            vals = sorted((min(max(v + 2 * math.pi * k, lo), hi) for k in range(k0, k1 + 1)), key=abs)
            per.append(vals if copies else vals[:1])
        if not per[-1]:
            return []
    return [np.array(c) for c in itertools.product(*per)]


def _verify(m, ctx, pose_row: np.ndarray, public_full: np.ndarray, W) -> tuple[float, float]:
    """FK of a full public answer against the target row, with the arm's own one-configuration
    forward map (``frame_jacobian1``, the numbers ``fkopt.inverse`` verifies with)."""
    angle = ctx["angle"]
    t = [math.radians(v) if a else v for v, a in zip(public_full.tolist(), angle)]
    p, R, _ = m.frame_jacobian1(t)
    Rt = pose_row[3:].reshape(3, 3).tolist() if len(pose_row) == 12 else rotations.zyz1(*pose_row[3:].tolist())
    dp = [a - b for a, b in zip(p, pose_row[:3].tolist())]
    e = rotation_error1(R, Rt)
    if W is not None:
        dp, e = [v * w for v, w in zip(dp, W[:3])], [v * w for v, w in zip(e, W[3:])]
    re = math.hypot(*e)
    if W is None or all(W[3:]):
        # the geodesic angle of R Rt^T from its skew part and its trace: the rotation vector
        # above vanishes at exactly pi, where a turn by pi about the tool axis would pass
        M = [[sum(R[a][k] * Rt[b][k] for k in range(3)) for b in range(3)] for a in range(3)]
        s = 0.5 * math.sqrt((M[2][1] - M[1][2]) ** 2 + (M[0][2] - M[2][0]) ** 2 + (M[1][0] - M[0][1]) ** 2)
        re = max(re, math.atan2(s, 0.5 * (M[0][0] + M[1][1] + M[2][2] - 1.0)))
    return math.hypot(*dp), re


def _inverse_row(row: np.ndarray) -> np.ndarray:
    """The inverse of a target (a pose row (6,) in ZYZ degrees or a frame row (12,)) as a frame row."""
    R = np.array(rotations.zyz1(*row[3:].tolist())) if len(row) == 6 else row[3:].reshape(3, 3)
    return np.ascontiguousarray(np.concatenate([-R.T @ row[:3], R.T.reshape(9)]))


def _windows(n: int) -> list[tuple[int, int]]:
    """The derived starts' windows (first, last joint drawn afresh; the others held): every three
    consecutive joints (a wrist, three parallel axes); all but the first joint (the solutions
    that share the base rotation: a UR's four per shoulder side, which a near-straight wrist
    makes hard to reach otherwise); and every joint, from the first turned by pi (the other
    shoulder side; the kernel reads the window (0, n - 1) so)."""
    if n <= 3:
        return []
    return [(i, i + 2) for i in range(n - 2)] + ([(1, n - 1), (0, n - 1)] if n > 4 else [])


def _spread_locks(m, spread, spread_joints, redundancy: int) -> list[dict[int, float]]:
    """The locked values of ``spread``: K values per locked joint at the centres of K equal bins
    of its limits, every combination."""
    try:
        K = int(spread)
    except (TypeError, ValueError):
        K = 0
    if K < 1 or isinstance(spread, bool) or float(spread) != K:
        raise FkoptError(f"{m.name} spread: expected an integer >= 1 (samples per locked joint), got {spread!r}")
    if spread_joints is None:
        first = min(2, m.dof - redundancy)
        idx = list(range(first, first + redundancy))
    else:
        names = [spread_joints] if isinstance(spread_joints, str) else list(spread_joints)
        bad = [s for s in names if s not in m.joint_names]
        if bad:
            raise FkoptError(f"{m.name} spread_joints: unknown joint {bad[0]!r}; joints: {', '.join(m.joint_names)}")
        idx = [m.joint_names.index(s) for s in names]
    lo, hi = _internal(m, m.bounds[:, 0]), _internal(m, m.bounds[:, 1])
    axes = [[float(lo[i] + (hi[i] - lo[i]) * (s + 0.5) / K) for s in range(K)] for i in idx]
    return [dict(zip(idx, vals)) for vals in itertools.product(*axes)]


def locked_sets(arm, *, fixed=None, spread=None, spread_joints=None, mask=None) -> list[dict[int, float]]:
    """The sets of locked joints ({index: internal value}) the search runs once each: ``fixed``'s
    one set, ``spread``'s every combination, or no lock; checked without searching (an unknown
    joint, a value outside its limits, a redundant arm without either, both given), so a caller
    can validate its options before any pose (an experiment file's plan)."""
    m = _arm(arm)
    W = _task_mask(mask)
    tasks = 6 if W is None else int(W.sum())
    locked = _locked(m, fixed)
    redundancy = m.dof - len(locked) - tasks
    if spread is not None:
        if locked:
            raise FkoptError(f"{m.name}: give fixed or spread, not both")
        if redundancy <= 0:
            raise FkoptError(f"{m.name} spread: the arm has no self-motion ({m.dof} joints, {tasks} task components)")
        return _spread_locks(m, spread, spread_joints, redundancy)
    if redundancy > 0:
        raise FkoptError(f"{m.name} has {m.dof} joints for {tasks} task components: its solutions are "
                         f"not finite; give fixed={{joint: value}} for {redundancy} joint(s) "
                         f"(joints: {', '.join(m.joint_names)}) or spread=K to sample the self-motion")
    return [locked]


def all_solutions(arm, pose, *, fixed=None, spread=None, spread_joints=None, tol=None, mask=None, seed: int = 0,
                  patience: int | None = None, growth: float = GROWTH, max_starts: int = MAX_STARTS, copies: bool = False,
                  orientation_scale: float | None = None) -> AllSolutions:
    """Every solution of one pose (6,) or tip frame (4, 4): see the module docstring.
    ``fixed``: {joint name: value} locked joints (public units); ``spread``: K samples per locked
    joint of a redundant arm's self-motion (``spread_joints`` names them); ``tol``: the
    verification tolerances (default :data:`ALL_TOL`); ``seed``: the hash draws' stream;
    ``patience`` / ``max_starts``: the stopping rule (``patience`` by default :data:`PATIENCE`,
    :data:`PIEPER_PATIENCE` on a chain with Pieper's bound; ``growth`` > 0 also asks for at least
    ``growth`` times the starts that found the last new solution; 0 by default, measured no
    better); ``copies``: list every in-limit copy of a
    joint whose limits span more than 2 pi."""
    m = _arm(arm)
    tp, tr = _tolerance(ALL_TOL if tol is None else tol)
    P = _targets(m, pose)
    if P.ndim != 1:
        raise FkoptError(f"{m.name} all solutions: one pose at a time here (got shape {np.shape(pose)}); "
                         "fkopt.inverse(arm, poses, solutions='all') takes a batch")
    for name, v, low in (("patience", 1 if patience is None else patience, 1), ("max_starts", max_starts, 1)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < low:
            raise FkoptError(f"{m.name} all solutions {name}: expected an integer >= {low}, got {v!r}")
    x, y, z = P[:3].tolist()
    dist = math.sqrt(x * x + y * y + z * z)
    if dist > m.reach * (1.0 + 1e-12):
        raise _unreachable(m, x, y, z, dist)
    W = _task_mask(mask)
    locks = locked_sets(m, fixed=fixed, spread=spread, spread_joints=spread_joints, mask=W)
    kern = _kernels()
    L = float(orientation_scale) if orientation_scale else m.reach
    row = np.ascontiguousarray(P, dtype=float)
    rows, perr, rerr, fixed_rows = [], [], [], []
    stats = {"starts": 0, "converged": 0, "evaluations": 0, "distinct": 0, "out_of_limits": 0, "unverified": 0,
             "since_last_new": [], "last_new_start": [], "found_at": [], "complete": []}
    if patience is None:
        patience = PIEPER_PATIENCE if _context(m, locks[0], W)["structure"]["bound"] else PATIENCE
    for lk in locks:
        ctx = _context(m, lk, W)
        nn = min(NEIGHBOURS, len(ctx["tq"]))
        side = ctx["search"]
        plan = side.get("plan")
        if plan is None:
            shape = side["structure"]
            draws = [PAIR_DRAWS if w == shape["pair_window"] else TWO_DRAWS if two else HELD_DRAWS
                     for w, two in zip(shape["windows"], shape["two_solution"])]
            plan = side["plan"] = kern.search_plan(shape["windows"], shape["hold"], shape["two_solution"], draws,
                                                   shape["bound"], shape["multiple"], HELD_ITERATIONS, POLISH,
                                                   POLISH_ITERATIONS, side["revolute"], side["lo"], side["hi"])
        sols, found_at, info = kern.search(side, plan, _inverse_row(row) if side["reversed"] else row, L, side["W"],
                                           nn, int(seed), int(max_starts), int(patience), SEARCH_TOL, ACCEPT_TOL,
                                           ITERATIONS, 0.01, 0.1, 10.0, 2.0, side["glo"], side["ghi"],
                                           side["revolute"], MERGE_TOL, CAP, float(growth))
        if side["reversed"]:
            sols = np.ascontiguousarray(sols[:, ::-1])
        stats["starts"] += int(info[0])
        stats["converged"] += int(info[1])
        stats["evaluations"] += int(info[2])
        stats["since_last_new"].append(int(info[3]))
        stats["last_new_start"].append(int(info[4]))
        stats["distinct"] += len(sols)
        stats["complete"].append(bool(info[5]))
        stats["found_at"].append(found_at.tolist())
        full = np.zeros(m.dof)
        for k, v in lk.items():
            full[k] = v
        if not copies:
            # compiled: each solution's in-limit copy nearest 0, verified (as the loop below)
            pub_rows, errs, status = kern.into_limits(sols, ctx["free"], full, ctx["angle"], ctx["revolute"],
                                                      ctx["periodic"], ctx["lo"], ctx["hi"], m.bounds[:, 0],
                                                      m.bounds[:, 1], ctx["full_chain"], row, ctx["W"])
            stats["out_of_limits"] += int((status == 1).sum())
            ok = (status == 0) & (errs[:, 0] <= tp) & (errs[:, 1] <= tr)
            stats["unverified"] += int(((status == 0) & ~ok).sum())
            rows.extend(pub_rows[ok])
            perr.extend(errs[ok, 0].tolist())
            rerr.extend(errs[ok, 1].tolist())
            fixed_rows.extend(pub_rows[ok][:, sorted(lk)].tolist())
            sols = sols[:0]
        for w in sols:
            reps = _in_limit_copies(w, ctx, copies)
            if not reps:
                stats["out_of_limits"] += 1
                continue
            for rep in reps:
                full[ctx["free"]] = rep
                pub = _public(m, full)
                pub = np.clip(pub, m.bounds[:, 0], m.bounds[:, 1])
                pe, re = _verify(m, ctx, row, pub, W)
                if not (pe <= tp and re <= tr):
                    stats["unverified"] += 1
                    continue
                rows.append(pub)
                perr.append(pe)
                rerr.append(re)
                fixed_rows.append([pub[k] for k in sorted(lk)])
    if len(locks) == 1:
        for key in ("since_last_new", "last_new_start", "found_at", "complete"):
            stats[key] = stats[key][0]
    shape = _context(m, locks[0], W)["structure"]
    done = stats["complete"] if isinstance(stats["complete"], list) else [stats["complete"]]
    if shape["bound"] and all(done):
        i, j, k, kind = shape["triple"]
        stats["rule"] = (f"certificate: {shape['bound']} distinct solutions found, Pieper's bound for a 6R chain "
                         f"whose joints {i + 1}, {j + 1}, {k + 1} have {kind} axes: there are no more")
    else:
        quiet = stats["since_last_new"] if isinstance(stats["since_last_new"], list) else [stats["since_last_new"]]
        how = (f"stopped after {patience} consecutive starts without a new solution" if min(quiet) >= patience else
               f"stopped at {max_starts} starts, before {patience} consecutive ones without a new solution")
        stats["rule"] = f"{how}; no certificate: the miss rate is measured in docs/robots.md"
    stats["patience"], stats["max_starts"] = int(patience), int(max_starts)
    n = m.dof
    sol = np.array(rows).reshape(-1, n)
    order = np.lexsort(sol.T[::-1]) if len(sol) else np.arange(0)
    names = [m.joint_names[k] for k in sorted(locks[0])] if locks[0] else []
    fx = np.array(fixed_rows).reshape(len(rows), len(names))[order] if names else np.zeros((len(rows), 0))
    fixed_out = {nm: fx[:, j] for j, nm in enumerate(names)} if spread is not None else \
        {nm: float(fx[0, j]) if len(fx) else float(_public(m, np.array([locks[0][k] if i == k else 0.0
                                                                        for i in range(n)]))[k])
         for j, (nm, k) in enumerate(zip(names, sorted(locks[0])))}
    return AllSolutions(mechanism=m.name, names=tuple(m.joint_names), solutions=sol[order],
                        position_error=np.array(perr)[order], rotation_error=np.array(rerr)[order],
                        fixed=fixed_out, search=stats, tol=(tp, tr))


#: The keywords of :func:`all_solutions` that ``fkopt.inverse(..., solutions="all")`` passes on.
ALL_OPTIONS = ("fixed", "spread", "spread_joints", "patience", "growth", "max_starts", "copies",
               "orientation_scale")


def inverse_all(arm, poses, *, tol=None, mask=None, seed: int = 0, **options):
    """``fkopt.inverse(arm, poses, solutions="all")``: one pose -> :class:`AllSolutions`; a batch
    (..., 6) or (..., 4, 4) -> a list of them, rows in C order of the leading axes."""
    bad = sorted(set(options) - set(ALL_OPTIONS))
    if bad:
        raise FkoptError(f"inverse solutions='all': option {bad[0]!r} is the one-answer solver's; "
                         f"allowed: tol, mask, seed, {', '.join(ALL_OPTIONS)}")
    if tol is INVERSE_TOL:                         # the one-answer default passed on: this search's own
        tol = None
    m = _arm(arm)
    P = _targets(m, poses)
    if P.ndim == 1:
        return all_solutions(m, P if P.shape[0] == 6 else poses, tol=tol, mask=mask, seed=seed, **options)
    flat = P.reshape(-1, P.shape[-1])
    if flat.shape[1] == 12:
        frames = np.zeros((len(flat), 4, 4))
        frames[:, :3, 3] = flat[:, :3]
        frames[:, :3, :3] = flat[:, 3:].reshape(-1, 3, 3)
        frames[:, 3, 3] = 1.0
        return [all_solutions(m, f, tol=tol, mask=mask, seed=seed, **options) for f in frames]
    return [all_solutions(m, r, tol=tol, mask=mask, seed=seed, **options) for r in flat]


# ----------------------------------------------------------------------------------------------
# paths
# ----------------------------------------------------------------------------------------------
def _frames(m, poses) -> np.ndarray:
    """Targets (..., w, 6) or (..., w, 4, 4) as rows (..., w, 12): x, y, z, R row-major."""
    P = _targets(m, poses)
    if P.shape[-1] == 12:
        return np.ascontiguousarray(P, dtype=float)
    flat = P.reshape(-1, 6)
    out = np.concatenate([flat[:, :3], rotations.zyz_rows(flat[:, 3:]).reshape(-1, 9)], axis=1)
    return np.ascontiguousarray(out.reshape(P.shape[:-1] + (12,)))


def _between(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    """The frame row a fraction s of the way from a to b (12,): position linear, rotation along
    the geodesic (Ra exp(s log(Ra^T Rb)))."""
    from scipy.spatial.transform import Rotation
    Ra, Rb = a[3:].reshape(3, 3), b[3:].reshape(3, 3)
    rel = Rotation.from_matrix(Ra.T @ Rb).as_rotvec()
    R = Ra @ Rotation.from_rotvec(s * rel).as_matrix()
    return np.concatenate([a[:3] + s * (b[:3] - a[:3]), R.reshape(9)])


def _smallest_singular(m, t, L: float) -> float:
    """Smallest singular value of the frame Jacobian at internal joints t, rotation rows times
    L (length units per radian), per internal unit."""
    _, _, J = m.frame_jacobian1([float(v) for v in t])
    J = np.array(J)
    J[3:] *= L
    return float(np.linalg.svd(J, compute_uv=False)[-1])


def inverse_path(arm, poses, *, start, tol=ALL_TOL, max_step: float = MAX_STEP, substeps: int = SUBSTEPS,
                 orientation_scale: float | None = None, iterations: int = ITERATIONS) -> PathResult:
    """Joints along a path of poses that stay on one branch: see the module docstring.

    ``poses``: (w, 6) / (w, 4, 4) waypoints, or a batch of paths (p, w, 6) / (p, w, 4, 4);
    ``start``: the joints before the first waypoint (n,) or one per path (p, n), public units,
    inside the limits; ``tol``: a waypoint's (position, rotation) tolerance; ``max_step``: the
    largest joint change between waypoints (rad, or length unit for a prismatic joint) without a
    break; ``substeps``: intermediate poses tried across a waypoint the direct step misses."""
    m = _arm(arm)
    tp, tr = _tolerance(tol)
    if not (isinstance(max_step, (int, float)) and not isinstance(max_step, bool) and max_step > 0
            and math.isfinite(max_step)):
        raise FkoptError(f"{m.name} inverse_path max_step: expected a positive number (rad), got {max_step!r}")
    if isinstance(substeps, bool) or not isinstance(substeps, (int, np.integer)) or substeps < 1:
        raise FkoptError(f"{m.name} inverse_path substeps: expected an integer >= 1, got {substeps!r}")
    F = _frames(m, poses)
    if F.ndim < 2:
        raise FkoptError(f"{m.name} inverse_path poses: expected waypoints (w, 6) or (w, 4, 4), got one pose")
    batch = F.shape[:-2]
    w = F.shape[-2]
    Fp = F.reshape((-1, w, 12))
    S = _values(m, start, m.joint_names, "inverse_path start")
    if S.ndim == 1:
        S = np.broadcast_to(S, (len(Fp), m.dof))
    S = S.reshape(-1, m.dof)
    if len(S) != len(Fp):
        raise FkoptError(f"{m.name} inverse_path start: one start per path, got {len(S)} for {len(Fp)} paths")
    if not m.in_bounds(S).all():
        box = ", ".join(f"{a} [{b[0]:g}, {b[1]:g}]" for a, b in zip(m.joint_names, m.bounds.tolist()))
        raise FkoptError(f"{m.name} inverse_path start: joints must be inside the limits ({box})")
    kern = _kernels()
    L = float(orientation_scale) if orientation_scale else m.reach
    per = m.periodic_mask()
    lo = np.where(per, -np.inf, _internal(m, m.bounds[:, 0]))
    hi = np.where(per, np.inf, _internal(m, m.bounds[:, 1]))
    chain = m.chain().arrays()
    W = np.ones(6)
    # a redundant arm saturates at its limits while following (its self-motion absorbs them);
    # a non-redundant one follows unsaturated, so that a limit shows as a limit break
    slo, shi = (lo, hi) if m.dof > 6 else (np.full(m.dof, -np.inf), np.full(m.dof, np.inf))
    predict = PREDICT if m.dof > 6 else True
    n = m.dof
    J = np.empty((len(Fp), w, n))
    E = np.empty((len(Fp), w, 2))
    breaks = []
    for path in range(len(Fp)):
        P = Fp[path]
        out, errs = J[path], E[path]
        q = _internal(m, S[path]).astype(float)
        found = []
        k = 0
        while k < w:
            k = kern.track(chain, P, k, q, L, W, (tp, tr), iterations, 0.01, 0.1, 10.0, 2.0, lo, hi, slo, shi,
                           max_step, out, errs, predict)
            if k >= w:
                break
            # the direct step missed: follow the branch through intermediate poses
            prev = P[k - 1] if k > 0 else _frames(m, m.fk_matrix(_public(m, q)[None]))[0]
            sub = np.array([_between(prev, P[k], (i + 1) / substeps) for i in range(substeps)])
            qs = q.copy()
            so, se = np.empty((substeps, n)), np.empty((substeps, 2))
            f = kern.track(chain, sub, 0, qs, L, W, (tp, tr), iterations, 0.01, 0.1, 10.0, 2.0, lo, hi, slo, shi,
                           max(max_step, 0.5), so, se, predict)
            if f >= substeps and np.abs(qs - q).max() <= max_step:
                out[k], errs[k] = qs, se[-1]
                q = qs
                k += 1
                continue
            reason, detail = _why(m, P, k, q, qs, so, se, f, substeps, L, lo, hi, tp, tr, max_step)
            chosen = _reseat(m, P[k], q, tp, tr)
            if chosen is None or isinstance(chosen, str):
                out[k] = q
                p1, R1, _ = m.frame_jacobian1(q.tolist())
                errs[k] = _frame_errors(p1, R1, P[k])
                if isinstance(chosen, str):
                    reason, detail = "joint limit", ("every solution of this waypoint lies outside the joint limits; "
                                                     "the previous joints are kept")
                else:
                    reason = "unreachable"
                    detail = ("no solution of this waypoint (joint limits ignored); the previous joints are kept"
                              if m.dof <= 6 else "fkopt.inverse found no solution inside the limits (restarts; no "
                              "certificate for a redundant arm); the previous joints are kept")
            else:
                out[k] = chosen
                p1, R1, _ = m.frame_jacobian1(chosen.tolist())
                errs[k] = _frame_errors(p1, R1, P[k])
                q = chosen
            found.append((int(k), reason, detail))
            k += 1
        breaks.append(found)
    joints = _public(m, J)
    pe, re = E[..., 0], E[..., 1]
    return PathResult(mechanism=m.name, names=tuple(m.joint_names), joints=joints.reshape(batch + (w, n)),
                      position_error=pe.reshape(batch + (w,)), rotation_error=re.reshape(batch + (w,)),
                      solved=((pe <= tp) & (re <= tr)).reshape(batch + (w,)),
                      breaks=breaks[0] if not batch else breaks, max_step=float(max_step), tol=(tp, tr))


def _frame_errors(p, R, row) -> tuple[float, float]:
    """(position, geodesic rotation) error of frame (p, R) against a frame row (12,)."""
    T = row[3:].reshape(3, 3)
    M = np.array(R) @ T.T
    s = 0.5 * math.sqrt((M[2, 1] - M[1, 2]) ** 2 + (M[0, 2] - M[2, 0]) ** 2 + (M[1, 0] - M[0, 1]) ** 2)
    return math.dist(p, row[:3].tolist()), math.atan2(s, 0.5 * (np.trace(M) - 1.0))


def _why(m, P, k, q, qs, so, se, f, substeps, L, lo, hi, tp, tr, max_step) -> tuple[str, str]:
    """Why waypoint k cannot be reached on the branch of q (see the module docstring)."""
    if f < substeps:
        at = so[f]
        if se[f, 0] <= tp and se[f, 1] <= tr:
            out = [m.joint_names[i] for i in range(m.dof) if not lo[i] <= at[i] <= hi[i]]
            if out:
                return "joint limit", f"the branch reaches this waypoint only with {', '.join(out)} outside its limits"
        before = so[f - 1] if f > 0 else q
        if m.dof > 6:
            # a redundant arm follows saturated at its limits: a joint held at one where the
            # branch stops converging is what stopped it
            held = [m.joint_names[i] for i in range(m.dof) if min(abs(before[i] - lo[i]), abs(before[i] - hi[i])) < 1e-9]
            if held:
                return "joint limit", (f"the branch stops converging with {', '.join(held)} held at its limit "
                                       "(the self-motion cannot absorb it)")
        sv = _smallest_singular(m, before, L)
        if sv < SINGULAR:
            return "singularity", (f"the branch stops converging next to a singular configuration "
                                   f"(smallest singular value {sv:.2g})")
        sv = min(sv, _smallest_singular(m, q, L))
        if se[f, 0] > tp or se[f, 1] > tr:
            return "singularity", (f"the branch folds back before this waypoint (no convergence along it; smallest "
                                   f"singular value {sv:.2g})")
        return "step", f"a joint moves {np.abs(at - before).max():.3g} between intermediate poses"
    big = float(np.abs(qs - q).max())
    sv = min(_smallest_singular(m, q, L), _smallest_singular(m, qs, L))
    if sv < SINGULAR:
        return "singularity", f"the branch moves {big:.3g} past a near-singular configuration (smallest singular value {sv:.2g})"
    return "step", f"the branch moves {big:.3g} between waypoints, above max_step {max_step:g}: waypoints too far apart"


def _reseat(m, row, q, tp, tr) -> np.ndarray | str | None:
    """The solution of the waypoint (frame row) nearest to q (internal units), every in-limit
    copy considered; "outside" when its solutions all lie outside the limits; None when there is
    none."""
    T = np.eye(4)
    T[:3, 3], T[:3, :3] = row[:3], row[3:].reshape(3, 3)
    tol = (max(tp, ALL_TOL[0]), max(tr, ALL_TOL[1]))
    if m.dof > 6:
        # a redundant arm: fkopt.inverse from q, then along the self-motion to the solution
        # locally nearest q (its ``start``); none found -> None
        try:
            one = inverse(m, T, start=np.clip(_public(m, q), m.bounds[:, 0], m.bounds[:, 1]), tol=tol)
        except FkoptError:
            return None
        return _internal(m, one.joints).astype(float) if bool(one.solved) else None
    try:
        got = all_solutions(m, T, tol=tol, copies=True)
    except FkoptError:
        return None
    if not len(got):
        # solutions that all lie outside the limits: the waypoint is reachable, not inside them
        return "outside" if got.search["distinct"] > got.search["unverified"] else None
    cand = _internal(m, got.solutions)
    return cand[int(np.argmin(np.abs(cand - q).max(axis=1)))].astype(float)
