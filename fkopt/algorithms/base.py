"""The algorithm protocol and the shared iteration loop.

An algorithm implements two methods on its own typed :class:`State` (a dataclass) holding
arrays shaped (runs, population, dim):

* ``initialize(problem, population, streams, x0, iterations)`` sets ``state.x`` (the algorithm's memory:
  ABC food sources, PSO personal bests, ant positions ...), ``state.f`` (their fitness) and
  ``state.evaluations`` (fitness evaluations so far, per run);
* ``iterate(state, problem, streams)`` advances every run by one iteration of the method.

:meth:`Algorithm.minimize` owns everything else, identically for every algorithm: the
best-so-far point and fitness per run, the history arrays (runs x (iterations + 1)), counting
evaluations, stopping at a target, snapshots of the population. All runs advance together; a
run that reached the target (with ``stop_at_target``) is frozen in the records from that
iteration on, so its numbers do not depend on the other runs of the batch.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any, ClassVar

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationError, field_validator

from fkopt.errors import FkoptError
from fkopt.files import did_you_mean, field_path, no_quoted_numbers
from fkopt.numerics import path as numerics_path
from fkopt.progress import heard, tick
from fkopt.numerics.streams import RunStreams

#: Ticks per run of the iteration loop that a progress listener hears at least, when the compiled
#: path runs many iterations per call (a bar that jumps from 0 to done says nothing).
TICKS = 20


class Params(BaseModel):
    """Base of every algorithm's parameter model (unknown keys are rejected)."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    #: ``limit: "3"`` is refused, not read as 3 (fkopt.files.no_quoted_numbers)
    _numbers = field_validator("*", mode="before")(no_quoted_numbers)


@dataclass(eq=False, kw_only=True)
class State:
    """What every algorithm's state holds; each algorithm subclasses it with its own fields
    (:class:`fkopt.algorithms.abc.ABCState`, ``PSOState``, ...), evosax-style.

    ``x``/``f`` are the algorithm's memory (runs, population, dim) / (runs, population) that
    :meth:`Algorithm.update_best` reads, ``evaluations`` the count per run; ``best_x``/``best_f``
    the best-so-far per run, kept by :meth:`Algorithm.minimize`.
    """

    x: np.ndarray
    f: np.ndarray
    evaluations: np.ndarray | None = None
    best_x: np.ndarray | None = None
    best_f: np.ndarray | None = None
    log: "EvaluationLog | None" = None   # set by Algorithm.minimize: see evaluated()
    # a compiled iteration already folded x/f into best_x/best_f (Algorithm.update_best's rule)
    best_folded: bool = False


@dataclass
class RunRecord:
    """What one batch of runs produced (before timing is attached by :func:`fkopt.solve`)."""

    best_x: np.ndarray                 # (runs, dim)
    best_f: np.ndarray                 # (runs,)
    history: np.ndarray                # (runs, iterations + 1) best-so-far fitness
    x_history: np.ndarray | None       # (runs, iterations + 1, dim) best-so-far point, if asked
    evaluation_history: np.ndarray     # (runs, iterations + 1) cumulative evaluations
    iterations_done: np.ndarray        # (runs,) iterations actually used (< iterations if stopped)
    extras: dict[str, np.ndarray] = field(default_factory=dict)       # name -> (runs, iterations + 1)
    snapshots: dict[int, np.ndarray] = field(default_factory=dict)    # iteration -> (runs, population, dim)
    #: Every improvement of each run's best-so-far at its exact evaluation number: (row, evaluation,
    #: fitness) arrays sorted by row, then evaluation (:class:`EvaluationLog`); None: not kept.
    events: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None


class EvaluationLog:
    """Improvements of the best-so-far fitness of each run at their exact evaluation number.

    An algorithm reports the fitness values it computes, in the order it evaluates them, with
    :func:`evaluated`; points of one call are counted in population order, so the improvement at
    position ``c`` of a call gets the evaluation number ``count before the call + c * step + 1``
    (``step``: evaluations each point costs, 1 but for local methods whose count includes the
    Jacobian). Vectorised over (runs, points). :meth:`Algorithm.minimize` opens every iteration
    with :meth:`start` and closes it with :meth:`finish`, which also covers an algorithm (or a
    phase, like the LM steps of a hybrid) that does not report: an improvement that no reported
    value explains is put at the iteration's last evaluation -- the resolution of the records.
    """

    def __init__(self, runs: int):
        self.count = np.zeros(runs, dtype=np.int64)
        self.best = np.full(runs, np.inf)
        self.active = np.ones(runs, dtype=bool)
        self.first = True
        self._r: list[np.ndarray] = []
        self._e: list[np.ndarray] = []
        self._f: list[np.ndarray] = []

    def start(self, evaluations: np.ndarray, active: np.ndarray) -> None:
        self.count = np.array(evaluations, dtype=np.int64, copy=True)
        self.active = active

    def add(self, f: np.ndarray, rows: np.ndarray | None = None, step=1) -> None:
        """Values ``f`` (runs, k) of every run, or (k,) of the runs ``rows`` (one point each)."""
        f = np.asarray(f, dtype=float)
        if rows is not None:
            rows = np.asarray(rows, dtype=np.intp)
            hit = (f < self.best[rows]) & self.active[rows]
            r = rows[hit]
            self._keep(r, self.count[r] + 1, f[hit])
            self.best[rows] = np.fmin(self.best[rows], f)
            self.count[rows] += step
            return
        runs, k = f.shape
        if not self.first and k:
            # Most calls improve no run: then nothing is kept and the best stays (a hit needs a
            # value below the run's best; fmin ignores NaN as the accumulation does).
            if not (np.fmin.reduce(f, axis=1) < self.best).any():
                self.count = self.count + k * np.asarray(step, dtype=np.int64)
                return
        acc = np.fmin.accumulate(f, axis=1)
        prev = np.empty_like(f)
        prev[:, 0] = self.best
        np.fmin(acc[:, :-1], self.best[:, None], out=prev[:, 1:])
        hit = f < prev
        if self.first:          # a run's first evaluation opens its trace, whatever its value
            hit[:, 0] = True
            self.first = False
        hit &= self.active[:, None]
        r, c = np.nonzero(hit)
        step = np.broadcast_to(np.asarray(step, dtype=np.int64), (runs,))
        self._keep(r, self.count[r] + c * step[r] + 1, f[r, c])
        np.fmin(self.best, acc[:, -1], out=self.best)
        self.count = self.count + k * step

    def _keep(self, r, e, f) -> None:
        if r.size:
            self._r.append(r)
            self._e.append(np.asarray(e, dtype=np.int64))
            f = np.asarray(f, dtype=float)
            self._f.append(np.where(np.isnan(f), np.inf, f))

    def finish(self, evaluations: np.ndarray, best_f: np.ndarray) -> None:
        """Close the iteration: an improvement of ``best_f`` that no reported value reached
        is put at the iteration's last evaluation."""
        gap = best_f < self.best
        if gap.any() and (gap := gap & self.active).any():     # rarely: most iterations report every value
            r = np.flatnonzero(gap)
            self._keep(r, np.asarray(evaluations)[r], best_f[r])
            self.best = np.where(gap, best_f, self.best)

    def events(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if not self._r:
            return np.empty(0, np.intp), np.empty(0, np.int64), np.empty(0)
        r, e, f = (np.concatenate(a) for a in (self._r, self._e, self._f))
        order = np.lexsort((e, r))
        return r[order], e[order], f[order]


def evaluated(state, f: np.ndarray, rows: np.ndarray | None = None) -> None:
    """Report fitness values just computed, in evaluation order, to the run's
    :class:`EvaluationLog` (nothing happens outside :meth:`Algorithm.minimize`)."""
    log = getattr(state, "log", None)
    if log is not None:
        log.add(f, rows)


def log_arrays(state, runs: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The run's :class:`EvaluationLog` as the arrays a compiled iteration updates in place while
    it reports its values (best, count, active: :func:`fkopt.algorithms.kernels.log_points`, the
    same rule as :meth:`EvaluationLog.add`); scratch arrays outside :meth:`Algorithm.minimize`.
    Hand the improvements it returns to :func:`log_kept`."""
    log = getattr(state, "log", None)
    if log is None:
        return np.full(runs, np.inf), np.zeros(runs, dtype=np.int64), np.zeros(runs, dtype=bool)
    if log.first:               # never in minimize: the initial population is reported first
        raise RuntimeError("a compiled iteration needs the log's initial report first")
    return log.best, log.count, log.active


def log_kept(state, kept) -> None:
    """Store the improvements (rows, evaluation numbers, values) a compiled iteration found."""
    log = getattr(state, "log", None)
    if log is not None:
        log._keep(*kept)


@lru_cache(maxsize=64)
def row_offsets(runs: int, population: int) -> np.ndarray:
    """``arange(runs) * population`` (read-only, cached): flat index of each run's first agent.

    ``row_offsets(R, P) + i`` turns per-run agent indices (R,) into indices of the flattened
    (R * P) arrays -- cheaper than fancy indexing with two index arrays.
    """
    out = np.arange(runs, dtype=np.intp) * population
    out.flags.writeable = False
    return out


def rows_of(problem, rows: np.ndarray):
    """The problem for points taken from batch rows ``rows`` (k, ..., dim), e.g. the active
    points of a local method: ``problem.take(rows)`` when the problem's first axis is per row
    (:func:`fkopt.solve` batching several targets), the problem itself otherwise."""
    return problem if getattr(problem, "cases", None) is None else problem.take(rows)


def compiled_step(problem, make):
    """(compiled iteration, absolute objective) when the problem's mechanism offers its fitness
    compiled for swarm iterations (``compiled_swarm_fitness()``: a
    :class:`fkopt.mechanisms.base.CompiledFitness`, the 3-RPS FK fitness, unless
    ``FKOPT_NUMERICS=numpy`` or numba is missing) and the problem is a plain FK problem of three
    variables without angle-valued joints, else None. ``make(fitness)`` builds the algorithm's
    iteration on it (:func:`fkopt.algorithms.pso_kernels.pso_iteration`,
    :func:`fkopt.algorithms.abc_kernels.abc_iteration`): the same operations as the numpy
    iteration, numpy's own ``np.tan`` included, so the same bits (tests/test_numerics.py)."""
    # Asked every iteration: the answer is kept on the problem per FKOPT_NUMERICS value (a test
    # or a caller may change the variable between iterations).
    key = (make, numerics_path.requested())
    cache = getattr(problem, "_compiled_steps", None)
    if cache is not None and key in cache:
        return cache[key]
    offer = getattr(getattr(problem, "mechanism", None), "compiled_swarm_fitness", None)
    rows = getattr(problem, "_joint_rows", None)
    if offer is None or rows is None or problem._angle.any() or problem.bounds.shape[0] != 3:
        got = None
    else:
        fitness = offer()
        got = None if fitness is None else (make(fitness), problem.objective == "absolute")
    if cache is None:
        try:
            cache = problem._compiled_steps = {}
        except AttributeError:          # a problem that takes no attributes: ask every time
            return got
    cache[key] = got
    return got


def clip(x: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """Project onto the box (the bound handling of every swarm in fkopt unless it says otherwise)."""
    return np.clip(x, bounds[:, 0], bounds[:, 1])


def uniform_in(bounds: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Map uniforms in [0, 1) (..., dim) to points in the box."""
    return bounds[:, 0] + u * (bounds[:, 1] - bounds[:, 0])


class Algorithm:
    """Base of all algorithms. Subclasses set ``name``, ``Params`` and the two methods."""

    name: ClassVar[str]
    Params: ClassVar[type[Params]] = Params
    #: Deterministic local methods (Newton, LM) start from ``x0`` and ignore the population.
    local: ClassVar[bool] = False
    #: True when no BLAS/LAPACK call lies on the algorithm's own path (elementwise numpy only), so
    #: its results do not depend on which BLAS kernel runs (:mod:`fkopt.run.compare`). False by default:
    #: code fkopt has not read (adapters, plug-ins) is assumed to call BLAS somewhere.
    blas_free: ClassVar[bool] = False
    #: Rough evaluations per iteration as a function of population, for documentation.
    evaluations_per_iteration: ClassVar[str] = "population"

    def __init__(self, **params: Any):
        try:
            self.params = self.Params(**params)
        except ValidationError as err:
            first = err.errors()[0]
            loc = field_path(first["loc"])
            allowed = ", ".join(self.Params.model_fields) or "(none)"
            msg = first["msg"].removeprefix("Value error, ")
            if first["type"] == "extra_forbidden":
                msg = "unknown parameter" + did_you_mean(loc, self.Params.model_fields)
            raise FkoptError(f"algorithm '{self.name}' parameter '{loc}': {msg} "
                             f"(parameters: {allowed})") from None

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.model_dump().items())
        return f"{type(self).__name__}({args})"

    # -- to implement ------------------------------------------------------------------------
    def initialize(self, problem, population: int, streams: RunStreams, x0: np.ndarray | None,
                   iterations: int) -> State:
        """The state after the initial population; ``iterations`` is the budget the run will get
        (schedules such as PSO's linear inertia depend on it)."""
        raise NotImplementedError

    def iterate(self, state: State, problem, streams: RunStreams) -> None:
        raise NotImplementedError

    def compiled_advance(self, problem):
        """None, or ``advance(state, streams, first, last, history, evaluations, x_history)`` that runs
        iterations first..k (first <= k <= last) in one compiled call and returns k: each iteration
        with everything :meth:`minimize` does around :meth:`iterate` (the log's start and finish,
        the best-so-far, the records: column t of ``history``, ``evaluations`` and, when not None,
        ``x_history``), the same bits. Offered by an algorithm without :meth:`extras`; minimize
        takes it when no run can stop at a target (fkopt's ABC and GABC on a compiled fitness:
        :meth:`fkopt.algorithms.abc.ABC.compiled_advance`)."""
        return None

    def extras(self, state: State) -> dict[str, np.ndarray]:
        """Extra per-run scalars to record each iteration (e.g. ACO pheromone)."""
        return {}

    def resources(self, population: int, iterations: int, dim: int) -> int:
        """Bytes this algorithm needs beyond fkopt's own arrays of a solve (counted by
        :func:`fkopt.solve.batch_bytes`), or a one-line error when the settings cannot run;
        checked for every algorithm of a config before the first starts. 0 for fkopt's own."""
        return 0

    def check_state(self, state, problem, runs: int, step: str) -> None:
        """A plug-in's state after ``step`` (initialize/iterate), checked before fkopt uses it:
        x (runs, population, dim) of finite points inside the bounds, f (runs, population)
        without NaN, evaluations (runs,) of whole numbers >= 0. One line naming the plug-in."""
        where = f"algorithm '{self.name}' ({type(self).__module__}.{type(self).__qualname__}): {step}"
        if state is None or not all(hasattr(state, k) for k in ("x", "f", "evaluations")):
            raise FkoptError(f"{where} returned {type(state).__name__}, not a State with x, f and evaluations")
        try:
            x, f = np.asarray(state.x, dtype=float), np.asarray(state.f, dtype=float)
            ev = np.asarray(state.evaluations, dtype=float)
        except (TypeError, ValueError):
            raise FkoptError(f"{where}: state.x, state.f and state.evaluations must be numbers") from None
        dim = problem.dim
        if x.ndim != 3 or x.shape[0] != runs or x.shape[2] != dim or f.shape != x.shape[:2]:
            raise FkoptError(f"{where}: state.x has shape {x.shape} and state.f {f.shape}; expected "
                             f"(runs={runs}, population, dim={dim}) and (runs, population)")
        if ev.shape != (runs,) or not np.isfinite(ev).all() or (ev < 0).any() or (ev != np.round(ev)).any():
            raise FkoptError(f"{where}: state.evaluations must be {runs} whole numbers >= 0, got shape {ev.shape}")
        if np.isnan(f).any():
            raise FkoptError(f"{where}: state.f holds NaN fitness values")
        b = np.asarray(problem.bounds, dtype=float)
        tol = 1e-9 * (b[:, 1] - b[:, 0])
        if not np.isfinite(x).all() or ((x < b[:, 0] - tol) | (x > b[:, 1] + tol)).any():
            raise FkoptError(f"{where}: state.x holds points outside the bounds (or not finite)")

    # -- shared --------------------------------------------------------------------------------
    @staticmethod
    def update_best(state: State) -> None:
        """Fold the memory ``state.x``/``state.f`` into the best-so-far of each run.

        The first minimum of each run wins; arrays are replaced (never written in place), and
        only when some run improved. A compiled iteration that did this already (the same rule,
        into new arrays) sets ``state.best_folded``; the call then only clears it.
        """
        if getattr(state, "best_folded", False):
            state.best_folded = False
            return
        f = state.f
        runs, population = f.shape
        flat = f.argmin(axis=1)
        flat += row_offsets(runs, population)
        fb = f.ravel()[flat]
        better = fb < state.best_f
        if better.any():
            state.best_f = np.where(better, fb, state.best_f)
            xb = state.x.reshape(runs * population, -1)[flat]
            state.best_x = np.where(better[:, None], xb, state.best_x)

    def minimize(self, problem, *, population: int, iterations: int, streams: RunStreams,
                 target: float | None = None, stop_at_target: bool = False,
                 x0: np.ndarray | None = None, snapshots=(), x_history: bool = True) -> RunRecord:
        """Run every row of ``streams`` for ``iterations`` iterations (see the module docstring).

        ``x_history=False`` keeps only the final best point (``RunRecord.x_history`` is None):
        (runs, iterations + 1, dim) floats are the largest record of a big batch.
        """
        runs, dim = streams.runs, problem.dim
        state = self.initialize(problem, population, streams, x0, iterations)
        plugin = not type(self).__module__.startswith("fkopt.")
        if plugin:
            self.check_state(state, problem, runs, "initialize")
        state.best_f = np.full(runs, np.inf)
        state.best_x = np.full((runs, dim), np.nan)
        log = EvaluationLog(runs)
        f0 = np.asarray(state.f)
        # the initial points, each costing evaluations / points (more than 1: a Jacobian too)
        log.add(f0, step=np.maximum(np.asarray(state.evaluations, dtype=np.int64) // f0.shape[1], 1))
        self.update_best(state)
        log.finish(state.evaluations, state.best_f)
        state.log = log

        history = np.empty((runs, iterations + 1))
        xs = np.empty((runs, iterations + 1, dim)) if x_history else None
        evals = np.empty((runs, iterations + 1), dtype=np.int64)
        extra_hist: dict[str, np.ndarray] = {}
        snaps: dict[int, np.ndarray] = {}
        wanted = {int(s) for s in snapshots}
        done = np.zeros(runs, dtype=bool)
        done_at = np.full(runs, iterations)
        final_x = state.best_x

        def record(t: int) -> None:
            nonlocal final_x
            if t == 0 or not frozen:
                history[:, t] = state.best_f
                final_x = state.best_x
                evals[:, t] = state.evaluations
                for key, value in self.extras(state).items():
                    extra_hist.setdefault(key, np.empty((runs, iterations + 1)))[:, t] = value
            else:   # runs that reached the target keep their values
                history[:, t] = np.where(done, history[:, t - 1], state.best_f)
                final_x = np.where(done[:, None], final_x, state.best_x)
                evals[:, t] = np.where(done, evals[:, t - 1], state.evaluations)
                for key, value in self.extras(state).items():
                    arr = extra_hist[key]
                    arr[:, t] = np.where(done, arr[:, t - 1], value)
            if xs is not None:
                xs[:, t] = final_x
            if t in wanted:
                snaps[t] = np.array(state.x, copy=True)

        frozen = False   # does any run hold its records (reached the target)?
        record(0)
        last = iterations
        watch = stop_at_target and target is not None
        advance = None if watch or plugin else self.compiled_advance(problem)
        t = 1
        # a listener hears at least TICKS ticks per run of the loop: the calls end there too (where a
        # call ends never changes a number: the draws follow one stream order, tests/test_numerics.py)
        span = max(1, iterations // TICKS) if heard() else iterations
        while advance is not None and t <= iterations:   # several iterations per compiled call
            stop = min([s for s in wanted if s >= t] + [iterations, t + span - 1])
            t = advance(state, streams, t, stop, history, evals, xs)
            final_x = state.best_x
            if t in wanted:
                snaps[t] = np.array(state.x, copy=True)
            tick(t, iterations)
            t += 1
        for t in range(t, iterations + 1):
            if watch:
                newly = ~done & (history[:, t - 1] < target)
                if newly.any():
                    done_at[newly] = t - 1
                    done |= newly
                    frozen = True
                    if done.all():
                        last = t - 1
                        break
            log.start(state.evaluations, ~done)
            self.iterate(state, problem, streams)
            if plugin:
                self.check_state(state, problem, runs, "iterate")
            self.update_best(state)
            log.finish(state.evaluations, state.best_f)
            record(t)
            tick(t, iterations)
        if stop_at_target and target is not None:
            newly = ~done & (history[:, last] < target)
            done_at[newly] = last
        if last < iterations:   # every run stopped early: hold the final values to the end
            history[:, last + 1:] = history[:, [last]]
            if xs is not None:
                xs[:, last + 1:] = xs[:, [last]]
            evals[:, last + 1:] = evals[:, [last]]
            for arr in extra_hist.values():
                arr[:, last + 1:] = arr[:, [last]]
        return RunRecord(
            best_x=np.array(final_x, dtype=float, copy=True), best_f=history[:, -1].copy(), history=history,
            x_history=xs, evaluation_history=evals, iterations_done=done_at,
            extras=extra_hist, snapshots=snaps, events=log.events(),
        )
