"""The adapter of an external optimiser: a counting fitness wrapper and one RunRecord.

For every library, fkopt -- not the library -- does the bookkeeping:

* **Counting.** The library sees a wrapper of ``problem.fitness``. It counts each point it
  evaluates (a batch of n points is n evaluations) and records best-so-far per evaluation: the
  evaluation number, fitness and point of every improvement (:class:`Trace`).
* **Budget.** A run gets ``evaluations`` fitness evaluations (param; default
  ``population * (iterations + 1)``, what a generational method with that population uses
  in ``iterations`` generations after its initial population). The library's own stopping
  option is set to the budget where it has one, and the wrapper enforces it anyway: a batch
  that would cross the budget is evaluated only up to it, and the next call raises a private
  exception that ends the library's run. So no run ever uses more than the budget; a library
  that stops by itself (converged) uses fewer, and the records say how many.
* **Seeds.** Run k of a task gets the integer seed ``SeedSequence(seed, spawn_key=(k,))``
  ``.generate_state(1)[0]`` (scipy gets a ``Generator`` on that SeedSequence), the stream
  of :mod:`fkopt.numerics.streams` -- so run k gives the same numbers alone, in a batch or in a worker.
* **Processes.** Runs are independent; ``workers`` (param; default 1) runs them in that many
  processes. The numbers do not depend on it. (A process pool costs ~0.5-1.5 s of start-up and
  imports per solve, more than it saves on the small solves of a suite, whose tasks run in
  worker processes already: hence the default of 1 for every library.)
* **Lockstep.** A per-point library (NiaPy) run in this process calls the fitness once per
  point; fkopt then runs up to :data:`LOCKSTEP_RUNS` runs in threads in lockstep
  (:class:`Lockstep`), so that one batched fitness call evaluates the next point of every
  run. Each run's numbers are those of the run alone (its own library object, stream and
  counter; the fitness is elementwise), only the cost of a point changes: from a whole
  single-point numpy evaluation to a share of a batched one.
* **Target.** With ``stop_at_target`` a run stops after the call (a batch for vectorised
  libraries) whose evaluations first went below the target; the whole batch is counted.

Iteration axis. fkopt's records are indexed by iteration t = 0..iterations. For a library run
the record t is the state after ``e_t = e_0 + round(t (B - e_0) / iterations)`` evaluations,
with B the budget and e_0 = min(population, B): t = 0 is after the first population, t =
iterations at the budget, evenly spaced between. With the default budget e_t = population (t +
1), one iteration = one population's worth of evaluations. ``evaluation_history`` holds the
evaluations actually used by then (``min(e_t, used)``), so evaluation-based comparisons
(``mean_evaluations``) are exact, while iteration-based ones compare checkpoints, not the
library's generations. ``iterations_done`` is the first record below the target (with
``stop_at_target``), else ``iterations``; a run that stopped there holds, from that record on,
its final fitness and point and the evaluations it used in all (the stopping batch counts
whole). ``RunRecord.events`` keeps every improvement at its exact evaluation number (what the
run traces and evaluations-to-threshold read), including the first evaluation.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from pydantic import ConfigDict, Field

from fkopt.adapters import niapy_, pymoo_, scipy_
from fkopt.adapters.libraries import library_version
from fkopt.algorithms.base import Algorithm, Params, RunRecord
from fkopt.errors import FkoptError
from fkopt.files import available_cpus
from fkopt.progress import tick

#: The module of each library's adapter: its ``resolve``, ``check_params``, ``run``, ``library_population``.
LIBRARY_MODULES = {"scipy": scipy_, "pymoo": pymoo_, "niapy": niapy_}


class _Stop(Exception):
    """Raised by the wrapper to end a library's run (budget used up or target reached)."""


class ExternalParams(Params):
    """fkopt's own parameters of an adapter; every other key goes to the library."""

    model_config = ConfigDict(extra="allow", frozen=True)
    evaluations: int | None = Field(None, ge=1, description="evaluation budget per run "
                                    "(default population * (iterations + 1))")
    workers: int | None = Field(None, ge=1, description="processes running the runs (default 1: "
                                "the runs in this process; per-point libraries' runs in lockstep)")


@dataclass
class Trace:
    """Best-so-far of one run, improvements only: ``evals[i]`` is the evaluation number at
    which ``f[i]`` (point ``x[i]``) became the best; ``used`` the evaluations used."""

    evals: np.ndarray
    f: np.ndarray
    x: np.ndarray
    used: int


class Counter:
    """The fitness the library sees: counts, records improvements, enforces budget and target."""

    def __init__(self, problem, budget: int, target: float | None = None, stop: bool = False,
                 fitness=None):
        self.problem = problem
        #: What evaluates the points (``problem.fitness``, or a :class:`Lockstep` member that
        #: evaluates them together with other runs' points: the same numbers).
        self.fitness = fitness if fitness is not None else problem.fitness
        self.budget = int(budget)
        self.stop_below = target if (stop and target is not None) else None
        self.n = 0
        self.best = np.inf
        self._evals: list[int] = []
        self._f: list[float] = []
        self._x: list[np.ndarray] = []

    def batch(self, X) -> np.ndarray:
        """Fitness of points ``X`` shaped (n, dim) -> (n,)."""
        X = np.asarray(X, dtype=float)
        if self.n >= self.budget or (self.stop_below is not None and self.best < self.stop_below):
            raise _Stop
        take = min(len(X), self.budget - self.n)
        f = np.asarray(self.fitness(X[:take]), dtype=float).reshape(take)
        f = np.where(np.isnan(f), np.inf, f)
        running = np.minimum.accumulate(np.concatenate([[self.best], f]))
        better = running[1:] < running[:-1]
        if self.n == 0:     # a run's first evaluation opens its trace, whatever its value
            better[0] = True
        for i in np.flatnonzero(better):
            self._evals.append(self.n + int(i) + 1)
            self._f.append(float(f[i]))
            self._x.append(X[i].copy())
        self.best = float(running[-1])
        self.n += take
        if take < len(X) or (self.stop_below is not None and self.best < self.stop_below):
            raise _Stop     # a batch that reached the target still counts whole: it was evaluated
        return f

    def point(self, x) -> float:
        """Fitness of one point ``x`` shaped (dim,) (per-point libraries): :meth:`batch` of
        ``x[None]`` with the bookkeeping done on Python floats (the same counts, trace and
        stops; a per-point library calls this thousands of times per run)."""
        x = np.array(x, dtype=float)            # a copy: the trace keeps it, the library may reuse its array
        stop = self.stop_below
        if self.n >= self.budget or (stop is not None and self.best < stop):
            raise _Stop
        f = float(np.asarray(self.fitness(x[None, :]), dtype=float).reshape(1)[0])
        if f != f:                              # NaN counts as +inf, as in batch
            f = np.inf
        if f < self.best or self.n == 0:        # a run's first evaluation opens its trace
            self._evals.append(self.n + 1)
            self._f.append(f)
            self._x.append(x)
        if f < self.best:
            self.best = f
        self.n += 1
        if stop is not None and self.best < stop:
            raise _Stop
        return f

    def trace(self) -> Trace:
        dim = self.problem.dim
        return Trace(np.array(self._evals, dtype=np.int64), np.array(self._f, dtype=float),
                     np.array(self._x, dtype=float).reshape(-1, dim), self.n)


def checkpoints(population: int, iterations: int, budget: int) -> np.ndarray:
    """Evaluation counts e_t (t = 0..iterations) at which the records are taken (module doc)."""
    e0 = min(int(population), int(budget))
    t = np.arange(int(iterations) + 1)
    return e0 + np.rint(t * (budget - e0) / iterations).astype(np.int64)


def run_seed(seed: int, run: int) -> np.random.SeedSequence:
    """Run ``run``'s seed sequence (:func:`fkopt.numerics.streams.run_seed_sequence`)."""
    return np.random.SeedSequence(int(seed), spawn_key=(int(run),))


def _runner(library: str):
    return LIBRARY_MODULES[library].run


def run_one(library: str, method: str, params: dict, problem, population: int, budget: int,
            seed_seq: np.random.SeedSequence, target, stop: bool, x0, fitness=None) -> Trace:
    """One run of ``library:method`` (module level, so a worker process can run it);
    ``fitness``: what evaluates the points instead of ``problem.fitness`` (:class:`Lockstep`)."""
    counter = Counter(problem, budget, target, stop, fitness)
    try:
        _runner(library)(method, dict(params), counter, problem, int(population), int(budget), seed_seq, x0)
    except _Stop:
        pass
    except FkoptError:
        raise
    except Exception as err:   # the library failed: one line naming it
        msg = str(err).strip().splitlines()[0] if str(err).strip() else ""
        raise FkoptError(f"algorithm '{library}:{method}' ({library} {library_version(library)}) "
                         f"raised {type(err).__name__}: {msg}") from None
    if counter.n > budget:   # pragma: no cover - Counter never lets it happen
        raise FkoptError(f"algorithm '{library}:{method}' used {counter.n} evaluations, budget {budget}")
    return counter.trace()


#: Runs of a per-point library that one :class:`Lockstep` group evaluates together (threads
#: per group; more makes each handoff dearer than the batching saves).
LOCKSTEP_RUNS = 32


class Lockstep:
    """Several runs of a per-point library, each in its own thread, whose single-point fitness
    calls are evaluated together: one batched ``problem.fitness`` call for every run's next point.

    Every member thread calls :meth:`member`'s function with its one point and blocks; when
    every member still running has handed in a point, the last to arrive evaluates them all in
    one call (on the rows of a problem with a case axis: each run's own target) and releases the
    others. A run's numbers are the same as alone: its library object, random stream and
    Counter are its own, it waits for its fitness before going on, and fitness is elementwise
    (the value of a point does not depend on the other points of the batch; tested for every
    kinbench problem). Only the order in which the runs' Python code interleaves changes."""

    def __init__(self, problem, members: int, batched: bool):
        self.problem = problem
        self.batched = batched                  # member k solves row k of the case axis
        self.active = int(members)
        self._lock = threading.Lock()
        self._gates: dict[int, Any] = {}
        self._pending: dict[int, np.ndarray] = {}
        self._out: dict[int, Any] = {}
        self._sub: tuple[tuple[int, ...], Any] | None = None

    def member(self, k: int):
        gate = self._gates[k] = threading.Lock()
        gate.acquire()

        def fitness(X):
            X = np.asarray(X, dtype=float)
            if X.shape[0] != 1:                 # not a single point: alone (never for per-point libraries)
                return (self.problem.case(k) if self.batched else self.problem).fitness(X)
            with self._lock:
                self._pending[k] = X[0]
                woken = self._flush() if len(self._pending) == self.active else None
            if woken is None:
                gate.acquire()                  # released by the member that evaluates the batch
            else:
                self._release(woken, k)
            out = self._out.pop(k)
            if isinstance(out, BaseException):
                raise out
            return out
        return fitness

    def leave(self, k: int) -> None:
        """Member ``k``'s run is over: the others no longer wait for its points."""
        with self._lock:
            self.active -= 1
            woken = self._flush() if self._pending and len(self._pending) == self.active else None
        if woken is not None:
            self._release(woken, None)

    def _release(self, woken, me) -> None:
        for j in woken:
            if j != me:
                self._gates[j].release()

    def _flush(self) -> list[int]:
        keys = sorted(self._pending)
        X = np.stack([self._pending[k] for k in keys])
        self._pending.clear()
        try:
            if not self.batched:                # one target for every run
                f = self.problem.fitness(X)
            else:
                rows = tuple(keys)
                if self._sub is None or self._sub[0] != rows:
                    self._sub = (rows, self.problem.take(list(rows)))
                f = self._sub[1].fitness(X[:, None, :])[:, 0]
            f = np.asarray(f, dtype=float).reshape(len(keys))
            for i, k in enumerate(keys):
                self._out[k] = f[i:i + 1]
        except BaseException as err:            # every waiting run gets the error
            for k in keys:
                self._out[k] = err
        return keys


def run_lockstep(args: list[tuple], problem, batched: bool) -> list[Trace]:
    """:func:`run_one` of every argument tuple, in groups of :data:`LOCKSTEP_RUNS` threads whose
    fitness calls are batched (:class:`Lockstep`); the traces in order. An error is raised once
    every thread of its group has finished (the first row's, as one run after the other would)."""
    traces: list[Trace | None] = [None] * len(args)
    errors: list[BaseException | None] = [None] * len(args)
    for start in range(0, len(args), LOCKSTEP_RUNS):
        group = list(range(start, min(start + LOCKSTEP_RUNS, len(args))))
        gang = Lockstep(problem, len(group), batched)

        def work(i: int) -> None:
            try:
                traces[i] = run_one(*args[i], fitness=gang.member(i))
            except BaseException as err:         # re-raised in the calling thread below
                errors[i] = err
            finally:
                gang.leave(i)
        threads = [threading.Thread(target=work, args=(i,), daemon=True) for i in group]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for i in group:
            if errors[i] is not None:
                raise errors[i]
    return traces


class ExternalAlgorithm(Algorithm):
    """An optimiser of another library run by fkopt (see the module docstring)."""

    Params = ExternalParams
    library: ClassVar[str]
    method: ClassVar[str]
    target: ClassVar[Any]
    #: Per-point libraries call the fitness one point at a time: their runs go in lockstep
    #: (:func:`run_lockstep`), so each call evaluates one point of every run at once.
    per_point: ClassVar[bool] = False   # set for niapy in fkopt.adapters.adapter_class
    evaluations_per_iteration = "population (one record per population's worth of evaluations)"

    def __init__(self, **params: Any):
        super().__init__(**params)
        self.library_params = dict(self.params.model_extra or {})
        module = LIBRARY_MODULES[self.library]
        module.check_params(self.method, self.target, self.library_params)
        small = getattr(module, "probe_params", lambda *_: None)(self.method, self.library_params)
        if small is not None:
            self.probe(small)

    def probe(self, params: dict) -> None:
        """Let the library check its options: one run on a 2-D box, stopped at its first
        evaluation (budget 0), before any real run starts; a rejection is one line."""
        class Box:
            dim = 2
            bounds = np.array([[0.0, 1.0], [0.0, 1.0]])
            variable_names = ("u", "v")

            @staticmethod
            def fitness(x):
                return np.zeros(len(x))
        try:
            _runner(self.library)(self.method, dict(params), Counter(Box(), 0), Box(), 4, 0,
                                  np.random.SeedSequence(0), None)
        except _Stop:
            pass
        except FkoptError:
            raise
        except Exception as err:
            msg = (str(err).strip().splitlines() or [type(err).__name__])[0]
            raise FkoptError(f"algorithm '{self.library}:{self.method}' ({self.library} "
                             f"{library_version(self.library)}) rejected params {self.library_params}: "
                             f"{type(err).__name__}: {msg}") from None

    def budget_for(self, population: int, iterations: int) -> int:
        return int(self.params.evaluations or population * (iterations + 1))

    def resources(self, population: int, iterations: int, dim: int) -> int:
        """The library's own population (``popsize`` x dim, ``pop_size``, ``population_size``):
        refused when it exceeds the evaluation budget (its first generation could never be
        evaluated); else its estimated bytes (about 64 arrays of its points, per worker
        process), which the job's memory estimate adds to fkopt's own."""
        module = LIBRARY_MODULES[self.library]
        points = module.library_population(self.method, self.library_params, int(population), int(dim))
        budget = self.budget_for(population, iterations)
        if points > budget:
            raise FkoptError(f"algorithm '{self.library}:{self.method}': its population of {points} points per "
                             f"generation exceeds the run's budget of {budget} evaluations (population x "
                             "(iterations + 1), or params.evaluations); lower the library's population")
        workers = max(1, min(self.params.workers or 1, available_cpus()))
        return 64 * 8 * points * max(int(dim), 1) * workers

    def minimize(self, problem, *, population: int, iterations: int, streams, target=None,
                 stop_at_target: bool = False, x0=None, snapshots=(), **_ignored) -> RunRecord:
        budget = self.budget_for(population, iterations)
        runs = list(streams.run_ids)
        # one seed per batch row (rows of several cases carry their case's seed, fkopt.numerics.streams)
        seeds = [run_seed(s, k) for s, k in zip(streams.seeds, runs)]
        start = None if x0 is None else np.asarray(x0, dtype=float)
        # a problem with a case axis holds one target per row: each run solves its own row's
        batched = getattr(problem, "cases", None) is not None
        args = [(self.library, self.method, self.library_params, problem.case(i) if batched else problem,
                 population, budget, s, target, stop_at_target,
                 None if start is None else (start if start.ndim == 1 else start[i]))
                for i, s in enumerate(seeds)]
        workers = min(self.params.workers or 1, len(runs), available_cpus())
        if workers <= 1 and self.per_point and len(args) > 1:
            traces = run_lockstep(args, problem, batched)      # batched fitness calls, same numbers
        elif workers <= 1:
            traces = []
            for a in args:
                traces.append(run_one(*a))
                tick(len(traces), len(args))
        else:
            import multiprocessing      # worker processes: their modules (and logging) cost every command's
            from concurrent.futures import ProcessPoolExecutor      # start-up (the registry loads this module)
            methods = multiprocessing.get_all_start_methods()
            ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
            with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
                traces = list(pool.map(run_one, *zip(*args)))
        self.last_traces = traces
        return record_from_traces(traces, population, iterations, budget, problem.dim,
                                  target if stop_at_target else None)


def record_from_traces(traces: list[Trace], population: int, iterations: int, budget: int, dim: int,
                       stop_target: float | None) -> RunRecord:
    """Sample each run's improvement trace at the checkpoints e_t (module docstring)."""
    e = checkpoints(population, iterations, budget)
    runs = len(traces)
    history = np.full((runs, iterations + 1), np.inf)
    x_history = np.full((runs, iterations + 1, dim), np.nan)
    evals = np.empty((runs, iterations + 1), dtype=np.int64)
    done = np.full(runs, iterations)
    for r, tr in enumerate(traces):
        idx = np.searchsorted(tr.evals, e, side="right") - 1
        ok = idx >= 0
        history[r, ok] = tr.f[idx[ok]]
        x_history[r, ok] = tr.x[idx[ok]]
        evals[r] = np.minimum(e, tr.used)
        if stop_target is not None:
            below = np.flatnonzero(history[r] < stop_target)
            if below.size:
                d = done[r] = below[0]
                # stopped there: the stopping batch's last improvements and count belong to it
                history[r, d:], x_history[r, d:], evals[r, d:] = tr.f[-1], tr.x[-1], tr.used
    events = (np.repeat(np.arange(runs), [len(tr.evals) for tr in traces]),
              np.concatenate([tr.evals for tr in traces]).astype(np.int64),
              np.concatenate([tr.f for tr in traces]).astype(float))
    return RunRecord(best_x=x_history[:, -1].copy(), best_f=history[:, -1].copy(), history=history,
                     x_history=x_history, evaluation_history=evals, iterations_done=done, events=events)


__all__ = ["Counter", "ExternalAlgorithm", "ExternalParams", "Trace", "checkpoints", "record_from_traces",
           "run_one", "run_seed"]
