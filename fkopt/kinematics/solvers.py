"""Practical exact solvers: ``fkopt.forward`` (parallel mechanisms) and ``fkopt.inverse`` (serial arms).

:func:`fkopt.solve` is the optimiser-level API (runs, populations, convergence histories) used
to compare algorithms. These two functions are the domain-level API: give joints (or poses),
batched over any leading axes, get poses (or joints) back with a verdict per row.

Both run their starts through the one restart loop, :mod:`fkopt.numerics.restart_loop` (forward's
rows side by side: :func:`~fkopt.numerics.restart_loop.restart_rows`; inverse's one-pose candidates:
:func:`~fkopt.numerics.restart_loop.restart`, compiled in :mod:`fkopt.numerics.compiled_ik`).
The pieces live beside this module: the argument checks (:mod:`.inputs`), the results
(:mod:`.results`), the start tables (:mod:`.start_tables`), forward's Newton step
(:mod:`.forward_newton`), inverse's one-pose and batched loops (:mod:`.inverse_pose`,
:mod:`.inverse_batch`).

**forward(mechanism, joints[..., m])** -- the pose whose closed-form inverse map gives ``joints``.

1. Local stage, vectorised over all rows (no per-row Python loop): damped Newton on
   r(x) = ik(x) - joints with the mechanism's analytic Jacobian (``ik_jacobian``; central
   differences for a mechanism without one), from ``start`` or the centre of the bounds. A step
   that does not decrease |r|^2 is halved (up to 10 times); steps are capped at a quarter of the
   box width per coordinate. At most 30 iterations. A single row takes the same iteration with
   scalar tests (its cost is numpy's per-call overhead), on Python floats throughout when the
   mechanism has ``ik_jacobian1`` (6-SPS: the same formulas per leg) and a 6x6 Gaussian
   elimination with partial pivoting.
2. Rows not solved restart the same Newton from a start table's poses nearest in joint space
   (as inverse's table, turned round for a parallel mechanism: ``table`` poses drawn uniformly in
   the bounds by a fixed hash, their joints by the closed-form inverse map, compared by the joints
   each divided by its spread over the table, nearest found exactly as inverse's (brute force
   below 32 rows, scipy's k-d tree from 32 on); :func:`_forward_table`, built once per mechanism
   geometry). A row takes ``neighbours`` of them, nearest first: the first ``candidates`` all
   run and the row keeps the likeliest of their solutions, the one with the smallest Jacobian
   volume (for a pose drawn uniformly in the bounds, mode i generated the joints with
   probability proportional to 1 / |det J(x_i)|, :func:`_jacobian_volume`); when none of them
   solves, the rest one after another until one does. Then a few deterministic starts: the centre
   moved by +-1/4 of the box width along each coordinate (2 n starts), all rows at once.
   Rows the start solves have the same answers with or without the table (``table=0`` is the
   solver before it); what the table buys on Dietmaier's platform is measured in
   docs/performance.md and docs/python-api.md.
3. Rows still not solved go to a seeded global search, one row at a time: ``gabc+lm``
   (population 20, 300 iterations, seed ``seed``, run id = row index) through :func:`fkopt.solve`.

**inverse(arm, poses[..., 6])** -- joints whose end-effector pose is ``poses`` (x, y, z in the
arm's length unit, Z-Y-Z Euler angles in degrees as :meth:`DHArm.fk` prints them), every joint
inside its limits, for any frame arm (DH tables and URDF chains alike: the solver uses the arm's
frame, frame Jacobian and periodic joints only). Internally angles are in radians and lengths
(prismatic joints) in the arm's unit; continuous (periodic) joints are not saturated and the
answer is wrapped into [-180, 180). ``mask`` selects task components (position only, ...);
``start`` as the current joints gives the locally nearest solution (see :func:`inverse`).
A bounded damped least-squares method on the 6 residuals (position error, L * rotation vector
of R R_t^T with L = ``orientation_scale`` length units per radian, default the arm's reach; the
geodesic orientation error, no Euler differences):

* step d = J^T (J J^T + mu I)^{-1} (-r) (minimum-norm damped least squares for a redundant
  arm), mu = lambda * trace(J J^T) / 6 with lambda adapted per candidate as in
  Levenberg-Marquardt (start ``damping`` = 5e-4, x ``down`` = 0.1 after a step that decreases
  |r|^2, x ``up`` = 10 otherwise; 5e-4 rather than 1e-2 since issue 38: 16 % fewer evaluations
  per pose over 14 arms, as many solved, docs/performance.md); the joint step is capped at ``step_cap`` radians; a
  candidate whose |r|^2 did not fall below ``stall`` (0.5) times its value two evaluations before
  gives way to the next start (the stall test; 0: off; a row's last start runs to its end), else
  it ends after ``iterations`` (20) steps (10 before the stall test, which ends the stuck
  candidates the cap had ended: 20 leaves fewer poses unsolved, docs/performance.md); the
  orientation rows use the angular velocity (the derivative of the rotation vector at zero
  error; ``exact_rotation=True`` applies the inverse left Jacobian of SO(3) -- measured: the
  same number of Jacobian evaluations on 1000 random poses, so the cheaper one is the default);
* joint limits handled by the method (saturation in the null space, as in Flacco, De Luca,
  Khatib 2012, "Motion control of redundant robots under joint constraints: saturation in the
  null space"): a joint whose step would leave its range is fixed at the limit, its column
  removed, and the remaining joints re-solved for the residual left over (up to 3 passes) -- the
  redundancy absorbs the saturation instead of the step being clipped;
* optional secondary objective in the null space of the task, ``rest`` > 0: pull every joint
  towards mid-range, d += (I - J^+ J) z with z = g rest (mid - q) / half-range^2, J^+ the
  pseudo-inverse (damped by 1e-9 trace(J J^T) / 6) and g = min(1, |r|) fading the pull below
  1 length unit of residual, so that a finite null-space step does not keep the task from
  converging (off by default);
* starts from a table: ``table`` (4096) joint configurations drawn uniformly inside the limits
  by a fixed hash (not the seed), compared by their tool position and reach / (3 sqrt 2) times
  their rotation matrix entries (1 rad weighs about a third of the reach), nearest found
  exactly (brute force below 32 rows, scipy's k-d tree from 32 rows on); a row's starts are ``start`` (when given), then the table's configurations nearest to
  its target (``starts`` of them plus ``neighbours`` (32) more for restarts), then seeded random draws
  inside the limits from a counter-based hash of (seed, row index, draw number). Measured on
  1000 random reachable poses: about 80 % of nearest-configuration starts converge against
  about 60 % of mid-range or random ones, which is why the hardest rows of a batch try 32 table
  neighbours before the random draws (measured in the commit that chose it; docs/performance.md);
* one pose (N = 1, ``rest`` = 0, no ``exact_rotation``) runs the same iteration on Python
  floats (the arm's ``frame_jacobian1``, Cholesky solves of the 6x6 systems), its candidates
  one after another in the order of its starts, stopping at the first that converges: numpy's
  per-call overhead is most of the cost of the batched loop on a few rows;
* restarts: a candidate that has not converged after ``iterations`` (10) steps, or stalls
  (lambda above 1e6), restarts in place from its row's next start, at most ``restarts`` times
  per row; a solved row retires all its candidates at once. A batch of N < ``fill`` (32) rows
  starts with ``fill // N`` candidates per row side by side, and whenever fewer than ``tail``
  (256) candidates remain, every unsolved row gets more at once (the last hard rows then try
  many starts per iteration instead of a few per iteration for many iterations: in a batch
  the time of the last iterations is numpy's per-call overhead, whatever their few rows). These restarts are inverse's global
  stage (restarts of a local method with limits, rather than a swarm). Same poses and seed give
  the same answer; a row's answer may differ between batches.

**Verdicts.** ``solved`` is true only when the closed form of the answer reproduces the input
within ``tol`` and the answer is inside the bounds: forward, max |ik(pose) - joints| <= ``tol``
(joint units; default 1e-9) and the pose inside ``mechanism.bounds`` (angles may be moved by
multiples of 360 deg); any assembly mode that does so is a solution. The residual is the one
the Newton loop evaluated at the answer with ``ik_jacobian`` (the same closed form; a row whose
angles were moved into the bounds is evaluated again with ``ik``). Inverse, distance between
fk(joints) and the target position <= ``tol[0]`` (length unit; default 1e-6) and geodesic angle
<= ``tol[1]`` (radians; default 1e-6), every joint inside its limits, evaluated with the arm's
elementwise :meth:`DHArm.frame` (the numbers of ``fk``; for a single pose the same DH
recursion on Python floats, :meth:`DHArm.frame_jacobian1`, equal to ~1e-13), not with the
solver's products.

**Evaluations** are counted per row and separately: ``evaluations["residual"]`` counts
evaluations of the closed form (the inverse map for forward, the arm's forward map for inverse),
``evaluations["jacobian"]`` evaluations of its analytic Jacobian (each also yields the closed
form at the same point: one call of ``ik_jacobian``/``frame_jacobian`` counts one of each). A
mechanism without analytic Jacobian is differentiated by central differences, counted as
2 n residual evaluations and no Jacobian evaluation. The global stage of forward adds
:attr:`fkopt.Result.evaluations` of its run (swarm fitness evaluations plus LM's, an analytic
Jacobian counted as one) to ``residual``.
"""
from __future__ import annotations

import math

import numpy as np

from fkopt.algorithms.hybrid import GABCLM
from fkopt.algorithms.runs import solve
from fkopt.api_bounds import MAX_SEED, check_integer, check_options
from fkopt.errors import FkoptError
from fkopt.kinematics.forward_newton import (_jacobian_volume, _newton, _newton1, _newton_scalar, _Residuals,
                                             _verify)
from fkopt.kinematics.inputs import (_internal, _inverse_arm, _mechanism, _targets, _task_mask, _tolerance,
                                     _unreachable, _values)
from fkopt.kinematics.inverse_batch import inverse_batch
from fkopt.kinematics.inverse_pose import _fast_context, _fast_result, _inverse_one
from fkopt.kinematics.results import FORWARD_TOL, INVERSE_TOL, ForwardResult, InverseResult
from fkopt.kinematics.start_tables import _TABLES, _forward_table, _joint_features, _nearest, _sumsq  # noqa: F401
from fkopt.mechanisms.base import ParallelMechanism
from fkopt.numerics import path as numerics_path
from fkopt.numerics.options import InverseOptions
from fkopt.numerics.restart_loop import restart_rows
from fkopt.problems import fk_problem

#: The swarm budget of one pose: fkopt.forward's global stage (gabc+lm) and a forward solve by a
#: named algorithm (:func:`fkopt.kinematics.by_algorithm.forward_by`, ``fkopt fk --algorithm``).
FORWARD_SWARM = {"population": 20, "iterations": 300}

#: forward's start table: poses of the bounds and their joints (see :func:`forward`).
FORWARD_TABLE = 4096

#: Start-table poses nearest to the joints that a row not solved from its start tries.
FORWARD_NEIGHBOURS = 16

#: Of those, how many all run before a row keeps the likeliest of their solutions.
FORWARD_CANDIDATES = 8

#: The budget of one IK pose by a named algorithm (:func:`fkopt.kinematics.by_algorithm.inverse_by`).
INVERSE_SWARM = {"population": 50, "iterations": 500}


def forward(mechanism, joints, *, start=None, tol: float = FORWARD_TOL, seed: int = 0,
            global_search: bool = True, table: int = FORWARD_TABLE,
            neighbours: int = FORWARD_NEIGHBOURS, candidates: int = FORWARD_CANDIDATES) -> ForwardResult:
    """Forward kinematics of a parallel mechanism for joints (..., m), batched over leading axes.

    ``mechanism``: a registered name or a :class:`ParallelMechanism`. ``start``: start pose(s)
    (n,) or (..., n) (default: centre of the bounds). ``tol``: largest accepted
    max |ik(pose) - joints|, joint units. ``seed``: the global stage's seed.
    ``global_search=False`` stops after the deterministic starts. ``table``: size of the start
    table (poses of the bounds and their joints, :func:`_forward_table`; 0: none, the behaviour
    before it); ``neighbours``: how many of its poses nearest to the joints a row not solved from
    ``start`` tries before the deterministic restarts; ``candidates``: how many of those (nearest
    first) all run, the row keeping the likeliest of their solutions (smallest Jacobian volume,
    :func:`_jacobian_volume`; 1: the first that solves). See the module docstring.
    """
    m = _mechanism(mechanism, ParallelMechanism, "forward")
    opts = check_options("forward", tol=tol, seed=seed, table=table, neighbours=neighbours, candidates=candidates)
    tol, seed, table, neighbours, candidates = (opts[k] for k in ("tol", "seed", "table", "neighbours", "candidates"))
    J0 = _values(m, joints, m.joint_names, "joints")
    shape = J0.shape[:-1]
    L = J0.reshape(-1, J0.shape[-1])
    N, n = len(L), len(m.pose_names)
    bounds = m.bounds
    centre = bounds.mean(axis=1)
    if start is None:
        x0 = np.broadcast_to(centre, (N, n))
    else:
        s = _values(m, start, m.pose_names, "start")
        x0 = np.broadcast_to(s, shape + (n,)).reshape(N, n)
    res = _Residuals(m, L)
    evals = (np.zeros(N, dtype=np.int64), np.zeros(N, dtype=np.int64))
    ftol = 0.01 * tol
    all_rows = np.arange(N)
    scalar = N == 1 and hasattr(m, "ik_jacobian1") and not res.angle.any()

    def local(s0, rows):
        """Newton from starts s0 on rows of L (scalar, one row or a batch), verified."""
        got = _newton_scalar(m, s0[0], L[rows[0]], ftol, evals) if scalar else None
        if got is not None:
            xs, rs = got
        elif N == 1:
            xs, rs = _newton1(res, np.array(s0[0], dtype=float), ftol, evals)
        else:
            xs, rs = _newton(res, s0, rows, ftol, evals)
        return _verify(m, L[rows], xs, rs, tol)

    x, resid = np.empty((N, n)), np.empty(N)
    solved, stage = np.zeros(N, dtype=bool), np.full(N, -1)
    outer = np.geterr()                                # the global search runs under the caller's settings
    quarter = 0.25 * (bounds[:, 1] - bounds[:, 0])
    fixed_starts = np.concatenate([centre + np.diag(quarter), centre - np.diag(quarter)])
    near: dict = {}                                    # the start table's nearest poses, made at start 1

    def search(j, rows):
        """Start j of every row in ``rows`` (not solved yet); the mask of the rows it solved (done).
        Start 0: ``start`` (or the centre); 1 .. k: the start table's k poses nearest in joint
        space, the first ``candidates`` of which all run (a row keeps the likeliest solution
        among them: smallest Jacobian volume), the rest until one solves; then the 2 n
        deterministic starts; then the seeded global search."""
        if j == 0:
            xs, rs, ok = local(x0, rows)
            x[:], resid[:], solved[:] = xs, rs, ok
            stage[ok] = 0
            return ok
        if j == 1:
            k = 0
            if table and neighbours:
                tab = _forward_table(m, int(table))
                k = min(int(neighbours), len(tab["pose"]))     # 0 when no table pose had finite joints
                near["pose"], near["rows"] = tab["pose"], np.zeros((N, k), np.intp)
                if k:
                    near["rows"][rows] = _nearest(tab, _joint_features(tab, L[rows]), k)
            near["k"], near["first"] = k, min(max(int(candidates), 1), k)
            near["kept"] = np.full(N, np.inf)                   # the kept solution's Jacobian volume
        t, k, first = j - 1, near["k"], near["first"]
        if t < k:
            xs, rs, ok = local(near["pose"][near["rows"][rows, t]], rows)
            if t < first:                              # all run; a row keeps its likeliest solution
                vol = np.full(len(rows), np.inf)
                if ok.any():
                    vol[ok] = _jacobian_volume(res, xs[ok], rows[ok], evals)
                take = ok & (vol < near["kept"][rows])          # ties: the nearer start's
                take |= ~solved[rows] & ~ok & (rs < resid[rows])
                near["kept"][rows] = np.where(take & ok, vol, near["kept"][rows])
            else:                                      # one after another until one solves
                take = ok | (rs < resid[rows])
            x[rows[take]], resid[rows[take]] = xs[take], rs[take]
            solved[rows[ok]] = True
            stage[rows[ok]] = 1
            if t < first:
                return solved[rows] if t == first - 1 else np.zeros(len(rows), dtype=bool)
            return ok
        d = t - k
        if d < len(fixed_starts):                      # deterministic restarts
            xs, rs = _newton(res, np.broadcast_to(fixed_starts[d], (len(rows), n)), rows, ftol, evals)
            xs, rs, ok = _verify(m, L[rows], xs, rs, tol)
            better = ok | (~solved[rows] & (rs < resid[rows]))
            x[rows[better]], resid[rows[better]] = xs[better], rs[better]
            solved[rows[ok]] = True
            stage[rows[ok]] = 1
            return ok
        if d > len(fixed_starts) or not global_search:
            return None
        with np.errstate(**outer):                     # the global search, one row at a time
            for r in rows:
                problem = fk_problem(m, L[r])
                out = solve(problem, GABCLM(), **FORWARD_SWARM, runs=1, seed=seed, run_ids=[int(r)])
                evals[0][r] += int(out.evaluations[0])
                xs = out.x[:1]
                rs = np.abs(problem.residuals(xs)).max(axis=-1)
                xs, rs, ok = _verify(m, L[r:r + 1], xs, rs, tol)
                if ok[0] or rs[0] < resid[r]:
                    x[r], resid[r] = xs[0], rs[0]
                if ok[0]:
                    solved[r], stage[r] = True, 2
        return solved[rows]

    with np.errstate(all="ignore"):
        restart_rows(all_rows, search)
    return ForwardResult(
        mechanism=m.name, names=tuple(m.pose_names), units=tuple(m.pose_units),
        pose=x.reshape(shape + (n,)), residual=resid.reshape(shape), solved=solved.reshape(shape),
        stage=stage.reshape(shape),
        evaluations={"residual": evals[0].reshape(shape), "jacobian": evals[1].reshape(shape)},
        tol=float(tol))


class InverseSolver:
    """:func:`inverse` prepared for one arm, one :class:`fkopt.numerics.InverseOptions`, one
    tolerance and one task mask: for a control loop that asks for one pose per tick.

    ``solver = fkopt.InverseSolver(arm, options, tol=..., mask=...)`` does the per-arm and
    per-option set-up once -- the options validated, the chain as arrays, the start table
    (``options.table`` FK evaluations) and its features, the limits in internal units, the
    compiled kernel's argument list -- and ``solver(target, seed=..., start=...)`` goes from the
    target straight to the compiled one-pose loop (:func:`fkopt.numerics.compiled_ik.inverse_pose`).
    Per call it checks only the target (shape, finite, an orthonormal frame, within reach) and
    ``seed``. Its answers are :func:`inverse`'s bit for bit: ``inverse`` itself runs every one-pose
    call through a solver like this one (cached per arm, options, tol and mask), and sends
    batches and the options without a one-pose loop (``rest`` > 0, ``exact_rotation``) to its
    batched loop, as the solver does.

    ``target``: a tip frame (4, 4) in the base frame (cheapest: no Euler angles), or a pose (6,)
    as ``arm.fk`` gives it; a batch (..., 4, 4) / (..., 6) goes to :func:`inverse`'s batched loop.
    ``seed``: the restarts' stream (an int). ``start``: the current joints (deg), as in
    :func:`inverse` (the given start first, then the self-motion step on a redundant arm).

    The solver reads the arm's limits when it is made; if ``arm.bounds`` changes later it
    prepares again on the next call (one byte comparison per call keeps that honest)."""

    __slots__ = ("arm", "options", "tol", "mask", "_W", "_bounds", "_fast", "_one_pose", "_budget", "_table",
                 "_kn", "_L", "_kernel", "_reach")

    def __init__(self, arm, options: InverseOptions | None = None, *, tol=INVERSE_TOL, mask=None):
        self.arm = m = _inverse_arm(arm)
        if options is None:
            options = InverseOptions()
        elif not isinstance(options, InverseOptions):
            raise FkoptError(f"InverseSolver options: expected fkopt.numerics.InverseOptions, "
                             f"got {type(options).__name__}")
        self.options = options.validated()
        self.tol = _tolerance(tol)
        self.mask = mask
        self._W = _task_mask(mask)
        self._prepare()

    def _prepare(self) -> None:
        """Everything that depends on the arm's limits and the options, once."""
        m, o = self.arm, self.options
        self._bounds = m.bounds.tobytes()
        self._reach = float(m.reach)
        self._one_pose = o.rest <= 0 and not o.exact_rotation
        first = max(1, int(o.starts), o.fill)
        self._budget = first + max(0, int(o.restarts))
        self._table = int(o.table)
        # neighbours per pose: without / with a start (own0 = 1 when a start is given or there is no table)
        self._kn = (first - (0 if self._table else 1) + int(o.neighbours), first - 1 + int(o.neighbours))
        self._L = float(o.orientation_scale) if o.orientation_scale else m.reach
        self._fast = fast = numerics_path.compiled_ik(o.compiled) if hasattr(m, "chain") else None
        self._kernel = None
        if fast is not None and self._one_pose:
            ctx = _fast_context(m, self._table, self._W)
            nn = min(self._table, self._kn[0]) if self._table else 0
            self._kernel = fast.bound_inverse_pose(ctx, float(self._L), ctx["W"], ctx["mid"], 0 if self._table else 1,
                                                   nn, self._budget, self.tol, int(o.iterations), float(o.damping),
                                                   float(o.down), float(o.up), float(o.step_cap), float(o.stall))

    def __repr__(self) -> str:
        return f"InverseSolver({self.arm.name!r}, {self.options!r}, tol={self.tol!r}, mask={self.mask!r})"

    def __call__(self, target, *, seed: int = 0, start=None) -> InverseResult:
        if self.arm.bounds.tobytes() != self._bounds:
            self._prepare()
        P0 = _targets(self.arm, target)
        if P0.ndim == 1 and self._one_pose:
            return self._one(P0, start, seed)
        return inverse(self.arm, target, start=start, tol=self.tol, mask=self.mask, seed=seed, options=self.options)

    def _one(self, pose: np.ndarray, start, seed) -> InverseResult:
        """One checked target row (6,) or (12,): the compiled kernel straight away when there is no
        start (the common call), else :func:`_inverse_one` with the prepared options."""
        if type(seed) is not int or not 0 <= seed <= MAX_SEED:
            seed = check_integer("seed", seed, "inverse")
        if self._kernel is not None and start is None:
            if not pose.flags.c_contiguous:         # a strided view would compile another specialisation
                pose = np.ascontiguousarray(pose)
            x, y, z = pose[0], pose[1], pose[2]
            dist = math.sqrt(x * x + y * y + z * z)
            if dist > self._reach * (1.0 + 1e-12):
                raise _unreachable(self.arm, x, y, z, dist)
            return _fast_result(self.arm, self._kernel(pose, seed), *self.tol)
        o = self.options
        return _inverse_one(self.arm, pose, start, self.tol, seed, self._budget, self._table,
                            self._kn[0 if start is None else 1], o.orientation_scale, o.iterations, o.damping, o.down,
                            o.up, o.step_cap, o.stall, self._W, o.compiled)


def inverse_solver(arm, *, tol=INVERSE_TOL, mask=None, **options) -> InverseSolver:
    """:class:`InverseSolver` from :func:`inverse`'s keyword options (``restarts=50``, ...)."""
    try:
        o = InverseOptions(**options)
    except TypeError:
        allowed = ", ".join(InverseOptions.__dataclass_fields__)
        raise FkoptError(f"inverse_solver: unknown option among {sorted(options)}; allowed: {allowed}") from None
    return InverseSolver(arm, o, tol=tol, mask=mask)


#: Prepared solvers kept per arm by :func:`inverse` (the oldest dropped beyond this many).
_SOLVERS_PER_ARM = 16


def _solver_for(m, options, tol: tuple[float, float], W) -> InverseSolver:
    """The :class:`InverseSolver` :func:`inverse` runs one pose through, cached on the arm by
    (options, tol, mask, numerics mode): ``FKOPT_NUMERICS`` may change between calls. ``options``:
    an :class:`InverseOptions`, or its field values in order as a tuple (inverse's keywords: the
    options object is made only when the solver is)."""
    key = (options, tol, None if W is None else W.tobytes(), numerics_path.requested())
    cache = m.__dict__.get("_inverse_solvers")
    if cache is None:
        cache = m.__dict__["_inverse_solvers"] = {}
    got = cache.get(key)
    if got is None:
        if len(cache) >= _SOLVERS_PER_ARM:
            cache.pop(next(iter(cache)))
        if not isinstance(options, InverseOptions):
            options = InverseOptions(*options)
        got = cache[key] = InverseSolver(m, options, tol=tol, mask=None if W is None else W)
    elif got._bounds != m.bounds.tobytes():
        got._prepare()
    return got


def inverse(arm, poses, *, start=None, tol=INVERSE_TOL, mask=None, seed: int = 0, restarts: int = 200,
            starts: int = 1, rest: float = 0.0, orientation_scale: float | None = None,
            iterations: int = 20, damping: float = 5e-4, step_cap: float = 2.0,
            down: float = 0.1, up: float = 10.0, stall: float = 0.5, fill: int = 32, exact_rotation: bool = False,
            table: int = 4096, neighbours: int = 32, tail: int = 256, compiled: bool | None = None,
            threads: int | None = None, options=None) -> InverseResult:
    """Inverse kinematics of a serial arm for poses (..., 6), batched over leading axes.

    ``arm``: a registered name or a frame arm (:class:`fkopt.mechanisms.base.FrameArm`: DH and
    URDF arms, through ``frame``, ``frame_jacobian``, ``frame_jacobian1``, ``kinematic_key`` and
    ``periodic_mask`` only). ``poses``: x, y, z (length unit of the arm) and Z-Y-Z Euler angles
    (deg), as ``arm.fk`` returns them; or tip frames (..., 4, 4) in the base frame, as
    ``arm.fk_matrix`` returns them, whose rotation is used as given (no Euler angles: no digits
    lost near their singularity at sin(beta) = 0, no conversion per call). ``start``: the current joints (n,) or (..., n) inside the
    limits (default mid-range): the first candidate begins there; when it is solved and the arm
    has self-motion (more than 6 joints, or a ``mask``), the answer is then moved along the
    self-motion to the solution locally nearest to ``start`` (Euclidean distance in rad and
    length units, continuous joints by their wrapped difference; :func:`_toward_start`). Nearest
    is local: another branch of solutions may hold a nearer one.
    ``tol``: (position, orientation in radians). ``mask``: the task components that count, 6
    flags over (x, y, z, rx, ry, rz) -- position and rotation-vector error in the base frame,
    as roboticstoolbox's ``we`` -- or their names (``"x,y,z"``: position only, for arms with
    fewer than 6 joints); the errors reported are those of the selected components. ``seed``:
    the restarts' stream. ``starts``:
    candidates solved side by side per row (the start and ``starts - 1`` random ones);
    ``restarts``: most random restarts per row. ``rest``: gain of the null-space pull towards
    mid-range (0: off). ``orientation_scale``: length units per radian weighing orientation
    against position in the least squares (default the arm's reach). ``iterations``: per
    candidate before it restarts. ``damping``, ``down``, ``up``: lambda's start and factors;
    ``stall``: the stall test's ratio (0 to 1; 0: off), see the module docstring. ``table``: size of the start table (0: no table, starts at
    ``start`` or mid-range, then random); ``neighbours``: table configurations kept per row for
    restarts beyond its first starts; ``fill`` / ``tail``: candidates side by side for small
    batches / when few remain. ``compiled``: one pose through the compiled loop
    (:mod:`fkopt.numerics.compiled`; None: when numba is there and ``FKOPT_NUMERICS`` is not
    ``numpy``; same answers as the Python loop). ``threads``: threads sharing a batch's rows on the
    compiled path, 1 to 256 (None: the CPUs this process may run on; 1: the calling thread alone;
    batches under 64 rows run on it anyway); every row's answer is the same for any number.
    ``options``: an
    :class:`fkopt.numerics.InverseOptions` holding all of the above at once (it replaces the
    keywords). See the module docstring.
    """
    if options is not None:
        o = options.as_dict()
        restarts, starts, rest, orientation_scale = o["restarts"], o["starts"], o["rest"], o["orientation_scale"]
        iterations, damping, step_cap, down, up = o["iterations"], o["damping"], o["step_cap"], o["down"], o["up"]
        stall = o["stall"]
        fill, exact_rotation, table, neighbours = o["fill"], o["exact_rotation"], o["table"], o["neighbours"]
        tail, compiled, threads = o["tail"], o["compiled"], o["threads"]
    m = _inverse_arm(arm)
    tp, tr = _tolerance(tol)
    seed = check_integer("seed", seed, "inverse")
    P0 = _targets(m, poses)
    if P0.ndim == 1 and rest <= 0 and not exact_rotation:
        # one pose: through the prepared solver (cached per arm, options, tol and mask), the one code path
        o = options if options is not None else (restarts, starts, rest, orientation_scale, iterations, damping,
                                                 step_cap, down, up, stall, fill, exact_rotation, table, neighbours, tail,
                                                 compiled, threads)
        return _solver_for(m, o, (tp, tr), _task_mask(mask))._one(P0, start, seed)
    if options is None:                                # the same checks as a one-pose call's solver
        InverseOptions(restarts, starts, rest, orientation_scale, iterations, damping, step_cap, down, up, stall, fill,
                       exact_rotation, table, neighbours, tail, compiled, threads).validated()
    else:
        options.validated()
    shape = P0.shape[:-1]
    P = P0.reshape(-1, P0.shape[-1])
    N, n = len(P), m.dof
    reach = m.reach
    dist = np.sqrt(_sumsq(P[:, :3]))
    far = dist > reach * (1.0 + 1e-12)
    if far.any():
        k = int(np.flatnonzero(far)[0])
        raise _unreachable(m, P[k, 0], P[k, 1], P[k, 2], dist[k])
    lo, hi = _internal(m, m.bounds[:, 0]), _internal(m, m.bounds[:, 1])
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    # saturation bounds: none for periodic (continuous) joints, wrapped at the end
    periodic = m.periodic_mask()
    slo, shi = (np.where(periodic, -np.inf, lo), np.where(periodic, np.inf, hi)) if periodic.any() else (lo, hi)
    W = _task_mask(mask)
    if start is None:
        q0 = np.broadcast_to(mid, (N, n))
    else:
        s = _values(m, start, m.joint_names, "start")
        q0 = np.broadcast_to(s, shape + (n,)).reshape(N, n)
        if not m.in_bounds(q0).all():
            box = ", ".join(f"{a} [{b[0]:g}, {b[1]:g}]" for a, b in zip(m.joint_names, m.bounds.tolist()))
            raise FkoptError(f"{m.name} start: joints must be inside the limits ({box})")
        q0 = _internal(m, q0)
    return inverse_batch(m, P, shape, q0, start, W, (tp, tr), seed, lo, hi, mid, half, periodic, slo, shi,
                         restarts=restarts, starts=starts, rest=rest, orientation_scale=orientation_scale,
                         iterations=iterations, damping=damping, step_cap=step_cap, down=down, up=up, stall=stall,
                         fill=fill,
                         exact_rotation=exact_rotation, table=table, neighbours=neighbours, tail=tail,
                         compiled=compiled, threads=threads)
