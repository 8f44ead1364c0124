"""A study's tasks, their computation and their merge, for the one runner.

* A task is (pose chunk, algorithm) in ``independent`` mode and (all trajectories, algorithm)
  in ``tracking`` mode. A chunk's poses are the cases of one solve through the experiment's
  solve path (:func:`fkopt.kinds.experiment.runner.solve_cases`): a study is an experiment whose
  cases come from a pose set. :func:`run_task` computes one from a JSON-able payload (so it runs in
  another process or on a Dask worker) and returns plain lists; the seeds come from
  :func:`fkopt.kinds.experiment.runner.task_seed` per pose (or step), so a task's numbers do not
  depend on where, when or next to what it ran.
* :func:`study_plan` hands the tasks to the one runner (:mod:`fkopt.run.tasks`), which
  keeps each finished one as a task file in ``OUT/<paper>/.<name>.partial/tasks/`` with its
  SHA-256, resumes (``fkopt study --resume``) from the files that still pass
  :func:`record_problem`, and publishes them in the result's ``tasks/``.
* :func:`merge_study` reads the records back into the run record of a
  :class:`~fkopt.run.result.RunResult` (the pose set in its ``own`` slot, :class:`StudyOwn`),
  which :mod:`fkopt.kinds.study.reports` writes (through :mod:`fkopt.run.writers`).
"""
from __future__ import annotations

import json
import math
import os
import re
import time
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path
from typing import Callable

import numpy as np

from fkopt.errors import FkoptError
from fkopt.run.config_base import files_folder
from fkopt.run.solving import (build_mechanism, make_problem, outputs_of, pose_error, solve_cases, start_point,
                               task_seed)
from fkopt.problems import BoxedProblem
from fkopt.run.record import BATCH, concat, run_record, timing_record
from fkopt.run.result import RunResult
from fkopt.solve import make_algorithm, pick_events
from fkopt.numerics.streams import case_seed
from fkopt.run.tasks import TASKS, Plan, Ran, Task as RunnerTask, work_folder  # noqa: F401 (tests, API)
from fkopt.kinds.study.config import StudyConfig
from fkopt.kinds.study.poses import PoseSet, build_poses


# -- tasks ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Task:
    algorithm: int      # index into config.algorithms
    label: str          # the algorithm's label (its key)
    chunk: int          # chunk index (0 for a whole trajectory)
    start: int          # first pose index
    stop: int           # one past the last pose index

    @property
    def id(self) -> str:
        slug = re.sub(r"[^A-Za-z0-9_.+-]", "_", self.label)
        return f"a{self.algorithm:02d}-{slug}-c{self.chunk:05d}"


def plan_tasks(config: StudyConfig, n_poses: int) -> list[Task]:
    """All tasks of a study, chunk by chunk (every algorithm of a chunk before the next)."""
    if config.mode == "tracking":
        return [Task(a, spec.key, 0, 0, n_poses) for a, spec in enumerate(config.algorithms)]
    out = []
    for c, start in enumerate(range(0, n_poses, config.chunk)):
        stop = min(start + config.chunk, n_poses)
        out += [Task(a, spec.key, c, start, stop) for a, spec in enumerate(config.algorithms)]
    return out


def validate_study(config: StudyConfig, folder: Path | None = None):
    """Build everything a run needs without running it (bad input fails before any work);
    relative files resolve in ``folder`` (:func:`fkopt.kinds.experiment.runner.build_mechanism`)."""
    mech = build_mechanism(config, folder)
    poses = build_poses(config, mech)
    for spec in config.algorithms:
        if getattr(make_algorithm(spec.name, spec.params), "every_solution", False):
            raise FkoptError(f"algorithms[{spec.key}].params.solutions: 'all' (every solution of a pose) runs in "
                             "experiment files, which write solutions.csv; a study takes one answer per run "
                             "(allowed here: one)")
        start_point(spec, mech)
    make_problem(config, mech, poses.inputs[0])
    return mech, poses


@lru_cache(maxsize=4)
def _context(config_json: str, folder: str | None = None):
    config = StudyConfig(**json.loads(config_json))
    mech, poses = validate_study(config, Path(folder) if folder else None)
    return config, mech, poses


def payload(config: StudyConfig, task: Task, folder: Path | None = None) -> dict:
    return {"config": config.model_dump_json(), "task": task.__dict__.copy(),
            "folder": None if folder is None else str(folder)}


def run_task(payload: dict) -> dict:
    """Compute one task (in any process); returns a JSON-able record."""
    config, mech, poses = _context(payload["config"], payload.get("folder"))
    task = Task(**payload["task"])
    spec = config.algorithms[task.algorithm]
    start = time.perf_counter()
    if config.mode == "tracking":
        rec = _track(config, mech, poses, spec, task)
    else:
        rec = _independent(config, mech, poses, spec, task)
    rec.update({"id": task.id, "task": task.__dict__.copy(), "fingerprint": config.fingerprint(),
                "wall_s": time.perf_counter() - start, "pid": os.getpid()})
    return rec


def _collect(rec: dict, r, thr: float, seconds: float) -> None:
    rec["fitness"].append(r.fitness.tolist())
    rec["evaluations"].append(r.evaluations.tolist())
    rec["iterations_done"].append(r.iterations_done.tolist())
    rec["iterations_to"].append(r.iterations_to(thr).tolist())
    rec["evaluations_to"].append(r.evaluations_to(thr).tolist())
    rec["x"].append(r.x.tolist())
    rec["time_s"].append(seconds)


def _empty(task: Task) -> dict:
    return {"poses": list(range(task.start, task.stop)), "seeds": [], "fitness": [], "evaluations": [],
            "iterations_done": [], "iterations_to": [], "evaluations_to": [], "x": [], "time_s": []}


def _independent(config, mech, poses: PoseSet, spec, task: Task) -> dict:
    """The chunk's poses are the cases of one experiment solve (poses x runs rows,
    :func:`fkopt.kinds.experiment.runner.solve_cases`), each pose with its own seed."""
    rec = _empty(task)
    seeds = [task_seed(config.seed, i, spec.key) for i in range(task.start, task.stop)]
    problem = make_problem(config, mech, poses.inputs[task.start:task.stop])
    t0 = time.perf_counter()
    r = solve_cases(config, spec, problem, seeds, x0=start_point(spec, mech))
    seconds = (time.perf_counter() - t0) / len(seeds)     # amortised over the poses
    rec["seeds"] = seeds
    for j in range(len(seeds)):
        _collect(rec, r.case(j), config.threshold, seconds)
    return rec


def _warm_boxes(mech, prev: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Per row, the box of +-radius of the workspace around its previous solution, clipped."""
    lo, hi = mech.bounds[:, 0], mech.bounds[:, 1]
    half = radius * (hi - lo)
    return np.maximum(lo, prev - half), np.minimum(hi, prev + half)


def _track(config, mech, poses: PoseSet, spec, task: Task) -> dict:
    """Solve every trajectory in order; each step warm-starts from the previous step's solution.

    Step t of all trajectories that have one is a single solve, trajectory j being case j with
    the seed ``task_seed(seed, i, label)`` of its pose's index i in the pose set. A cold step
    (the first; every step without ``warm_start``) and a local method are one solve of those
    cases x runs rows (local methods start at the previous solution of their run). A warm swarm
    searches a box around each run's previous solution: every (trajectory, run) is then a case
    of a :class:`fkopt.problems.BoxedProblem` (one box each), run k of trajectory j drawing from
    ``case_seed(seed of j's step, k)`` -- so a trajectory gives the same numbers alone or
    batched with others.
    """
    rec = _empty(task)
    rec["poses"], rec["start"] = [], []
    algo = make_algorithm(spec.name, spec.params)
    runs, dim = config.runs, len(mech.unknown_names)
    x0 = start_point(spec, mech)
    segments = poses.segments
    prev = np.full((len(segments), runs, dim), np.nan)
    for t in range(max(stop - start for start, stop in segments)):
        active = [j for j, (start, stop) in enumerate(segments) if start + t < stop]
        idx = [segments[j][0] + t for j in active]
        seeds = [task_seed(config.seed, i, spec.key) for i in idx]
        warm = spec.warm_start and t > 0
        t0 = time.perf_counter()
        # where each (trajectory, run) starts: its previous solution, or the cold start (NaN: none)
        starts = prev[active] if warm else np.broadcast_to(np.nan if x0 is None else x0, (len(active), runs, dim))
        if algo.local or not warm:
            r = solve_cases(config, spec, make_problem(config, mech, poses.inputs[idx]), seeds,
                            x0=starts if warm else x0)
            results = [r.case(c) for c in range(len(active))]
        else:
            lo, hi = _warm_boxes(mech, starts.reshape(-1, dim), config.tracking.radius)
            target = make_problem(config, mech, np.repeat(poses.inputs[idx], runs, axis=0))
            boxed = BoxedProblem(target, lo, hi)
            rb = solve_cases(config, spec, boxed, [case_seed(s, k) for s in seeds for k in range(runs)], runs=1)
            x = boxed.to_x(rb.x[:, 0]).reshape(len(active), runs, dim)
            results = [_runs_of(rb, x[c], slice(c * runs, (c + 1) * runs)) for c in range(len(active))]
        seconds = (time.perf_counter() - t0) / len(active)    # amortised over the trajectories
        for c, (j, i, r) in enumerate(zip(active, idx, results)):
            rec["poses"].append(i)
            rec["seeds"].append(seeds[c])
            rec["start"].append(np.asarray(starts[c], dtype=float).tolist())
            _collect(rec, r, config.threshold, seconds)
            prev[j] = np.array(r.x, dtype=float)
    return rec


def _runs_of(r, x: np.ndarray, rows: slice):
    """Rows ``rows`` of a result of (trajectory, run) cases x 1 run, read as one target's runs."""
    one = lambda a: None if a is None else a[rows, 0]   # noqa: E731
    return replace(r, x=x, fitness=one(r.fitness), history=one(r.history), x_history=one(r.x_history),
                   evaluation_history=one(r.evaluation_history), iterations_done=one(r.iterations_done),
                   time_per_run=one(r.time_per_run), extras={}, snapshots={}, cases=None, seeds=None,
                   run_ids=np.arange(len(x)),
                   events=pick_events(r.events, np.arange(r.runs * (rows.start or 0), r.runs * rows.stop,
                                                          r.runs * (rows.step or 1))))


# -- checking a reused record ------------------------------------------------------------------
def record_problem(rec, ident: str, task: Task, config: StudyConfig, dim: int) -> str | None:
    """Why ``rec`` (the task file ``ident``) is not the finished ``task`` of this study; None when it is."""
    if not isinstance(rec, dict):
        return f"holds a JSON {type(rec).__name__}, not a task record"
    if rec.get("id") != ident:
        return f"its id {str(rec.get('id'))[:40]!r} is not its file name {ident!r}"
    if rec.get("task") != task.__dict__:
        return "its task (algorithm, poses) is not the one its id names"
    n = task.stop - task.start if config.mode == "independent" else None
    try:
        poses = np.asarray(rec["poses"])
        if poses.ndim != 1 or (n is not None and len(poses) != n) or not np.issubdtype(poses.dtype, np.integer):
            return "poses: not the task's pose indices"
        if poses.size and (poses.min() < task.start or poses.max() >= task.stop):
            return "poses: outside the task's poses"
        rows = len(poses)
        shapes = {k: (rows, config.runs) for k in ("fitness", "evaluations", "iterations_done",
                                                     "iterations_to", "evaluations_to")}
        shapes["x"] = (rows, config.runs, dim)
        shapes["time_s"] = (rows,)
        shapes["seeds"] = (rows,)
        if config.mode == "tracking":
            shapes["start"] = (rows, config.runs, dim)
        #: NaN only where a run never reached the threshold; every other number finite
        may_be_nan = {"iterations_to", "evaluations_to", "start"}
        for key, shape in shapes.items():
            if any(isinstance(v, (str, bool)) for v in np.asarray(rec[key], dtype=object).ravel()):
                return f"{key}: not numbers"
            value = np.asarray(rec[key], dtype=float)
            if value.shape != shape:
                return f"{key}: shape {value.shape}, expected {shape}"
            finite = np.isfinite(value) | (np.isnan(value) if key in may_be_nan else False)
            if not finite.all() or (key != "x" and key != "start" and (value[np.isfinite(value)] < 0).any()):
                return f"{key}: not non-negative finite numbers" + (" (or NaN)" if key in may_be_nan else "")
        if not math.isfinite(float(rec["wall_s"])) or float(rec["wall_s"]) < 0:
            return "wall_s: not a non-negative finite number"
    except KeyError as err:
        return f"field {err.args[0]!r} is missing"
    except (TypeError, ValueError):
        return f"{key}: not numbers" if "key" in locals() else "poses: not numbers"
    return None


# -- merged result -------------------------------------------------------------------------------
@dataclass
class StudyOwn:
    """What only a study has (the :attr:`fkopt.run.result.RunResult.own` slot): its mechanism,
    its pose set (points, targets, grid axes, trajectories) and each algorithm's wall time (the
    sum of its tasks'); the runs themselves are the run record's rows."""

    mechanism: object
    poses: PoseSet
    solve_s: dict[str, float]


def study_tables(config: StudyConfig, mech, poses: PoseSet, records: dict[str, dict]):
    """The run record, the timing record and each algorithm's wall time, from the task records:
    algorithm by algorithm, pose by pose (from 0, the index its seed takes), run by run."""
    n, runs, dim = len(poses), config.runs, len(mech.unknown_names)
    tasks = plan_tasks(config, n)
    case = "trajectory" if config.mode == "tracking" else "all"
    frames, timings, walls = [], [], {}
    for a, spec in enumerate(config.algorithms):
        arr = {k: np.full((n, runs), np.nan) for k in ("fitness", "evaluations", "iterations_done",
                                                         "iterations_to", "evaluations_to")}
        x = np.full((n, runs, dim), np.nan)
        start = np.full((n, runs, dim), np.nan) if config.mode == "tracking" else None
        seeds = np.zeros(n, dtype=np.int64)
        time_s = np.zeros(n)
        wall = 0.0
        for task in (t for t in tasks if t.algorithm == a):
            rec = records[task.id]
            idx = np.asarray(rec["poses"], dtype=int)
            for k in arr:
                arr[k][idx] = np.asarray(rec[k], dtype=float)
            x[idx] = np.asarray(rec["x"], dtype=float)
            if start is not None:
                start[idx] = np.asarray(rec["start"], dtype=float)
            seeds[idx] = rec["seeds"]
            time_s[idx] = rec["time_s"]
            wall += rec["wall_s"]
        errors = pose_error(mech, outputs_of(mech, x), poses.targets[:, None, :])
        cols = {"problem": config.name, "pose": np.repeat(np.arange(n), runs), "solver": spec.key,
                "run": np.tile(np.arange(runs), n), "task_seed": np.repeat(seeds, runs),
                "final_fitness": arr["fitness"].ravel(), "evaluations": arr["evaluations"].ravel(),
                "iterations_done": arr["iterations_done"].ravel(), "iterations_to_threshold": arr["iterations_to"].ravel(),
                "evaluations_to_threshold": arr["evaluations_to"].ravel()}
        if start is not None:
            cols.update({f"start_{name}": start[:, :, j].ravel() for j, name in enumerate(poses.names)})
        cols.update({f"x_{name}": x[:, :, j].ravel() for j, name in enumerate(poses.names)})
        cols.update({f"abs_error_{name}": errors[:, :, j].ravel() for j, name in enumerate(mech.pose_names)})
        frames.append(run_record("study", cols))
        # each pose's (or tracking step's) wall time over its runs: its share of the chunk's batched solve
        timings.append(timing_record("study", {"problem": config.name, "case": case, "pose": np.arange(n),
                                               "solver": spec.key, "runs": config.runs, "seconds": time_s,
                                               "mode": BATCH}))
        walls[spec.key] = wall
    return concat(frames), concat(timings), walls


# -- the one runner's view of a study -------------------------------------------------------------
@dataclass
class _Context:
    mech: object
    poses: PoseSet
    prepared_s: float     # building the plan (validation)


def _label(config: StudyConfig, task: Task) -> str:
    where = (f"poses {task.start}-{task.stop - 1}" if config.mode == "independent"
             else f"{task.stop - task.start} steps")
    return f"{task.label} · {where}"


def study_plan(config: StudyConfig, source: str | None = None, timing: bool = True) -> Plan:
    """A study as tasks of the one runner: kept as task files (resume), published in ``tasks/``
    (its times are each task's own wall time: no separate timing tasks)."""
    started = time.perf_counter()
    folder = files_folder(config, source)        # relative files resolve beside the config
    mech, poses = validate_study(config, folder)
    tasks = plan_tasks(config, len(poses))
    by_id = {t.id: t for t in tasks}
    dim = len(mech.unknown_names)
    return Plan([RunnerTask(t.id, payload(config, t, folder), _label(config, t)) for t in tasks],
                run_task, fingerprint=config.fingerprint(), stored=True, keep=True,
                check=lambda task, rec: record_problem(rec, task.id, by_id[task.id], config, dim),
                context=_Context(mech, poses, time.perf_counter() - started), name=f"study '{config.name}'")


def merge_study(config: StudyConfig, plan: Plan, ran: Ran, *, source: str | None = None, **_) -> RunResult:
    """The study's :class:`~fkopt.run.result.RunResult`: run and timing records from its task
    records, its pose set in ``own`` (:class:`StudyOwn`)."""
    merging = time.perf_counter()
    ctx: _Context = plan.context
    runs, timing, walls = study_tables(config, ctx.mech, ctx.poses, ran.records)
    wall = ctx.prepared_s + ran.wall_s + (time.perf_counter() - merging)   # however long before it was planned
    return RunResult(config, runs, timing, None, StudyOwn(ctx.mech, ctx.poses, walls), wall, source,
                     list(ran.computed))
