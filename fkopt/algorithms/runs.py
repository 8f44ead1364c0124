"""The run loop under :func:`fkopt.solve`: an :class:`~fkopt.algorithms.base.Algorithm` object on a
problem for several seeded runs (names resolve one floor up, in :func:`fkopt.solve.solve` through
:mod:`fkopt.registry`; the exact solvers call this loop with algorithm objects, so nothing here
imports the registry).

Rows. Every (case, run) pair is one *row* of one array: a problem with a case axis (several
targets, see :mod:`fkopt.problems`) and R runs gives ``cases * R`` rows, case-major, advanced
together through the algorithm's (runs, population, dim) axis -- algorithms know nothing of
cases; row i simply gets the target ``problem.take(case of row i)``. Every row draws from its
own stream, ``run_seed_sequence(seed of its case, run id)`` (:mod:`fkopt.numerics.streams`), so a case
gives bit-identical numbers alone (solved with the seed recorded for it, ``result.seeds[c]``),
inside a batch, in chunks, or one run at a time.

Chunks. Rows are advanced in chunks of at most :data:`CHUNK_POINTS` // population rows, as equal
as possible (``chunk_rows`` overrides it): about 10,000 points of the population per chunk, e.g. 1000 rows of a
population of 10 or 100 rows of 100. The results never depend on the chunk size (each row's
numbers are its own); the speed does: at a few rows the per-iteration cost of numpy calls
dominates, beyond ~10^4 points the working arrays leave the CPU caches. The size was chosen by
measuring GABC on 3-RPS (population 10, 3000 rows), ABC on the 7-DOF arm (population 100) and
P-ABC's ABC on 3RPUPc-UPS at several chunk sizes; ``fkopt bench`` (section ``cases``) keeps
measuring 300 / 1000 / 3000 rows per chunk, and ``bench/bench.csv`` keeps the
numbers. With ``batch=False`` every row is solved on its own, one after
the other -- the reference mode that proves batching never changes the numbers.

Memory. The records kept for every row (best-so-far fitness and evaluations per iteration,
algorithm extras, snapshots, and the best-so-far point per iteration only with
``x_history=True``) plus the working arrays of one chunk are estimated before anything is
allocated; a batch above :data:`MEMORY_LIMIT` bytes is refused with an FkoptError.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Any, Sequence

import numpy as np

from fkopt.algorithms.base import Algorithm, RunRecord
from fkopt.errors import FkoptError
from fkopt.progress import part
from fkopt.numerics.streams import CHUNK, RunStreams, case_seed

#: Points (rows x population) advanced together; chosen by measurement (module docstring).
CHUNK_POINTS = 10_000
#: Largest estimated memory of one solve (bytes): 2 GiB.
MEMORY_LIMIT = 2 * 1024 ** 3


@dataclass
class Result:
    """Outcome of ``runs`` independent runs of one algorithm on one problem (or on each case).

    Arrays are indexed by run first -- by case, then run, when the problem has a case axis:
    ``fitness`` (runs,) or (cases, runs), ``x`` (..., dim), ``history[..., t]`` the best-so-far
    fitness after iteration t (t = 0 is the initial population), ``evaluation_history`` the
    matching cumulative count of fitness evaluations, ``x_history`` (..., iterations + 1, dim)
    the best-so-far point (None unless ``solve(..., x_history=True)``). ``time_per_run`` is the
    wall time of a chunk divided by its rows (amortised) in batch mode, the run's own time
    otherwise. ``success`` and ``message`` follow scipy's ``OptimizeResult``. ``case(i)``
    gives case i as a single-target result.
    """

    algorithm: str
    params: dict[str, Any]
    variable_names: tuple[str, ...]
    seed: int | None
    run_ids: np.ndarray
    population: int
    iterations: int
    x: np.ndarray
    fitness: np.ndarray
    history: np.ndarray
    x_history: np.ndarray | None
    evaluation_history: np.ndarray
    iterations_done: np.ndarray
    time_per_run: np.ndarray
    target: float | None = None
    extras: dict[str, np.ndarray] = field(default_factory=dict)
    snapshots: dict[int, np.ndarray] = field(default_factory=dict)
    #: Number of cases (None: a single-target problem) and the integer seed of each case.
    cases: int | None = None
    seeds: np.ndarray | None = None
    #: Every improvement of each run's best-so-far at its exact evaluation number, as (row,
    #: evaluation, fitness) arrays; row = case * runs + run (:class:`~fkopt.algorithms.base.RunRecord`).
    events: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def runs(self) -> int:
        return len(self.run_ids)

    @property
    def evaluations(self) -> np.ndarray:
        """Fitness evaluations used per run (up to the stop, when stopping at a target)."""
        return np.take_along_axis(self.evaluation_history, self.iterations_done[..., None], axis=-1)[..., 0]

    def iterations_to(self, threshold: float) -> np.ndarray:
        """First iteration at which each run's best fitness was below ``threshold`` (NaN: never)."""
        hit = self.history < threshold
        first = np.argmax(hit, axis=-1).astype(float)
        first[~hit.any(axis=-1)] = np.nan
        return first

    def evaluations_to(self, threshold: float) -> np.ndarray:
        """The evaluation at which each run first went below ``threshold`` (NaN: never): exact
        from :attr:`events`; without them, the count at the end of that iteration."""
        if self.events is not None:
            r, e, f = self.events
            out = np.full(self.fitness.size, np.nan)
            below = f < threshold
            rows, first = np.unique(r[below], return_index=True)   # events are sorted by row, evaluation
            out[rows] = e[below][first]
            return out.reshape(self.fitness.shape)
        it = self.iterations_to(threshold)
        ok = ~np.isnan(it)
        at = np.where(ok, it, 0).astype(np.intp)[..., None]
        ev = np.take_along_axis(self.evaluation_history, at, axis=-1)[..., 0].astype(float)
        return np.where(ok, ev, np.nan)

    @property
    def success(self) -> np.ndarray:
        """Per run (per case and run): final fitness below ``target``; without a target, a
        finite final fitness (the run used its budget normally)."""
        if self.target is None:
            return np.isfinite(self.fitness)
        return self.fitness < self.target

    def succeeded(self, threshold: float) -> np.ndarray:
        """Per run: final fitness below ``threshold``."""
        return self.fitness < threshold

    @property
    def message(self) -> str:
        n = self.fitness.size
        what = f"{n} runs" if self.cases is None else f"{n} runs ({self.cases} cases x {self.runs})"
        if self.target is None:
            return f"{what}: iteration budget ({self.iterations}) used; no target given"
        ok = int(np.count_nonzero(self.success))
        return f"{ok} of {what} reached fitness < {self.target:g} within {self.iterations} iterations"

    @property
    def best_run(self):
        """Index of the best run (per case: an array, when the problem has cases)."""
        best = np.argmin(self.fitness, axis=-1)
        return int(best) if self.cases is None else best

    @property
    def median_run(self):
        """The run whose final fitness is the (lower) median over all runs (per case)."""
        order = np.argsort(self.fitness, axis=-1, kind="stable")
        med = order[..., (self.runs - 1) // 2]
        return int(med) if self.cases is None else med

    def case(self, i: int) -> "Result":
        """Case ``i`` of a batched result as the single-target result of that case."""
        if self.cases is None:
            raise FkoptError("this result has no case axis")
        pick = lambda a: None if a is None else np.array(a[i])   # noqa: E731
        return replace(
            self, seed=int(self.seeds[i]), x=pick(self.x), fitness=pick(self.fitness),
            history=pick(self.history), x_history=pick(self.x_history),
            evaluation_history=pick(self.evaluation_history), iterations_done=pick(self.iterations_done),
            time_per_run=pick(self.time_per_run), extras={k: pick(v) for k, v in self.extras.items()},
            snapshots={k: pick(v) for k, v in self.snapshots.items()}, cases=None, seeds=None,
            events=pick_events(self.events, np.arange(i * self.runs, (i + 1) * self.runs)))

    def __repr__(self) -> str:
        where = "" if self.cases is None else f"cases={self.cases}, "
        return (f"Result({self.algorithm}, {where}runs={self.runs}, median fitness="
                f"{np.median(self.fitness):.3g}, best={self.fitness.min():.3g})")


def validate_budget(population: int, iterations: int, runs: int, local: bool = False) -> None:
    if int(population) < (1 if local else 2):
        raise FkoptError(f"population must be at least {1 if local else 2}, got {population}")
    if int(iterations) < 1:
        raise FkoptError(f"iterations must be at least 1, got {iterations}")
    if int(runs) < 1:
        raise FkoptError(f"runs must be at least 1, got {runs}")


def case_seeds(seed: int | Sequence[int], cases: int | None) -> np.ndarray:
    """The integer seed of every case: ``seed`` itself for a single-target problem; for a
    problem with cases, one seed per case as given, or :func:`fkopt.numerics.streams.case_seed` of one
    int ``seed`` (case c's seed is then the first word of ``SeedSequence(seed, spawn_key=(c,))``)."""
    if np.ndim(seed) == 0:
        if cases is None:
            return np.array([int(seed)], dtype=np.int64)
        return np.array([case_seed(int(seed), c) for c in range(cases)], dtype=np.int64)
    seeds = np.asarray(seed)
    if cases is None:
        raise FkoptError("seed must be one integer for a problem with a single target")
    if seeds.shape != (cases,) or not np.issubdtype(seeds.dtype, np.integer):
        raise FkoptError(f"seed: one integer, or one integer per case ({cases}); got shape {seeds.shape}")
    return seeds.astype(np.int64)


def _start_rows(problem, x0, ids: np.ndarray, cases: int | None) -> np.ndarray | None:
    """``x0`` as the local methods get it: one point (dim,) for every row, or one per row."""
    if x0 is None:
        return None
    x0 = np.asarray(x0, dtype=float)
    dim = problem.dim
    if x0.shape[-1] != dim:
        raise FkoptError(f"start point has {x0.shape[-1]} values, the problem has {dim} "
                         f"({', '.join(problem.variable_names)})")
    if x0.ndim == 1:
        return x0
    runs = len(ids)
    if cases is None:
        if x0.ndim != 2:
            raise FkoptError(f"x0 must be one point ({dim},) or one per run (runs, {dim}); got shape {x0.shape}")
        if ids.size and ids.max() >= x0.shape[0]:
            raise FkoptError(f"x0 has {x0.shape[0]} start points (rows are indexed by run id), "
                             f"run {int(ids.max())} has none")
        return x0[ids]
    if x0.ndim == 2 and x0.shape[0] == cases:
        return np.repeat(x0, runs, axis=0)
    if x0.ndim == 3 and x0.shape[:2] == (cases, runs):
        return x0.reshape(cases * runs, dim)
    raise FkoptError(f"x0 must be one point ({dim},), one per case ({cases}, {dim}) or one per case "
                     f"and run ({cases}, {runs}, {dim}); got shape {x0.shape}")


def batch_bytes(rows: int, chunk: int, population: int, iterations: int, dim: int,
                snapshots: int = 0, x_history: bool = False) -> int:
    """Estimated peak bytes of a solve: records of every row (twice, while chunks are joined)
    plus the working arrays of one chunk (about 16 population-sized arrays, the stream buffer)."""
    T = iterations + 1
    per_row = 8 * (4 * T + (T * dim if x_history else 0) + snapshots * population * dim + 2 * dim + 4)
    working = min(rows, chunk) * 8 * (16 * population * dim + 4 * T + min(CHUNK, 1 << 20))
    return 2 * rows * per_row + working


def chunk_size(cases: int, runs: int, population: int, iterations: int, dim: int, *, batch: bool = True,
               chunk_rows: int | None = None, snapshots: int = 0, x_history: bool = False) -> int:
    """Rows per chunk of a solve of ``cases`` x ``runs`` rows; an FkoptError, before anything is
    allocated, when the batch's estimated memory (:func:`batch_bytes`) exceeds :data:`MEMORY_LIMIT`."""
    rows = cases * runs
    size = 1 if not batch else (max(1, CHUNK_POINTS // population) if chunk_rows is None else int(chunk_rows))
    if size < 1:
        raise FkoptError(f"chunk_rows must be at least 1, got {chunk_rows}")
    if chunk_rows is None and rows > size:     # equal chunks: 100 rows by 33 -> 4 x 25, not 33+33+33+1
        size = -(-rows // -(-rows // size))
    need = batch_bytes(rows, size, population, iterations, dim, snapshots, x_history)
    if need > MEMORY_LIMIT:
        raise FkoptError(f"a batch of {rows} runs ({cases} cases x {runs} runs) of {iterations} "
                         f"iterations needs about {need / 2**30:.1f} GiB of memory, more than fkopt's per-solve "
                         f"limit of {MEMORY_LIMIT / 2**30:.1f} GiB; solve fewer cases or runs at a time"
                         + (", or without x_history" if x_history else ""))
    return size


def solve(problem, algorithm: Algorithm, *, population: int = 10, iterations: int = 100,
          runs: int = 1, seed: int | Sequence[int] = 0, target: float | None = None,
          stop_at_target: bool = False, x0=None, run_ids=None, batch: bool = True, snapshots=(),
          x_history: bool = False, chunk_rows: int | None = None,
          params: dict[str, Any] | None = None) -> Result:
    """Minimise ``problem.fitness`` with ``algorithm`` over ``runs`` seeded runs of every case.

    ``algorithm`` is an :class:`Algorithm` object (:func:`fkopt.solve.solve` also takes a registered
    name with ``params``).
    ``seed``: one integer, or (problems with cases) one per case -- see :func:`case_seeds`.
    ``target`` is a fitness threshold: success, iterations/evaluations to reach it are
    reported, and with ``stop_at_target`` each run stops there. ``x0`` is the start point of
    local methods (``nr``, ``lm``): one point for all, one per run id (single target), one per
    case, or one per case and run. ``run_ids`` selects which runs of the seed to compute
    (default 0..runs-1). ``snapshots``: iterations at which the population is kept;
    ``x_history``: keep the best-so-far point of every iteration. ``chunk_rows`` overrides
    :data:`CHUNK_POINTS` // population rows per chunk (the numbers do not depend on it).
    """
    if not isinstance(algorithm, Algorithm):
        raise FkoptError(f"algorithm must be an Algorithm object here, got {type(algorithm).__name__} "
                         "(fkopt.solve resolves names)")
    if params:
        raise FkoptError("pass parameters either to the algorithm object or to solve(), not both")
    algo = algorithm
    validate_budget(population, iterations, runs, algo.local)
    ids = np.arange(runs) if run_ids is None else np.asarray(run_ids, dtype=int)
    cases = getattr(problem, "cases", None)
    seeds = case_seeds(seed, cases)
    n_cases = len(seeds)
    x0_rows = _start_rows(problem, x0, ids, cases)
    rows = n_cases * len(ids)
    size = chunk_size(n_cases, len(ids), int(population), int(iterations), problem.dim, batch=batch,
                      chunk_rows=chunk_rows, snapshots=len(snapshots), x_history=x_history)
    who = _plugins(algo, problem)         # plug-ins are contained and their records checked
    case_of_row = np.repeat(np.arange(n_cases), len(ids))
    run_of_row = np.tile(ids, n_cases)
    seed_of_row = seeds[case_of_row]
    kwargs = dict(population=int(population), iterations=int(iterations), target=target,
                  stop_at_target=stop_at_target, snapshots=snapshots, x_history=x_history)
    parts: list[RunRecord] = []
    times = np.empty(rows)
    for s in range(0, rows, size):
        e = min(s + size, rows)
        sub = problem if cases is None else problem.take(case_of_row[s:e])
        x0_part = x0_rows if x0_rows is None or x0_rows.ndim == 1 else x0_rows[s:e]
        start = time.perf_counter()
        with part(s / rows, e / rows):
            chunk = contained(who, lambda: algo.minimize(sub, streams=RunStreams(seed_of_row[s:e], run_of_row[s:e]),
                                                         x0=x0_part, **kwargs))
        if who is not None:
            check_record(chunk, who, e - s, int(iterations), problem.bounds)
        parts.append(chunk)
        times[s:e] = (time.perf_counter() - start) / (e - s)
    record = parts[0] if len(parts) == 1 else _concatenate(parts)
    shape = (len(ids),) if cases is None else (n_cases, len(ids))
    lead = lambda a: None if a is None else a.reshape(shape + a.shape[1:])   # noqa: E731
    return Result(
        algorithm=algo.name, params=algo.params.model_dump(), variable_names=tuple(problem.variable_names),
        seed=int(seed) if np.ndim(seed) == 0 else None, run_ids=ids, population=int(population),
        iterations=int(iterations), x=lead(record.best_x), fitness=lead(record.best_f),
        history=lead(record.history), x_history=lead(record.x_history),
        evaluation_history=lead(record.evaluation_history), iterations_done=lead(record.iterations_done),
        time_per_run=lead(times), target=target, extras={k: lead(v) for k, v in record.extras.items()},
        snapshots={k: lead(v) for k, v in record.snapshots.items()},
        cases=cases, seeds=None if cases is None else seeds, events=record.events,
    )


# -- plug-in containment ---------------------------------------------------------------------------
def plugin_of(obj) -> str | None:
    """``"module.Class"`` when ``obj``'s class is not fkopt's own (a plug-in), else None."""
    cls = obj if isinstance(obj, type) else type(obj)
    module = getattr(cls, "__module__", "") or ""
    return None if module == "fkopt" or module.startswith("fkopt.") else f"{module}.{cls.__qualname__}"


def _plugins(algo, problem) -> str | None:
    """What to name when a plug-in in this solve fails: the algorithm's and/or the mechanism's."""
    names = []
    if plugin_of(algo):
        names.append(f"algorithm plug-in '{algo.name}' ({plugin_of(algo)})")
    mech = getattr(problem, "mechanism", None)
    if mech is not None and plugin_of(mech):
        names.append(f"mechanism plug-in '{getattr(mech, 'name', '?')}' ({plugin_of(mech)})")
    return " / ".join(names) or None


def contained(who: str | None, call):
    """``call()``; when ``who`` names a plug-in, anything it raises -- an exception, even
    ``SystemExit(0)`` from inside ``iterate`` -- becomes one :class:`FkoptError` line naming it
    (Ctrl-C stays Ctrl-C). fkopt's own code is not wrapped: its failures are bugs to see."""
    if who is None:
        return call()
    try:
        return call()
    except FkoptError as err:
        raise FkoptError(f"{who}: {err}") from None
    except (KeyboardInterrupt, GeneratorExit, MemoryError):
        raise
    except BaseException as err:
        text = (str(err).strip().splitlines() or [""])[0][:300]
        raise FkoptError(f"{who} raised {type(err).__name__}" + (f": {text}" if text else "")
                         + "; the plug-in failed, not fkopt") from None


def check_record(record, who: str, rows: int, iterations: int, bounds) -> None:
    """A plug-in's :class:`RunRecord` must be one fkopt can store: the right shapes, no NaN
    fitness, evaluation counts that are whole, non-negative and never decrease, iterations used
    within the budget, final points inside the bounds. Else one line naming the plug-in."""
    def bad(msg):
        raise FkoptError(f"{who} returned an invalid result: {msg}")
    if not isinstance(record, RunRecord):
        bad(f"a {type(record).__name__}, not a RunRecord")
    bounds = np.asarray(bounds, dtype=float)
    dim, T = len(bounds), iterations + 1
    want = {"best_x": (rows, dim), "best_f": (rows,), "history": (rows, T), "evaluation_history": (rows, T),
            "iterations_done": (rows,)}
    if record.x_history is not None:
        want["x_history"] = (rows, T, dim)
    arrays = {}
    for key, shape in want.items():
        try:
            arrays[key] = a = np.asarray(getattr(record, key), dtype=float)
        except (TypeError, ValueError):
            bad(f"{key} is not numbers")
        if a.shape != shape:
            bad(f"{key} has shape {a.shape}, expected {shape}")
    for key in ("best_f", "history"):
        if np.isnan(arrays[key]).any():
            bad(f"{key} holds NaN fitness values")
    ev = arrays["evaluation_history"]
    if not np.isfinite(ev).all() or (ev < 0).any() or (ev != np.round(ev)).any() or (np.diff(ev, axis=1) < 0).any():
        bad("evaluation counts must be whole numbers >= 0 that never decrease")
    done = arrays["iterations_done"]
    if not np.isfinite(done).all() or (done < 0).any() or (done > iterations).any() or (done != np.round(done)).any():
        bad(f"iterations_done must be whole numbers in 0..{iterations}")
    x = arrays["best_x"]
    found = np.isfinite(arrays["best_f"])
    if np.isnan(x[found]).any():
        bad("best_x holds NaN for a run with a finite fitness")
    tol = 1e-9 * (bounds[:, 1] - bounds[:, 0])
    outside = found[:, None] & ((x < bounds[:, 0] - tol) | (x > bounds[:, 1] + tol))
    if outside.any():
        r, j = map(int, np.argwhere(outside)[0])
        bad(f"run {r}'s point has variable {j + 1} = {x[r, j]:g} outside the bounds "
            f"[{bounds[j, 0]:g}, {bounds[j, 1]:g}]")


def _concatenate(parts: list[RunRecord]) -> RunRecord:
    cat = lambda name: (None if getattr(parts[0], name) is None  # noqa: E731
                        else np.concatenate([getattr(p, name) for p in parts]))
    return RunRecord(
        best_x=cat("best_x"), best_f=cat("best_f"), history=cat("history"), x_history=cat("x_history"),
        evaluation_history=cat("evaluation_history"), iterations_done=cat("iterations_done"),
        extras={k: np.concatenate([p.extras[k] for p in parts]) for k in parts[0].extras},
        snapshots={k: np.concatenate([p.snapshots[k] for p in parts]) for k in parts[0].snapshots},
        events=None if any(p.events is None for p in parts) else tuple(
            np.concatenate(a) for a in zip(*((p.events[0] + off, p.events[1], p.events[2]) for p, off in
                                             zip(parts, np.cumsum([0] + [len(p.best_f) for p in parts[:-1]]))))),
    )


def pick_events(events, rows: np.ndarray):
    """The events of rows ``rows`` (old row numbers, in their new order), renumbered 0, 1, ..."""
    if events is None:
        return None
    r, e, f = events
    new = np.full(int(max(r.max(initial=-1), np.max(rows, initial=-1))) + 1, -1)
    new[np.asarray(rows)] = np.arange(len(rows))
    keep = new[r] >= 0
    nr = new[r[keep]]
    order = np.lexsort((e[keep], nr))
    return nr[order], e[keep][order], f[keep][order]
