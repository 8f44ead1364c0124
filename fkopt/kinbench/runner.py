"""Run a suite on the experiment layer's one solve path.

One task is one (problem, solver): every pose of every selected set of the problem is a case of
one batched problem (:func:`fkopt.kinds.experiment.runner.make_problem`), solved by
:func:`fkopt.kinds.experiment.runner.solve_cases` for ``runs`` runs in one call. Case seeds:
:func:`fkopt.kinds.experiment.runner.task_seed` of (suite seed, pose index within its set,
``"<problem>/<set>/<solver label>"``); run k of a case is its k-th child stream
(:mod:`fkopt.numerics.streams`), so a task's numbers do not depend on which other problems, sets,
solvers or workers there are. The tasks go to the one runner (:mod:`fkopt.run.tasks`,
:func:`suite_plan`): in this process, in local worker processes or on Dask, each kept as a task
file with its SHA-256 until the suite is written, so ``--resume`` continues after a kill.

Budget: a run of a problem of dimension n may spend ``B = budget_per_dim * n`` fitness
evaluations (an analytic Jacobian counts as one, as everywhere in fkopt). The solver gets
``ceil(B / population)`` iterations and stops once below the smallest target; every measure is
read from the run's cumulative evaluation counts at the last iteration within ``B``.
"""
from __future__ import annotations

import hashlib
import json
import os
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.errors import FkoptError
from fkopt.run.record import BATCH, concat, run_record, timing_record
from fkopt.run.result import RunResult
from fkopt.run.config_base import files_folder, numeric_fields, RunConfig
from fkopt.run.solving import make_problem, solve_cases, start_point, task_seed
from fkopt.run.tasks import Plan, Ran, Task, run_tasks
from fkopt.solve import chunk_size
from fkopt.kinbench.clock import (is_ik, make_solver, run_clock, run_throughput, track_arm, track_cases,
                                  track_settings)
from fkopt.kinbench import branch_tracks
from fkopt.kinbench.answer_checks import clock_record_problem
from fkopt.kinbench.budget import at_budget, budget_of, target_column
from fkopt.kinbench.config import SuiteConfig, suite_from_dict
from fkopt.kinbench.outside import digest, read_outside
from fkopt.kinbench.posesets import load_pose_sets, problem_mechanism, targets_of
from fkopt.kinbench.traces import suite_trace, task_trace
from fkopt.adapters.field import NotApplicable
from fkopt.kinbench.submissions import read_submission


def task_config(config: SuiteConfig, problem, solver, dim: int) -> RunConfig:
    """The experiment layer's settings of one (problem, solver) task."""
    budget = budget_of(config, dim)
    pop = solver.population or config.population
    cfg = RunConfig(name=problem.name, mechanism=problem.mechanism, objective=problem.objective,
                    algorithms=[solver.model_dump(exclude={"track"})], population=config.population,
                    iterations=solver.iterations or max(1, math.ceil(budget / pop)), runs=config.runs_of(solver.key),
                    seed=config.seed, threshold=min(config.targets), stop_at_threshold=True)
    return cfg


@dataclass
class SuiteOwn:
    """What only a suite has (the :attr:`fkopt.run.result.RunResult.own` slot): its pose sets'
    manifest, where its relative files are, and the clock track's answers and throughput with the
    load averages and entries' settings meta.json records (kinbench v3)."""

    manifest: dict | None = None
    files: Path | None = None            # where its relative files are (pose sets, outside logs)
    answers: pd.DataFrame | None = None  # answers.csv.gz: every answer of the clock track (v3)
    throughput: pd.DataFrame | None = None   # throughput.csv: queries/s per batch size (v3)
    load_avg: dict | None = None         # the load averages at the clock track's start and end (meta.json)
    entries: dict | None = None          # the clock track's entries' settings (meta.json)
    branch_answers: dict | None = None   # the all-solutions and paths tracks' answers (fkopt.kinbench.branch_tracks)


def _cases(config: SuiteConfig, sets: dict, problem, solver=None):
    """(set name, pose index, point) of every case of ``problem``, in set then pose order; of
    the cells of ``solver``'s subset when it has one (its sets, its first ``poses`` poses)."""
    sub = config.subset_of(solver.key) if solver is not None else None
    names = sub.sets if sub is not None and sub.sets is not None else config.sets
    keep = sub.poses if sub is not None and sub.poses is not None else None
    return [(name, i, p) for name in config.sets if name in names
            for i, p in enumerate(sets[(problem.name, name)][:keep])]


def instances_of(config: SuiteConfig, sets: dict) -> set[tuple[str, str, int]]:
    """Every (problem, set, pose) the suite selects."""
    return {(p.name, name, i) for p in config.problems for name, i, _ in _cases(config, sets, p)}


def validate_suite(config: SuiteConfig, plan: Plan | None = None) -> int:
    """Everything a suite needs, built without solving (the pose sets its plan loaded, else
    loaded here); the estimated bytes of the run."""
    files = plan.context.files if plan is not None else files_folder(config)
    sets = plan.context.sets if plan is not None else load_pose_sets(config, files)[0]
    need = 0
    dims: dict[str, int] = {}
    for problem in config.problems:
        mech, _ = problem_mechanism(problem, files)
        cases = _cases(config, sets, problem)
        if not cases:
            raise FkoptError(f"problems[{problem.name}]: no poses in sets {', '.join(config.sets)}")
        dim = dims[problem.name] = len(mech.unknown_names)
        if not np.all(mech.in_bounds(np.stack([c[2] for c in cases]))):
            raise FkoptError(f"problems[{problem.name}]: a frozen pose lies outside mechanism.bounds")
        for solver in config.solvers:
            if not config.runs_problem(solver.key, problem.name):
                continue
            where = f"solvers[{solver.key}]"
            cases = _cases(config, sets, problem, solver)
            try:
                cfg = task_config(config, problem, solver, dim)
                pop = solver.population or config.population
                chunk_size(len(cases), cfg.runs, pop, cfg.iterations, dim)
                # a one-iteration probe on one pose: an unknown solver or parameter, a bad start, a
                # solver that cannot take this problem (nr on a redundant arm) fail here, before any work
                probe = cfg.model_copy(update={"runs": 1, "iterations": 1, "stop_at_threshold": False})
                spec = cfg.algorithms[0]
                solve_cases(probe, spec, make_problem(probe, mech, targets_of(mech, cases[0][2][None])), [0],
                            x0=start_point(spec, mech))
            except FkoptError as err:
                raise FkoptError(f"{where} on problems[{problem.name}]: {err}") from None
            T = cfg.iterations + 1
            need = max(need, len(cases) * cfg.runs * 8 * (3 * T + 2 * dim) * 2)
    if config.outside:            # read and checked now, so a bad file fails before any solve
        instances = instances_of(config, sets)
        for k in range(len(config.outside)):
            read_outside(config, k, dims, instances, files)
            digest(config, config.outside[k], files)   # every file meta.json will hash, read bounded now
    tracks = plan.context.tracks if plan is not None else track_cases(config, sets, files)
    for p, _ in tracks:
        validate_track(config, p, files)
    read_submissions(config, tracks, files)
    branch_tracks.validate(config, files)
    return need


def read_submissions(config: SuiteConfig, tracks, files: Path | None = None) -> pd.DataFrame | None:
    """Every outside submission of the clock track (IK joints or FK poses), verified by kinbench's
    own FK or IK (answers rows)."""
    if not tracks or not config.tracks.clock.submissions:
        return None
    # every arm of the track: IK answers (joints) and FK answers of parallel mechanisms (poses)
    arms = {config.problems[p].name: (track_arm(config, p, files), queries) for p, queries in tracks}
    return pd.concat([read_submission(config, k, arms, files) for k in range(len(config.tracks.clock.submissions))],
                     ignore_index=True)


def validate_track(config: SuiteConfig, p: int, files: Path | None = None) -> None:
    """Every clock-track solver built once on arm ``p``: a missing package or an arm a package
    misreads is one line before any work."""
    arm = track_arm(config, p, files)
    solvers, reference, timeouts = track_settings(config.tracks.clock, arm)
    for name in dict.fromkeys([reference, *solvers]):
        try:
            make_solver(name, arm, timeout=max(timeouts) / 1e3, rng=np.random.default_rng(0))
        except NotApplicable:             # by design (EAIK on a 7-joint arm): a "not applicable" cell
            continue
        except FkoptError as err:
            raise FkoptError(f"tracks.clock.solvers[{name}] on problems[{config.problems[p].name}]: {err}") from None


def solve_track(payload: dict) -> dict:
    """Worker: the clock (and throughput) track on one arm; returns every answer, JSON-able."""
    config = suite_from_dict(payload["config"], "suite task")
    files = Path(payload["folder"]) if payload["folder"] else None
    p, clock, tp = payload["problem"], config.tracks.clock, config.tracks.throughput
    arm = track_arm(config, p, files)
    name = config.problems[p].name
    queries = np.asarray(payload["queries"], dtype=float)
    start = time.perf_counter()
    load_start = load_average()
    solvers, reference, timeouts = track_settings(clock, arm)
    settings: dict = {}
    answers = run_clock(arm, name, queries, solvers, timeouts_ms=timeouts, reference=reference, seed=config.seed,
                        settings=settings)
    answers.insert(1, "set", clock.set)
    rate = None
    if tp is not None:
        batches = tp.batches if is_ik(arm) else tp.fk_batches
        batched = list(dict.fromkeys([*solvers, *(tp.solvers if is_ik(arm) else [])]))
        rate = run_throughput(arm, name, queries, batched, batches=tuple(batches), repeats=tp.repeats,
                              reference=reference, seed=config.seed,
                              optional=set(tp.solvers) - set(solvers)).to_dict(orient="list")
    return {"fingerprint": payload["fingerprint"], "track": "clock", "problem": p,
            "answers": answers.to_dict(orient="list"), "throughput": rate, "wall_s": time.perf_counter() - start,
            "load_avg": {"start": load_start, "end": load_average()},
            "settings": json.loads(json.dumps(settings, default=str))}


def entry_settings(tracked: list[dict]) -> dict:
    """meta.json's ``entries``: each entry's settings as on the first arm it ran on (less the arm's
    own file); an arm it cannot take records only why (``not_applicable``), which stands only for
    an entry that ran on no arm."""
    entries: dict = {}
    for r in tracked:
        for solver, st in (r.get("settings") or {}).items():
            if solver in entries and (set(st) == {"not_applicable"} or set(entries[solver]) != {"not_applicable"}):
                continue
            entries[solver] = {k: v for k, v in st.items() if k not in ("urdf", "urdf_note", "family")}
    return entries


def load_average() -> list[float] | None:
    """The machine's 1-, 5- and 15-minute load averages (None where the OS has none): stored in
    meta.json at the board's start and end, so anyone can see a run the scheduler distorted."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def solve_task(payload: dict) -> dict:
    """Worker: one (problem, solver) task on the cases (checked poses) the payload carries;
    returns its record, JSON-able (a task file): run rows as columns of lists, wall time. A
    track task (``payload["track"]``) goes to :func:`solve_track`."""
    if payload.get("track") in branch_tracks.FILES:
        return branch_tracks.solve_task(payload)
    if payload.get("track"):
        return solve_track(payload)
    config = suite_from_dict(payload["config"], "suite task")
    problem = config.problems[payload["problem"]]
    solver = config.solvers[payload["solver"]]
    cases = payload["cases"]
    mech, _ = problem_mechanism(problem, Path(payload["folder"]) if payload["folder"] else None)
    dim = len(mech.unknown_names)
    cfg = task_config(config, problem, solver, dim)
    points = np.stack([c[2] for c in cases])
    batched = make_problem(cfg, mech, targets_of(mech, points))
    seeds = [task_seed(config.seed, i, f"{problem.name}/{name}/{solver.key}") for name, i, _ in cases]
    spec = cfg.algorithms[0]
    start = time.perf_counter()
    result = solve_cases(cfg, spec, batched, seeds, x0=start_point(spec, mech))
    wall = time.perf_counter() - start
    rows = run_rows(config, problem, solver, cases, result, dim, seeds)
    return {"fingerprint": payload["fingerprint"], "problem": payload["problem"], "solver": payload["solver"],
            "dim": dim, "rows": rows.to_dict(orient="list"), "trace": task_trace(result, budget_of(config, dim)),
            "wall_s": wall, "solves": len(cases) * cfg.runs}


def run_rows(config: SuiteConfig, problem, solver, cases, result, dim: int, seeds) -> pd.DataFrame:
    """The task's rows of the run record (:mod:`fkopt.run.record`), measured at the budget."""
    budget = budget_of(config, dim)
    m = at_budget(result.history, result.evaluation_history, budget, config.targets)
    n, runs = len(cases), config.runs_of(solver.key)
    cols = {"problem": problem.name, "class": problem.problem_class,
            "set": np.repeat([c[0] for c in cases], runs), "pose": np.repeat([c[1] for c in cases], runs),
            "solver": solver.key, "track": solver.track, "run": np.tile(np.arange(runs), n),
            "dim": dim, "budget": budget, "task_seed": np.repeat(seeds, runs)}
    cols.update({k: np.asarray(v).reshape(n * runs) for k, v in m.items()})
    return run_record("suite", cols)


def rows_of(record: dict) -> pd.DataFrame:
    """A task file's run rows (columns of lists) as run-record rows, dtypes restored."""
    rows = record["rows"]
    return run_record("suite", {k: v for k, v in rows.items() if k != "kind"})


def fingerprint(config: SuiteConfig, manifest: dict) -> str:
    """Hash of everything that changes a task's numbers: the config's result-changing fields and
    the pose sets (a resumed suite must match it)."""
    text = json.dumps([numeric_fields(config.stored_dump()), manifest], sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _numbers(values, name: str, lo: float, hi: float, *, nan: bool = False, integer: bool = False,
             inf: bool = False) -> str | None:
    """Why ``values`` (a column read back from a task file) is not a list of numbers in [lo, hi]
    (NaN only when ``nan``, +inf only when ``inf``, whole numbers only when ``integer``)."""
    if any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in values):
        return f"{name}: not numbers"
    a = np.asarray(values, dtype=float)
    bad = np.isnan(a) if not nan else np.zeros(a.shape, bool)
    ok = np.isnan(a) | ((a >= lo) & (a <= hi)) | (inf & (a == np.inf))
    bad |= ~ok
    if integer:
        bad |= np.isfinite(a) & (a % 1 != 0)
    if bad.any():
        allowed = f"{'whole ' if integer else ''}numbers in [{lo:g}, {hi:g}]" + (", NaN" if nan else "") + \
            (", inf" if inf else "")
        return f"{name}: row {int(np.flatnonzero(bad)[0])} is not one of {allowed}"
    return None


def record_problem(task, rec) -> str | None:
    """Why ``rec`` is not the finished record of ``task`` (a task file read back by --resume):
    every field is checked against the plan -- the problem, class, solver, track, set and pose
    names and run numbers of every row, the dimension and budget, each measure's type and range
    (NaN only where a target was not reached, inf only as the fitness of a run without an answer)
    and the row counts of the rows and the trace. A digest proves the file is the one written,
    not that it holds this task's numbers (an edited file with a re-signed manifest)."""
    if not isinstance(rec, dict):
        return f"holds a JSON {type(rec).__name__}, not a task record"
    if task.payload.get("track"):
        try:
            if type(rec["problem"]) is not int or rec["problem"] != task.payload["problem"] \
                    or rec["track"] != task.payload["track"]:
                return "its problem/track are not its file name's"
            if not isinstance(rec["answers"], dict) or not all(isinstance(v, list) for v in rec["answers"].values()):
                return "answers: not a table of answers"
            if _numbers([rec["wall_s"]], "wall_s", 0, float(np.finfo(float).max)):
                return "wall_s: not a non-negative finite number"
            if task.payload["track"] in branch_tracks.FILES:
                return branch_tracks.record_problem(task, rec)
            return clock_record_problem(task, rec)      # every answer counted and judged again
        except KeyError as err:
            return f"field {str(err.args[0])[:40]!r} is missing"
        except (TypeError, ValueError, IndexError, AttributeError, FkoptError) as err:
            return f"{type(err).__name__}: {str(err)[:120]}"
    payload = task.payload
    try:
        if rec["problem"] != payload["problem"] or rec["solver"] != payload["solver"] \
                or isinstance(rec["problem"], bool) or isinstance(rec["solver"], bool):
            return "its problem/solver are not its file name's"
        config = suite_from_dict(payload["config"], "suite task")
        problem, solver = config.problems[payload["problem"]], config.solvers[payload["solver"]]
        cases = payload["cases"]
        dim = len(cases[0][2]) if cases else rec["dim"]
        if rec["dim"] != dim or isinstance(rec["dim"], bool):
            return f"dim: {str(rec['dim'])[:20]!r}, expected {dim}"
        budget, runs = budget_of(config, dim), config.runs_of(solver.key)
        n = len(cases) * runs
        rows = rec["rows"]
        measures = ["evaluations", "fitness", *(target_column(t) for t in config.targets)]
        names = ["kind", "problem", "class", "set", "pose", "solver", "track", "run", "dim", "budget", "task_seed",
                 *measures]
        if not isinstance(rows, dict) or sorted(rows) != sorted(names):
            return f"rows: not the columns {', '.join(names)}"
        if any(not isinstance(v, list) or len(v) != n for v in rows.values()):
            return f"rows: not a table of {n} run rows"
        expected = {"kind": ["suite"] * n, "problem": [problem.name] * n, "class": [problem.problem_class] * n,
                    "set": [c[0] for c in cases for _ in range(runs)],
                    "pose": [c[1] for c in cases for _ in range(runs)],
                    "solver": [solver.key] * n, "track": [solver.track] * n,
                    "run": list(range(runs)) * len(cases), "dim": [dim] * n, "budget": [budget] * n,
                    "task_seed": [task_seed(config.seed, c[1], f"{problem.name}/{c[0]}/{solver.key}")
                                  for c in cases for _ in range(runs)]}
        for col, want in expected.items():
            got = rows[col]
            if any(type(g) is not type(w) or g != w for g, w in zip(got, want)):
                i = next(i for i, (g, w) in enumerate(zip(got, want)) if type(g) is not type(w) or g != w)
                return f"rows.{col}: row {i} is {str(got[i])[:30]!r}, this task's is {str(want[i])[:30]!r}"
        why = (_numbers(rows["evaluations"], "rows.evaluations", 0, budget, integer=True)
               or _numbers(rows["fitness"], "rows.fitness", 0, float(np.finfo(float).max), inf=True)
               or next(filter(None, (_numbers(rows[c], f"rows.{c}", 0, budget, nan=True, integer=True)
                                     for c in measures[2:])), None))
        if why:
            return why
        trace = rec["trace"]
        if not isinstance(trace, dict) or any(not isinstance(trace.get(k), list)
                                              for k in ("row", "evaluations", "best_fitness")):
            return "trace: not the run traces (row, evaluations, best_fitness)"
        if len({len(trace[k]) for k in ("row", "evaluations", "best_fitness")}) != 1:
            return "trace: row, evaluations and best_fitness differ in length"
        why = (_numbers(trace["row"], "trace.row", 0, max(n - 1, 0), integer=True)
               or _numbers(trace["evaluations"], "trace.evaluations", 1, max(budget, 1), integer=True)
               or _numbers(trace["best_fitness"], "trace.best_fitness", 0, float(np.finfo(float).max), inf=True))
        if why:
            return why
        if rec["solves"] != len(cases) * runs or isinstance(rec["solves"], bool):
            return f"solves: expected {len(cases) * runs}"
        if _numbers([rec["wall_s"]], "wall_s", 0, float(np.finfo(float).max)):
            return "wall_s: not a non-negative finite number"
    except KeyError as err:
        return f"field {str(err.args[0])[:40]!r} is missing"
    except (TypeError, ValueError, IndexError, AttributeError) as err:
        return f"{type(err).__name__}: {str(err)[:120]}"
    return None


@dataclass
class _Context:
    sets: dict
    manifest: dict
    prepared_s: float     # building the plan (validation)
    files: Path | None    # where the suite's relative files are (pose sets, outside logs)
    tracks: list = field(default_factory=list)   # (problem index, queries) of the clock track's arms


def suite_plan(config: SuiteConfig, source: str | None = None, timing: bool = True) -> Plan:
    """A suite as tasks of the one runner: one per (problem, solver), every pose of the
    problem's selected sets a case of one batched solve; kept as task files while the suite runs
    (``--resume``), not in the published folder (its run rows are)."""
    started = time.perf_counter()
    files = files_folder(config, source)          # relative files resolve beside the suite file
    sets, manifest = load_pose_sets(config, files)
    fp = fingerprint(config, manifest)
    data = config.model_dump(mode="json")
    folder = str(files) if files is not None else ""
    tasks = [Task(f"p{p}-s{s}", {"config": data, "folder": folder, "problem": p, "solver": s, "fingerprint": fp,
                                 "cases": _cases(config, sets, problem, solver)}, f"{problem.name} / {solver.key}")
             for p, problem in enumerate(config.problems) for s, solver in enumerate(config.solvers)
             if config.runs_problem(solver.key, problem.name)]
    tracks = track_cases(config, sets, files)      # the clock track's queries, loaded once per run
    tasks += [Task(f"t{p}", {"config": data, "folder": folder, "problem": p, "track": "clock", "fingerprint": fp,
                             "queries": queries.tolist()}, f"{config.problems[p].name} / clock track")
              for p, queries in tracks]
    tasks += branch_tracks.track_tasks(config, sets, files, data, fp)     # all-solutions, paths
    return Plan(tasks, solve_task, fingerprint=fp, stored=True, check=record_problem,
                context=_Context(sets, manifest, time.perf_counter() - started, files, tracks),
                name=f"suite '{config.name}'")


def merge_suite(config: SuiteConfig, plan: Plan, ran: Ran, *, source: str | None = None, **_) -> RunResult:
    """The suite's :class:`~fkopt.run.result.RunResult`: the run rows of every task, then the
    imported outside results, the timing record, the trace, and the clock track's answers
    (:class:`SuiteOwn`)."""
    merging = time.perf_counter()
    ctx: _Context = plan.context
    done = [{**ran.records[t.id], "rows": rows_of(ran.records[t.id])} for t in plan.tasks
            if not t.payload.get("track")]
    clocked = [ran.records[t.id] for t in plan.tasks if t.payload.get("track") == "clock"]
    tracked = [ran.records[t.id] for t in plan.tasks if t.payload.get("track")]
    answers = pd.concat([pd.DataFrame(r["answers"]) for r in clocked], ignore_index=True) if clocked else None
    submitted = read_submissions(config, ctx.tracks, ctx.files) if clocked else None
    if submitted is not None:
        answers = pd.concat([answers, submitted], ignore_index=True)
    rates = [pd.DataFrame(r["throughput"]) for r in clocked if r.get("throughput")]
    throughput = pd.concat(rates, ignore_index=True) if rates else None
    frames = [r["rows"] for r in done]
    if config.outside:
        dims = {config.problems[r["problem"]].name: r["dim"] for r in done}
        instances = instances_of(config, ctx.sets)
        frames += [read_outside(config, k, dims, instances, ctx.files) for k in range(len(config.outside))]
    runs = concat(frames)
    tim = concat([timing_record("suite", {"problem": config.problems[r["problem"]].name,
                                          "solver": config.solvers[r["solver"]].key, "runs": r["solves"],
                                          "seconds": r["wall_s"], "mode": BATCH}) for r in done])
    wall = ctx.prepared_s + ran.wall_s + (time.perf_counter() - merging)   # however long before it was planned
    loads = [r["load_avg"] for r in tracked if r.get("load_avg")]
    load_avg = {"start": loads[0]["start"], "end": loads[-1]["end"]} if loads else None
    entries = entry_settings(tracked)
    own = SuiteOwn(ctx.manifest, ctx.files, answers, throughput, load_avg, entries or None,
                   branch_tracks.merge_tables(config, plan, ran))
    return RunResult(config, runs, tim, suite_trace(config, done, runs, ctx.files), own, wall, source,
                     list(ran.computed))


def run_suite(config: SuiteConfig, *, source: str | None = None, progress=None, jobs: int = 1,
              executor: str = "local", scheduler: str | None = None) -> RunResult:
    """Every (problem, solver) task computed (no task files, nothing written), then the
    imported outside results: the suite's result (``fkopt suite`` runs it through
    :func:`fkopt.run.pipeline.run_config`, which keeps task files and resumes)."""
    plan = suite_plan(config, source)
    ran = run_tasks(plan, executor=executor, jobs=jobs, scheduler=scheduler, progress=progress)
    return merge_suite(config, plan, ran, source=source)
