"""All assembly modes: every distinct real forward solution inside the bounds.

A swarm finds *one* pose whose inverse map matches the measured inputs; a parallel mechanism
usually has several (a general 6-SPS platform up to 40, Dietmaier 1998). :func:`all_solutions`
finds them all, numerically, for any :class:`~fkopt.mechanisms.base.ParallelMechanism` with as
many inputs as pose variables:

1. **Starts** come in rounds, points of one randomly shifted Kronecker sequence
   frac(u0 + k alpha) in the unit cube (Roberts 2018; ``qmc=False``: independent uniforms),
   u0 drawn from the seeded stream (:class:`fkopt.numerics.streams.RunStreams`), mapped to the unknowns.
   A low-discrepancy sequence reaches every region of the start space at a steady rate, so the
   rarest basins (a few hits per thousand starts) are found after a less variable number of
   starts than with independent draws (measured in the commit that introduced it).
   For a 6-SPS platform a start is a rotation -- uniform on SO(3) (Shoemake's quaternions) when
   the angle bounds cover a full turn, else uniform Euler angles in the bounds widened by
   ``_ANGLE_PAD`` (0.2) of their width on each side -- and the
   position that best satisfies, in least squares, the five *linear* equations obtained by
   subtracting leg 1's equation |R q_i + t - b_i|^2 = L_i^2 from the others. Only rotations are
   sampled, so no position box has to be guessed. The widening is for solutions near a face of
   the angle box: their Newton basins reach well beyond it, and starts drawn only inside cut
   them off (near a corner of three angle bounds, to about an eighth). Measured on 6-sps-cmm
   (+-30 deg) with 600 starts, seed 0, the basin of the pose the legs came from held, at the
   1st percentile of 400 poses with every coordinate within 5 % of a bound, 1.2 % of the starts
   unwidened (0 for the worst, u = [0.625, 0.02, 0.031, 0.02, 0.023, 0.031], whose neighbour just
   outside at y = -0.20005 took half), 8.8 % widened; for poses away from the bounds the worst
   stayed at 15 % (median 38 -> 29 %). With 40 starts per pose, 2000 poses near the bounds
   missed their pose 70 times unwidened, 5 times widened; a start costs ~1.2x the Newton steps.
   For other mechanisms a start is uniform in the bounds (their basins measured to cover the
   box: 3-RPS, 3-RPUPc-UPS and 3-PPR poses on and near the bounds are hit by > 99 % of the starts,
   or by both branches' halves).
2. **Damped Newton**, vectorised over all starts of a round: for 6-SPS on the leg equations
   (|v_i|^2 - L_i^2) / (2 L_i) = 0 with the analytic Jacobian [v_i, (R q_i) x v_i] / L_i in the
   position and a rotation vector (R <- exp([w]x) R, so no Euler singularity during the
   search); for other mechanisms on ``FKProblem.residuals`` with ``FKProblem.jacobian`` (central
   differences only for a mechanism without an analytic Jacobian).
   Steps are capped (6-SPS: 2 rad of rotation and one mechanism size of translation; others:
   a quarter of the bounds width). For other mechanisms they are halved up to 8 times until the
   squared residual decreases (backtracking line search: the full step's residual and Jacobian
   in one call, the Jacobian kept when the step is taken; the halvings of the rows that need
   them in one more call). For 6-SPS every capped step is taken (plain Newton): measured on
   Dietmaier's platform over 20 seeds, a seed then needs a median of ~1260 starts to see all 40
   solutions against ~1700 with the line search (the backtracking shrinks the rarest basins),
   and an iteration costs one evaluation. A start stops when converged (then one more
   polishing step), diverged, stalled (line search) or out of ``iterations`` (60), or is
   *captured*: its residual is at most ``capture[0]`` (1e-4, relative as ``tol``) and its
   state within ``capture[1]`` (1e-3, in the dedup coordinates) of a solution already known
   -- well inside that solution's quadratic convergence region, where the remaining steps would
   only confirm it; it counts as a hit of that solution (``capture=None``: every start runs to
   convergence). At most ``pool`` (512) starts of a round iterate at once;
   a finished start is replaced by the round's next one, in order, and converged starts are
   deduplicated after every iteration, so the search stops mid-round as soon as ``maximum``
   solutions are known (the answer stays a function of the seed alone).
3. **Deduplication** with the stated tolerance ``dedup``: two converged starts are one
   solution when they differ by at most ``dedup`` in the normalised pose space -- length
   variables divided by their bounds width, angle variables in radians compared modulo 2 pi,
   and for 6-SPS the rotation compared by its matrix (max entry difference), so the Euler
   equivalences (a, b, g) ~ (a + 180, 180 - b, g + 180) ~ (a + 360 k, ...) never split a
   solution. For other mechanisms whose pose holds a Tait-Bryan triple (alpha, beta, gamma)
   the triple is first mapped to the representative with beta in [-90, 90] (valid for every
   Tait-Bryan sequence) when that representative has the same inputs.
4. **Check**: the pose of each solution is written in the mechanism's own variables (Z-Y-X
   Euler degrees for 6-SPS, angles moved into the bounds by multiples of 360 deg or by the
   Euler equivalence), its residual ``max |ik(pose) - joints|`` recomputed with the
   mechanism's inverse map; it is kept if that residual is at most ``tol * max(1, |joint|)``
   for every joint and the pose is inside the bounds (solutions found outside are counted in
   ``Solutions.outside``). A pose at most ``_BOUND_SLACK`` (1e-3 of a width) past a bound is
   clipped into the bounds and polished there by Gauss-Newton with the clipped variables held
   (a root on a bound that is double, e.g. 3-PPR at x = 60, theta = 0, converges linearly and
   stops within ``tol`` but ~1e-6 past it); it is kept if its residual is within ``tol``
   (then it is a solution in the bounds by definition), merged into a solution already found
   within ``dedup``.

Rounds continue until ``patience`` consecutive rounds bring no new solution in the bounds,
after at least ``min_starts`` (or until ``max_starts``), or until ``maximum`` distinct real
solutions are known (40 for a 6-SPS platform: no more can exist); ``starts=N`` instead runs exactly N
starts in one round. ``Solutions.history`` records (starts, seconds, solutions in the bounds)
after every round.

On Dietmaier's platform (default "6-sps" geometry and legs ``DIETMAIER_LEGS``) all 40 real
solutions are found on every seed tried, almost always within the first round of 2000 starts
(counts and times: ``bench/targets.csv`` and ``fkopt bench``, section kinematics).

**A 6-SPS platform on the compiled path** (``method="auto"``, the default, without ``starts``)
is solved instead by a parameter homotopy (:mod:`fkopt.kinematics.sps6_homotopy`): the 40
complex roots of a start system, found once per process, are tracked to the platform's, and the
real ones go through steps 3 and 4 above (those whose residual is not within ``tol`` first
through the real Newton steps of step 2). The search knows it has them all when the 40 paths
end at 40 distinct nonsingular roots, the generic number (``Solutions.certificate`` says so;
``hits`` is 1 per solution and ``starts`` the 40 paths). Where they do not (a special geometry
with fewer than 40 finite roots, e.g. 6-sps-cmm's similar hexagons, or a failed path) the
restart search above runs and ``settings["homotopy"]`` says why; its stopping rule is what
``Solutions.certificate`` then reports. ``FKOPT_NUMERICS=numpy`` runs the restart search (the
reference the homotopy is tested against).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from fkopt.errors import FkoptError
from fkopt.mechanisms.base import Mechanism, ParallelMechanism
from fkopt.mechanisms.sps6 import SixSPS
from fkopt.kinematics import sps6_homotopy
from fkopt.kinematics.assembly_search import (_cluster, _euler_triple, _into_bounds, _kronecker, _model_for, _newton,
                                             _SixSPSModel)
from fkopt.numerics.restart_loop import restart
from fkopt.numerics.streams import RunStreams
from fkopt.problems import FKProblem


@dataclass
class Solution:
    """One assembly mode: its pose (mechanism variables), residual max |ik - joints|, and how many starts found it."""

    pose: dict[str, float]
    residual: float
    hits: int

    @property
    def x(self) -> np.ndarray:
        return np.array(list(self.pose.values()))


class Solutions(list):
    """List of :class:`Solution` (most hits first) with the search's bookkeeping as attributes."""

    names: tuple[str, ...] = ()
    #: starts used, wall time (s), distinct real solutions found outside the bounds
    starts: int = 0
    time_s: float = 0.0
    outside: int = 0
    #: (starts so far, seconds so far, solutions in the bounds so far) after every round
    history: list[tuple[int, float, int]]
    #: "homotopy" or "restarts" (all_solutions' ``method``), and how the search decided it had them all
    method: str = "restarts"
    certificate: str = ""
    settings: dict[str, Any]

    def poses(self) -> np.ndarray:
        """Poses (n, dim), rows in the order of the list."""
        return np.array([s.x for s in self]).reshape(len(self), len(self.names))


def solutions_to_dict(solutions: Solutions) -> dict[str, Any]:
    """JSON-able form: ``{"solutions": [{"pose", "residual", "hits"}], "starts", "time_s", ...,
    "method", "certificate"}``."""
    return {
        "solutions": [{"pose": {k: float(v) for k, v in s.pose.items()}, "residual": float(s.residual),
                       "hits": int(s.hits)} for s in solutions],
        "starts": int(getattr(solutions, "starts", 0)),
        "time_s": float(getattr(solutions, "time_s", 0.0)),
        "outside": int(getattr(solutions, "outside", 0)),
        "history": [list(h) for h in getattr(solutions, "history", [])],
        "method": getattr(solutions, "method", "restarts"),
        "certificate": getattr(solutions, "certificate", ""),
    }


def pose_distance(mechanism: ParallelMechanism, a, b) -> np.ndarray:
    """Distance between poses ``a`` and ``b`` (..., dim) as :func:`all_solutions` dedupes them.

    Max norm in the normalised pose space: length variables divided by their bounds width,
    angles in radians modulo 2 pi (through cos and sin), and for 6-SPS the rotation compared
    by its matrix entries, so Euler-equivalent poses are at distance ~0.
    """
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    shape = a.shape[:-1]
    A, B = a.reshape(-1, a.shape[-1]), b.reshape(-1, b.shape[-1])
    model = _model_for(mechanism, np.atleast_1d(mechanism.ik(A[0])))
    ka, kb = model.keys(model.from_poses(A)), model.keys(model.from_poses(B))
    return np.abs(ka - kb).max(-1).reshape(shape)


def prepare(mechanism: Mechanism, method: str = "auto") -> None:
    """Load what :func:`all_solutions` with this ``method`` will run on ``mechanism``, so that a
    timed call does not include it: for a 6-SPS platform on the compiled path, numba's compiled
    tracker (from its cache, or compiled once) and the homotopy's start system (once per process)."""
    if isinstance(mechanism, SixSPS) and method != "restarts" and sps6_homotopy.available():
        sps6_homotopy.prepare()


def all_solutions(mechanism: ParallelMechanism, joints, *, starts: int | None = None, seed: int = 0,
                  tol: float = 1e-9, dedup: float = 1e-6, round_size: int | None = None,
                  patience: int = 1, min_starts: int | None = None, max_starts: int = 200_000,
                  iterations: int = 60, maximum: int | None = None, pool: int | None = 512,
                  line_search: bool | None = None, capture: tuple[float, float] | None = (1e-4, 1e-3), qmc: bool = True,
                  method: str = "auto") -> Solutions:
    """Every distinct real forward solution of ``mechanism`` for ``joints`` inside its bounds.

    ``starts``: run exactly this many starts (one round); by default rounds of ``round_size``
    starts (2000 for 6-SPS, 200 otherwise) run until ``patience`` consecutive rounds add no
    solution, after at least ``min_starts`` (default 2 rounds) and at most ``max_starts``.
    ``tol``: accepted residual, ``max_i |ik(pose)_i - joints_i| / max(1, |joints_i|)``.
    ``dedup``: duplicate tolerance in the normalised pose space (see the module docstring).
    ``seed``: the start stream (``RunStreams(seed, [0])``); same seed, same answer.
    ``line_search``: backtrack Newton steps until the squared residual decreases (default: yes,
    except for 6-SPS, whose plain capped Newton steps reach the rarest basins more often; see
    the module docstring). ``pool``: most starts iterated at once within a round (finished ones are replaced by the
    round's next starts, so the search can stop mid-round; None: the whole round at once).
    ``capture``: (residual, distance) under which a start is counted as a hit of a known
    solution and stopped (module docstring). ``qmc``: starts from a randomly shifted Kronecker
    sequence (default) rather than independent uniforms.
    ``maximum``: the most assembly modes the mechanism can have; the search stops as soon as
    that many distinct real solutions (inside or outside the bounds) are found, since no more
    can exist. Default 40 for a 6-SPS platform (the number of complex solutions of the general
    6-6 Stewart-Gough platform: Raghavan 1993, Ronga & Vust 1995), none otherwise.
    ``method``: "restarts" (the search above), "homotopy" (6-SPS only, on the compiled path: all
    40 complex roots by a parameter homotopy, :mod:`fkopt.kinematics.sps6_homotopy`; the real
    ones kept, certified complete when the 40 paths end at 40 distinct nonsingular roots, else
    the restart search runs and ``settings["homotopy"]`` says why) or "auto" (the homotopy for a
    6-SPS platform when the compiled path runs and ``starts`` is not given, else the restarts).
    ``Solutions.method`` and ``Solutions.certificate`` say which ran and how it decided it had
    every solution.
    """
    if not isinstance(mechanism, ParallelMechanism):
        raise FkoptError(f"all_solutions needs a parallel mechanism; '{mechanism.name}' is {mechanism.kind}")
    joints = mechanism.as_values(joints, mechanism.joint_names, "joints")
    if len(mechanism.joint_names) != len(mechanism.pose_names):
        raise FkoptError(f"all_solutions needs as many joints as pose variables; {mechanism.name} has "
                         f"{len(mechanism.joint_names)} and {len(mechanism.pose_names)}")
    for name, value in (("tol", tol), ("dedup", dedup)):
        if not value > 0:
            raise FkoptError(f"all_solutions {name}: must be positive, got {value}")
    if starts is not None and int(starts) < 1:
        raise FkoptError(f"all_solutions starts: must be at least 1, got {starts}")
    if method not in ("auto", "homotopy", "restarts"):
        raise FkoptError(f"all_solutions method: allowed values auto, homotopy, restarts; got {method!r}")
    if method == "homotopy" and not isinstance(mechanism, SixSPS):
        raise FkoptError(f"all_solutions method 'homotopy' is for a 6-SPS platform; '{mechanism.name}' is not one")
    if method == "homotopy" and not sps6_homotopy.available():
        raise FkoptError("all_solutions method 'homotopy' runs on the compiled path; it needs numba (pip install "
                         "numba) and FKOPT_NUMERICS other than numpy")

    t0 = time.perf_counter()
    model = _model_for(mechanism, joints)
    triple = (3, 4, 5) if isinstance(model, _SixSPSModel) else _euler_triple(mechanism)
    if starts is not None:
        size, limit, need = int(starts), int(starts), int(starts)
    else:
        size = int(round_size or (2000 if isinstance(model, _SixSPSModel) else 200))
        limit, need = int(max_starts), int(min_starts if min_starts is not None else 2 * size)
    streams = []                                      # RunStreams(seed, [0]), made by the first round
    cap = maximum if maximum is not None else (40 if isinstance(model, _SixSPSModel) else None)
    search = (not isinstance(model, _SixSPSModel)) if line_search is None else bool(line_search)
    jscale = np.maximum(1.0, np.abs(joints))
    ftol = 1e-3 * tol * float(jscale.min())           # Newton's own stop, well below the acceptance

    problem = FKProblem(mechanism, joints)
    rep_keys: list[np.ndarray] = []                   # one key per distinct solution found
    hits: list[int] = []
    # (pose in bounds, residual, polished onto a bound), None: outside, False: merged duplicate
    found: list[tuple[np.ndarray, float, bool] | None | bool] = []
    unchecked: list[np.ndarray] = []                  # states of new solutions not checked yet
    history: list[tuple[int, float, int]] = []
    used, quiet = 0, 0
    known = [np.empty((0, 0))]                        # rep_keys as one array, rebuilt when it grows

    def known_keys():
        if len(known[0]) != len(rep_keys):
            known[0] = np.array(rep_keys)
        return known[0]

    def add(S):
        """Deduplicate converged states S against the solutions known so far and each other."""
        good = (np.abs(model.residual(S)) / jscale <= tol).all(-1)
        S = S[good]
        if not len(S):
            return
        keys = model.keys(S)
        if hits:                                      # known solutions (mutually > dedup apart)
            dist = np.abs(keys[:, None, :] - known_keys()[None]).max(-1)
            near = dist.min(-1) <= dedup
            for i in dist[near].argmin(-1).tolist():
                hits[i] += 1
            S, keys = S[~near], keys[~near]
            if not len(S):
                return
        labels = _cluster(keys, dedup)
        for lab in range(int(labels.max()) + 1):
            members = np.flatnonzero(labels == lab)
            rep_keys.append(keys[members[0]])
            hits.append(len(members))
            unchecked.append(S[members[0]])           # checked once per round (settle)

    def settle():
        """Check the round's new solutions (pose in the bounds, residual) in one call."""
        if unchecked:
            first = len(found)
            found.extend(_check_many(mechanism, problem, model.poses(np.array(unchecked)), triple, jscale, tol))
            unchecked.clear()
            # A root polished onto a bound may be one found inside already: merge it there.
            for i in range(first, len(found)):
                if found[i] is not None and found[i][2]:
                    key = model.keys(model.from_poses(found[i][0][None]))[0]
                    for j, fj in enumerate(found):
                        if j != i and fj and np.abs(model.keys(model.from_poses(fj[0][None]))[0] - key).max() <= dedup:
                            hits[j] += hits[i]
                            found[i] = False       # a duplicate: neither a solution nor outside
                            break

    def report(rows, S):
        add(S)
        return cap is not None and len(hits) >= cap   # every assembly mode is found

    cap_f2 = (capture[0] * float(jscale.min())) ** 2 if capture else 0.0

    def captured(S, F, open_):
        """Open rows near convergence (residual <= capture[0]) within capture[1] of a known solution."""
        if not hits:
            return None
        cand = np.flatnonzero((F <= cap_f2) & open_)
        if not len(cand):
            return None
        keys, known_ = model.keys(S[cand]), known_keys()
        # the known solution nearest in the first three key coordinates (position for 6-SPS),
        # then the full distance to that one only (a row it misses just runs to convergence)
        j = np.abs(keys[:, None, :3] - known_[None, :, :3]).max(-1).argmin(-1)
        near = np.abs(keys - known_[j]).max(-1) <= capture[1]
        for i in j[near].tolist():
            hits[i] += 1
        return cand[near]

    shift = []

    def round_starts(j):
        """The next round's starts: points used .. used + n - 1 of the shifted Kronecker sequence."""
        n = min(size, limit - used)
        if not streams:
            streams.append(RunStreams(seed, [0]))
        if qmc:
            if not shift:
                shift.append(streams[0].uniform(1, model.draws)[0][0])
            return model.starts(_kronecker(shift[0], used, n, model.draws))
        return model.starts(streams[0].uniform(n, model.draws)[0])

    def run_round(S0):
        """Newton from every start of a round (pooled), then the round's new solutions checked;
        the number of solutions in the bounds after it."""
        nonlocal used, quiet
        inside_before = sum(bool(f) for f in found)
        with np.errstate(all="ignore"):                 # diverging starts may overflow
            _, _, started = _newton(model, S0, ftol=ftol, iterations=iterations, pool=pool, report=report,
                                    line_search=search, capture=captured if capture else None)
        used += started
        settle()
        inside = sum(bool(f) for f in found)
        history.append((used, time.perf_counter() - t0, inside))
        quiet = quiet + 1 if inside == inside_before else 0
        return inside

    def enough(_):
        """The stopping rule: ``patience`` quiet rounds after ``min_starts``, or every assembly mode found."""
        return (used >= need and quiet >= patience) or (cap is not None and len(found) >= cap)

    homotopy = None
    if isinstance(model, _SixSPSModel) and (method == "homotopy" or (method == "auto" and starts is None
                                                                     and sps6_homotopy.available())):
        base, platform, probe = mechanism.points()
        homotopy = sps6_homotopy.solve(base, platform - probe, joints, seed=seed)
    if homotopy is not None and homotopy["certified"]:
        # the real roots, polished by the real Newton steps (a root that is not real stays unconverged)
        S = homotopy["states"]
        rough = ~(np.abs(model.residual(S)) / jscale <= tol).all(-1)
        add(S[~rough])
        if rough.any():          # an ill-conditioned root, or one not real: the real Newton steps decide
            with np.errstate(all="ignore"):
                S, conv, _ = _newton(model, S[rough], ftol=ftol, iterations=iterations, line_search=False)
            add(S[conv])
        settle()
        used = homotopy["paths"]
        history.append((used, time.perf_counter() - t0, sum(bool(f) for f in found)))
        certificate = (f"complete: {homotopy['paths']} homotopy paths ended at {homotopy['roots']} distinct "
                       f"nonsingular complex roots, the generic number of a 6-6 platform")
    else:
        # rounds of starts through the one restart loop: a round is one start, the rule its stopping test
        restart(round_starts, run_round, enough, budget=None if limit > 0 else 0, give_up=lambda: used >= limit)
        certificate = (f"complete: {cap} distinct real solutions, the most there can be" if cap is not None
                       and len(found) >= cap else f"stopping rule: {quiet} round(s) of {size} starts without a "
                       f"new solution after {used} starts" if starts is None and quiet >= patience
                       else f"{used} starts, as asked" if starts is not None else f"max_starts ({limit}) spent")

    out = Solutions(sorted((Solution(pose=dict(zip(mechanism.pose_names, map(float, f[0]))), residual=f[1], hits=h)
                            for f, h in zip(found, hits) if f), key=lambda s: -s.hits))
    out.names = tuple(mechanism.pose_names)
    out.outside = sum(f is None for f in found)
    out.starts = used
    out.time_s = time.perf_counter() - t0
    out.history = history
    out.method = "homotopy" if homotopy is not None and homotopy["certified"] else "restarts"
    out.certificate = certificate
    out.settings = dict(seed=seed, tol=tol, dedup=dedup, round_size=size, patience=patience,
                        iterations=iterations, maximum=cap, pool=pool, line_search=search, method=out.method)
    if homotopy is not None and not homotopy["certified"]:
        out.settings["homotopy"] = homotopy["reason"]
    return out


def _check_many(mechanism, problem, X, triple, jscale, tol):
    """(pose moved into the bounds, residual, on_bound) of each converged row of X (k, dim), or
    None if it is outside or inexact; residuals in one call of the inverse map.

    A row that no move by 360 deg (or the Euler equivalence) brings into the bounds is clipped
    into them and polished there (:func:`_polish_on_bounds`), and kept (``on_bound`` True) if
    the polished pose has a residual within ``tol``: by definition a solution in the bounds.
    This is a root on a bound that Newton's stop left slightly past it (a double root converges
    linearly and stops within ``tol`` some 1e-6 beyond). A solution genuinely outside keeps a
    residual of the order of its distance to the bounds and stays outside."""
    moved = [_into_bounds(mechanism, x, triple) for x in X]
    out: list = [None] * len(X)
    inb = [i for i, xb in enumerate(moved) if xb is not None]
    if inb:
        r = np.abs(problem.residuals(np.array([moved[i] for i in inb])))
        for i, ri in zip(inb, r):
            if (ri / jscale <= tol).all():
                out[i] = (moved[i], float(ri.max()), False)
    rows, clipped = [], []
    for i, xb in enumerate(moved):
        if xb is None:
            for c in _clipped_into_bounds(mechanism, X[i], triple):
                rows.append(i)
                clipped.append(c)
    if clipped:
        C = _polish_on_bounds(mechanism, problem, np.array(clipped))
        r = np.abs(problem.residuals(C))
        for i, c, ri in zip(rows, C, r):
            if out[i] is None and (ri / jscale <= tol).all():
                out[i] = (c, float(ri.max()), True)
    return out


def _polish_on_bounds(mechanism, problem, X, steps: int = 8):
    """Gauss-Newton in the pose variables with the variables at a bound held there (rows X
    (k, dim) clipped into the bounds; a variable a step pushes out is clipped and held too)."""
    lo, hi = mechanism.bounds[:, 0], mechanism.bounds[:, 1]
    h = 1e-7 * (hi - lo)
    X = np.array(X, dtype=float)
    for _ in range(steps):
        held = (X <= lo) | (X >= hi)
        r = problem.residuals(X)
        if problem.has_jacobian:
            J = problem.jacobian(X)
        else:                                      # central differences, as _GenericModel
            E = np.eye(X.shape[1]) * h
            J = np.stack([(problem.residuals(X + e) - problem.residuals(X - e)) / (2 * hk)
                          for e, hk in zip(E, h)], axis=-1)
        J = np.where(held[:, None, :], 0.0, J)
        with np.errstate(all="ignore"):
            dx = -np.einsum("nij,nj->ni", np.linalg.pinv(J), r)
        if not np.isfinite(dx).all():
            break
        X = np.clip(X + dx, lo, hi)
        if (np.abs(dx) <= 1e-15 * (hi - lo)).all():
            break
    return X


#: How far past a bound (fraction of its width) a converged pose is clipped and polished back:
#: a double root stops ~1e-8 of the width past it, a triple one ~1e-4 (the pose error of a
#: k-fold root is ~ (Newton's stopping residual)^(1/k)); farther is a solution outside.
_BOUND_SLACK = 1e-3


def _clipped_into_bounds(mechanism: Mechanism, x: np.ndarray, triple) -> list[np.ndarray]:
    """The pose x clipped into the bounds, once per Euler representative (plain, then the
    equivalent triple), each angle first moved by multiples of 360 deg next to the bounds;
    representatives more than ``_BOUND_SLACK`` of a width outside are left out."""
    lo, hi = mechanism.bounds[:, 0], mechanism.bounds[:, 1]
    angle = np.flatnonzero(mechanism.angle_mask(mechanism.pose_units))
    x = np.array(x, dtype=float)
    candidates = [x]
    if triple is not None:
        a, b, g = triple
        alt = x.copy()
        alt[a] += 180.0
        alt[b] = 180.0 - alt[b]
        alt[g] += 180.0
        candidates.append(alt)
    out = []
    for c in candidates:
        c = c.copy()
        for i in angle:
            v = lo[i] + (c[i] - lo[i]) % 360.0           # smallest representative >= lo
            c[i] = v if v - hi[i] <= lo[i] - (v - 360.0) else v - 360.0   # the nearer side
        inside = np.clip(c, lo, hi)
        if (np.abs(inside - c) <= _BOUND_SLACK * (hi - lo)).all():
            out.append(inside)
    return out
