"""The one timing method of fkopt's reports: the papers' mode, one run at a time.

The papers time one run of an algorithm after another (MATLAB or Java loops). fkopt's batch mode
advances all runs of a task together, and the batch's wall time divided by the runs (the
*amortised* time, kept in ``timing.csv`` as ``amortised_ms_per_run`` for information) answers a
different question: it favours algorithms whose per-iteration cost is numpy overhead, and it can
reverse a comparison. Every timing figure and timing claim of fkopt's reports therefore uses the
times measured here:

* **Order**: the algorithms of a case are timed interleaved, run 0 of each, then run 1 of each
  (A B A B ...), in one process (:func:`time_case`): one planned timing task per timed case,
  run after every solve of the experiment, in this process, with nothing else running
  (:attr:`fkopt.run.tasks.Plan.timed`).
* **Mode**: each sampled run is solved alone (``solve(..., batch=False, run_ids=[k])``, the same
  stream as in the batch, so the same numbers) and timed with ``time.perf_counter`` around that
  call; one untimed short warm-up solve precedes the task's first timed run.
* **Sample**: runs ``0 .. n-1`` of each (case, algorithm) task with
  ``n = max(1, ceil(TIMING_RUNS / cases))`` (all runs if fewer), on the first ``TIMING_RUNS``
  cases of the experiment; so a single-case experiment times 8 runs per algorithm, a 50-pose
  experiment one run on each of 8 poses. A task stops adding runs once it has spent
  ``TIMING_BUDGET_S`` seconds on timed runs, but never with fewer than ``TIMING_MIN_RUNS``
  (5: the fewest with which a rank test can reach p < 0.05). This keeps ``make reproduce``
  within its budget: the budget only shortens the samples of tasks whose runs take more than
  ``TIMING_BUDGET_S / TIMING_RUNS`` each, and those still get 5 runs.
* **Path**: every timed run runs on the numpy reference path (``FKOPT_NUMERICS=numpy``,
  :func:`fkopt.numerics.path.forced`), whatever path solved the runs. Compiled kernels exist for
  some algorithms and mechanisms only (PSO, ABC and GABC on 3-RPS; the one-pose IK loop), and a
  time claim compares algorithms, not how much of each fkopt compiled: with ABC compiled and
  ACO not, "ABC takes longer than ACO" would be judged on fkopt's engineering. The runs are the
  same on both paths (bit for bit, tests/test_numerics.py); only their time differs, and the
  compiled path's speed is measured by ``fkopt bench`` against its peers.
* **Spread**: the sample's median and quartiles are reported; two algorithms' times differ only
  if a two-sided Mann-Whitney rank test over the sampled runs rejects equality at alpha = 0.05
  (verdict *within noise* otherwise; see :mod:`fkopt.reproduce.claims`).

Per-run times go to ``timing_runs.csv``; the summary to ``timing.csv``.
"""
from __future__ import annotations

import math
import time

import numpy as np

from fkopt.numerics.path import forced
from fkopt.solve import solve

#: Timed runs per algorithm (spread over the first TIMING_RUNS cases; see the module docstring).
TIMING_RUNS = 8
#: A task times at least this many runs (if it has them) ...
TIMING_MIN_RUNS = 5
#: ... and stops adding runs once its timed runs took this long (s).
TIMING_BUDGET_S = 1.5


def sample_plan(n_cases: int, runs: int) -> tuple[int, int]:
    """(cases timed, runs timed per case) of an experiment."""
    cases = min(n_cases, TIMING_RUNS)
    return cases, min(runs, max(1, math.ceil(TIMING_RUNS / n_cases)))


def time_case(config, timed: list[tuple], per: int) -> list[np.ndarray]:
    """Seconds of the timed runs ``0 .. per-1`` of every algorithm of one case, as
    ``timed = [(spec, problem, seed), ...]``: one array per algorithm, in that order (shorter
    than ``per`` once an algorithm has its sample: :data:`TIMING_BUDGET_S`).

    The timed runs of a case's algorithms are **interleaved** (A0 B0 A1 B1 ...: round k times run k
    of every algorithm still sampling), in this one process, so that a slow period of the machine
    falls on every algorithm alike instead of on whichever was timed then. One planned timing task
    of an experiment (:func:`fkopt.kinds.experiment.runner.experiment_plan`) is one call.
    """
    with forced("numpy"):            # one implementation path for every algorithm (module docstring)
        return _time_case(config, timed, per)


def _time_case(config, timed: list[tuple], per: int) -> list[np.ndarray]:
    kwargs = [_kwargs(config, spec, problem, seed) for spec, problem, seed in timed]
    for (spec, problem, _), kw in zip(timed, kwargs):
        solve(problem, spec.name, iterations=2, run_ids=[0], **kw)   # warm-up, untimed
    seconds: list[list[float]] = [[] for _ in timed]
    for k in range(per):
        for (spec, problem, _), kw, s in zip(timed, kwargs, seconds):
            if len(s) >= TIMING_MIN_RUNS and sum(s) > TIMING_BUDGET_S:
                continue   # this task has its sample; the others keep alternating
            start = time.perf_counter()
            solve(problem, spec.name, iterations=spec.iterations or config.iterations, run_ids=[k], **kw)
            s.append(time.perf_counter() - start)
    return [np.array(s) for s in seconds]


def _kwargs(config, spec, problem, seed: int) -> dict:
    return dict(population=spec.population or config.population, runs=1, seed=seed,
                target=config.threshold, stop_at_target=config.stop_at_threshold,
                x0=None if spec.start is None else _start(spec, problem), batch=False, params=spec.params)


def _start(spec, problem) -> np.ndarray:
    return np.asarray([spec.start[n] for n in problem.variable_names], dtype=float)
