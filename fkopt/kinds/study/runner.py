"""A study's tasks, their computation and their merge, for the one runner.

* A task is (pose chunk, algorithm) in ``independent`` mode and (all trajectories, algorithm)
  in ``tracking`` mode. A chunk's poses are the cases of one solve through the experiment's
  solve path (:func:`fkopt.kinds.experiment.runner.solve_cases`): a study is an experiment whose
  cases come from a pose set. :func:`run_task` computes one from a JSON-able payload (so it runs in
  another process or on a Dask worker) and returns JSON-able columns; the seeds come from
  :func:`fkopt.kinds.experiment.runner.task_seed` per pose (or step), so a task's numbers do not
  depend on where, when or next to what it ran.
* :func:`study_plan` hands the tasks to the one runner (:mod:`fkopt.run.tasks`), which
  keeps each finished one as a task file in ``OUT/<paper>/.<name>.partial/tasks/`` with its
  SHA-256, resumes (``fkopt study --resume``) from the files that still pass
  :func:`record_problem`, and publishes them in the result's ``tasks/``.
* A task's record is its rows of the run record and of the timing record (:func:`task_rows`), as
  an experiment's and a suite's are; :func:`merge_study` puts them, pose by pose, into the run record of a
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
from fkopt.run.tasks import TASKS, Plan, Ran, Task as RunnerTask, reason_or_none, work_folder  # noqa: F401 (tests, API)
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
    """Compute one task (in any process); returns its JSON-able record: its rows of the run record
    (``rows``: :mod:`fkopt.run.record`'s columns, one row per (pose, run), poses in the order solved)
    and of the timing record (``timing``: one row per pose, its share of the batched solve), as an
    experiment's and a suite's tasks return theirs."""
    config, mech, poses = _context(payload["config"], payload.get("folder"))
    task = Task(**payload["task"])
    spec = config.algorithms[task.algorithm]
    start = time.perf_counter()
    solved = (_track if config.mode == "tracking" else _independent)(config, mech, poses, spec, task)
    rows, timing = task_rows(config, mech, poses, spec, solved)
    return {"id": task.id, "task": task.__dict__.copy(), "fingerprint": config.fingerprint(),
            "rows": rows, "timing": timing, "wall_s": time.perf_counter() - start, "pid": os.getpid()}


@dataclass
class Solved:
    """One pose's (or tracking step's) runs as a task solved them."""

    pose: int               # index in the pose set
    seed: int               # its task seed
    result: object          # the runs (:class:`fkopt.solve.Result` of one case)
    seconds: float          # its share of the batched solve's wall time
    start: np.ndarray | None = None     # tracking: where each run started, (runs, dim) (NaN: cold swarm)


def task_rows(config: StudyConfig, mech, poses: PoseSet, spec, solved: list[Solved]) -> tuple[dict, dict]:
    """The run record's and the timing record's rows of one task (columns of lists, JSON-able)."""
    runs, m = config.runs, len(solved)
    idx = np.array([s.pose for s in solved], dtype=np.int64)
    stack = lambda f: np.array([f(s.result) for s in solved], dtype=float).reshape(m, runs, -1)   # noqa: E731
    x = stack(lambda r: r.x)
    errors = pose_error(mech, outputs_of(mech, x), poses.targets[idx][:, None, :])
    thr = config.threshold
    cols = {"problem": config.name, "pose": np.repeat(idx, runs), "solver": spec.key,
            "run": np.tile(np.arange(runs), m), "task_seed": np.repeat([s.seed for s in solved], runs).astype(np.int64),
            "final_fitness": stack(lambda r: r.fitness).ravel(), "evaluations": stack(lambda r: r.evaluations).ravel(),
            "iterations_done": stack(lambda r: r.iterations_done).ravel(),
            "iterations_to_threshold": stack(lambda r: r.iterations_to(thr)).ravel(),
            "evaluations_to_threshold": stack(lambda r: r.evaluations_to(thr)).ravel()}
    if config.mode == "tracking":
        start = np.array([np.broadcast_to(s.start, (runs, x.shape[2])) for s in solved], dtype=float).reshape(x.shape)
        cols.update({f"start_{name}": start[:, :, j].ravel() for j, name in enumerate(poses.names)})
    cols.update({f"x_{name}": x[:, :, j].ravel() for j, name in enumerate(poses.names)})
    cols.update({f"abs_error_{name}": errors[:, :, j].ravel() for j, name in enumerate(mech.pose_names)})
    case = "trajectory" if config.mode == "tracking" else "all"
    timing = timing_record("study", {"problem": config.name, "case": case, "pose": idx, "solver": spec.key,
                                     "runs": runs, "seconds": np.array([s.seconds for s in solved], dtype=float),
                                     "mode": BATCH})
    return _columns(run_record("study", cols)), _columns(timing)


def _columns(frame) -> dict:
    """A record's rows as JSON-able columns of lists, without ``kind`` (the merge adds it back)."""
    return {k: v for k, v in frame.to_dict(orient="list").items() if k != "kind"}


def _independent(config, mech, poses: PoseSet, spec, task: Task) -> list[Solved]:
    """The chunk's poses are the cases of one experiment solve (poses x runs rows,
    :func:`fkopt.kinds.experiment.runner.solve_cases`), each pose with its own seed."""
    seeds = [task_seed(config.seed, i, spec.key) for i in range(task.start, task.stop)]
    problem = make_problem(config, mech, poses.inputs[task.start:task.stop])
    t0 = time.perf_counter()
    r = solve_cases(config, spec, problem, seeds, x0=start_point(spec, mech))
    seconds = (time.perf_counter() - t0) / len(seeds)     # amortised over the poses
    return [Solved(task.start + j, seeds[j], r.case(j), seconds) for j in range(len(seeds))]


def _warm_boxes(mech, prev: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Per row, the box of +-radius of the workspace around its previous solution, clipped."""
    lo, hi = mech.bounds[:, 0], mech.bounds[:, 1]
    half = radius * (hi - lo)
    return np.maximum(lo, prev - half), np.minimum(hi, prev + half)


def _track(config, mech, poses: PoseSet, spec, task: Task) -> list[Solved]:
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
    solved = []
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
            solved.append(Solved(i, seeds[c], r, seconds, np.asarray(starts[c], dtype=float)))
            prev[j] = np.array(r.x, dtype=float)
    return solved


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
#: Record columns that may be NaN: where a run never reached the threshold, a cold swarm's start.
MAY_BE_NAN = ("iterations_to_threshold", "evaluations_to_threshold", "start_")
#: Record columns that may be negative: points (the rest are fitnesses, counts and errors).
SIGNED = ("x_", "start_")


def record_problem(rec, ident: str, task: Task, config: StudyConfig, mech, poses: PoseSet) -> str | None:
    """Why ``rec`` (the task file ``ident``) is not the finished ``task`` of this study; None when it is:
    the run record's columns of this study, one row per (pose, run) of the task's poses (each once,
    in order unless tracking), its solver, and numbers where numbers belong."""
    if not isinstance(rec, dict):
        return f"holds a JSON {type(rec).__name__}, not a task record"
    if rec.get("id") != ident:
        return f"its id {str(rec.get('id'))[:40]!r} is not its file name {ident!r}"
    if rec.get("task") != task.__dict__:
        return "its task (algorithm, poses) is not the one its id names"
    return reason_or_none(lambda: _record_problem(rec, task, config, mech, poses))


def _record_problem(rec: dict, task: Task, config: StudyConfig, mech, poses: PoseSet) -> str | None:
    runs, n = config.runs, task.stop - task.start
    rows, timing = rec["rows"], rec["timing"]
    names = ["problem", "pose", "solver", "run", "task_seed", "final_fitness", "evaluations", "iterations_done",
             "iterations_to_threshold", "evaluations_to_threshold",
             *([f"start_{v}" for v in poses.names] if config.mode == "tracking" else []),
             *(f"x_{v}" for v in poses.names), *(f"abs_error_{v}" for v in mech.pose_names)]
    if not isinstance(rows, dict) or sorted(rows) != sorted(names):
        return "rows: not the run record's columns of a study"
    if any(not isinstance(v, list) or len(v) != n * runs for v in rows.values()):
        return f"rows: not {n * runs} rows (one per pose and run)"
    pose = rows["pose"]
    order = pose[::runs]
    if pose != [p for p in order for _ in range(runs)] or sorted(order) != list(range(task.start, task.stop)) \
            or (config.mode == "independent" and order != sorted(order)):
        return "pose: not the task's poses, each once"
    if rows["run"] != list(range(runs)) * n or rows["solver"] != [task.label] * len(pose) \
            or rows["problem"] != [config.name] * len(pose):
        return "run, solver, problem: not this task's"
    for key in ("pose", "run", "task_seed"):
        if not all(type(v) is int for v in rows[key]):
            return f"{key}: not integers"
    for key in names[5:]:
        if any(isinstance(v, (str, bool)) or v is None for v in rows[key]):
            return f"{key}: not numbers"
        value = np.asarray(rows[key], dtype=float)
        nan_ok = key.startswith(MAY_BE_NAN)
        finite = np.isfinite(value) | (np.isnan(value) if nan_ok else False)
        if not finite.all() or (not key.startswith(SIGNED) and (value[np.isfinite(value)] < 0).any()):
            return f"{key}: not non-negative finite numbers" + (" (or NaN)" if nan_ok else "")
    if not isinstance(timing, dict) or timing.get("pose") != order:
        return "timing: not one row per pose of the task"
    seconds = np.asarray(timing["seconds"], dtype=float)
    if seconds.shape != (n,) or not (np.isfinite(seconds) & (seconds >= 0)).all():
        return "timing.seconds: not non-negative finite numbers"
    if not math.isfinite(float(rec["wall_s"])) or float(rec["wall_s"]) < 0:
        return "wall_s: not a non-negative finite number"
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


def study_tables(config: StudyConfig, records: dict[str, dict]):
    """The run record, the timing record and each algorithm's wall time (the sum of its tasks'),
    from the task records: algorithm by algorithm, pose by pose (from 0, the index its seed
    takes), run by run."""
    frames, timings, walls = [], [], {}
    for a, spec in enumerate(config.algorithms):
        mine = [rec for rec in records.values() if rec["task"]["algorithm"] == a]     # in plan order
        rows = concat([run_record("study", rec["rows"]) for rec in mine])
        frames.append(rows.sort_values(["pose", "run"], kind="stable"))
        timing = concat([timing_record("study", rec["timing"]) for rec in mine])
        timings.append(timing.sort_values("pose", kind="stable"))
        walls[spec.key] = sum(float(rec["wall_s"]) for rec in mine)
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
    return Plan([RunnerTask(t.id, payload(config, t, folder), _label(config, t)) for t in tasks],
                run_task, fingerprint=config.fingerprint(), stored=True, keep=True,
                check=lambda task, rec: record_problem(rec, task.id, by_id[task.id], config, mech, poses),
                context=_Context(mech, poses, time.perf_counter() - started), name=f"study '{config.name}'")


def merge_study(config: StudyConfig, plan: Plan, ran: Ran, *, source: str | None = None, **_) -> RunResult:
    """The study's :class:`~fkopt.run.result.RunResult`: run and timing records from its task
    records, its pose set in ``own`` (:class:`StudyOwn`)."""
    merging = time.perf_counter()
    ctx: _Context = plan.context
    runs, timing, walls = study_tables(config, ran.records)
    wall = ctx.prepared_s + ran.wall_s + (time.perf_counter() - merging)   # however long before it was planned
    return RunResult(config, runs, timing, None, StudyOwn(ctx.mech, ctx.poses, walls), wall, source,
                     list(ran.computed))
