"""Run a suite on the experiment layer's one solve path.

One task is one (problem, solver): every pose of every selected set of the problem is a case of
one batched problem (:func:`fkopt.experiment.runner.make_problem`), solved by
:func:`fkopt.experiment.runner.solve_cases` for ``runs`` runs in one call. Case seeds:
:func:`fkopt.experiment.runner.task_seed` of (suite seed, pose index within its set,
``"<problem>/<set>/<solver label>"``); run k of a case is its k-th child stream
(:mod:`fkopt.streams`), so a task's numbers do not depend on which other problems, sets,
solvers or workers there are. The tasks go to the one runner (:mod:`fkopt.experiment.tasks`,
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
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import FkoptError
from ..experiment.config import RunConfig
from ..experiment.runner import make_problem, solve_cases, start_point, task_seed
from ..experiment.tasks import Plan, Ran, Task, run_tasks
from ..solve import chunk_size
from .budget import at_budget, budget_of
from .config import SuiteConfig, suite_from_dict
from .outside import read_outside
from .posesets import load_pose_sets, problem_mechanism, targets_of
from .traces import suite_trace, task_trace


def task_config(config: SuiteConfig, problem, solver, dim: int) -> RunConfig:
    """The experiment layer's settings of one (problem, solver) task."""
    budget = budget_of(config, dim)
    pop = solver.population or config.population
    cfg = RunConfig(name=problem.name, mechanism=problem.mechanism, objective=problem.objective,
                    algorithms=[solver.model_dump(exclude={"track"})], population=config.population,
                    iterations=solver.iterations or max(1, math.ceil(budget / pop)), runs=config.runs,
                    seed=config.seed, threshold=min(config.targets), stop_at_threshold=True)
    cfg._folder = config._folder
    return cfg


@dataclass
class SuiteResult:
    config: SuiteConfig
    runs: pd.DataFrame                   # one row per (problem, set, pose, solver, run)
    timing: pd.DataFrame                 # one row per (problem, solver): wall time per solve
    manifest: dict
    wall_s: float
    source: str | None = None
    trace: pd.DataFrame | None = None    # trace.csv.gz: each run's best-so-far within the budget
    answers: pd.DataFrame | None = None  # answers.csv.gz: every answer of the clock track (v3)
    throughput: pd.DataFrame | None = None   # throughput.csv: queries/s per batch size (v3)


def _cases(config: SuiteConfig, sets: dict, problem):
    """(set name, pose index, point) of every case of ``problem``, in set then pose order."""
    return [(name, i, p) for name in config.sets for i, p in enumerate(sets[(problem.name, name)])]


def instances_of(config: SuiteConfig, sets: dict) -> set[tuple[str, str, int]]:
    """Every (problem, set, pose) the suite selects."""
    return {(p.name, name, i) for p in config.problems for name, i, _ in _cases(config, sets, p)}


def validate_suite(config: SuiteConfig) -> tuple[int, int]:
    """Everything a suite needs, built without solving; (tasks, estimated bytes)."""
    sets, _ = load_pose_sets(config)
    need = 0
    dims: dict[str, int] = {}
    for problem in config.problems:
        mech, _ = problem_mechanism(problem, config._folder)
        cases = _cases(config, sets, problem)
        if not cases:
            raise FkoptError(f"problems[{problem.name}]: no poses in sets {', '.join(config.sets)}")
        dim = dims[problem.name] = len(mech.unknown_names)
        if not np.all(mech.in_bounds(np.stack([c[2] for c in cases]))):
            raise FkoptError(f"problems[{problem.name}]: a frozen pose lies outside mechanism.bounds")
        for solver in config.solvers:
            where = f"solvers[{solver.key}]"
            try:
                cfg = task_config(config, problem, solver, dim)
                pop = solver.population or config.population
                chunk_size(len(cases), config.runs, pop, cfg.iterations, dim)
                # a one-iteration probe on one pose: an unknown solver or parameter, a bad start, a
                # solver that cannot take this problem (nr on a redundant arm) fail here, before any work
                probe = cfg.model_copy(update={"runs": 1, "iterations": 1, "stop_at_threshold": False})
                spec = cfg.algorithms[0]
                solve_cases(probe, spec, make_problem(probe, mech, targets_of(mech, cases[0][2][None])), [0],
                            x0=start_point(spec, mech))
            except FkoptError as err:
                raise FkoptError(f"{where} on problems[{problem.name}]: {err}") from None
            T = cfg.iterations + 1
            need = max(need, len(cases) * config.runs * 8 * (3 * T + 2 * dim) * 2)
    if config.outside:            # read and checked now, so a bad file fails before any solve
        instances = instances_of(config, sets)
        for k in range(len(config.outside)):
            read_outside(config, k, dims, instances)
    tracks = track_cases(config, sets)
    for p, _ in tracks:
        validate_track(config, p)
    read_submissions(config, tracks)
    return len(config.problems) * len(config.solvers) + len(tracks), need


def track_cases(config: SuiteConfig, sets: dict) -> list[tuple[int, np.ndarray]]:
    """(problem index, queries: joints of the clock set's first ``queries`` poses) of every
    clock-track arm; the suite's ``poses`` (how many poses the swarms get) does not cut them."""
    clock = config.tracks.clock if config.tracks is not None else None
    if clock is None:
        return []
    if config.poses is not None:
        full = config.model_copy(update={"poses": None})
        full._folder = config._folder
        sets, _ = load_pose_sets(full)
    index = {p.name: k for k, p in enumerate(config.problems)}
    return [(index[name], np.asarray(sets[(name, clock.set)][:clock.queries], dtype=float)) for name in clock.problems]


def track_arm(config: SuiteConfig, p: int):
    """The URDF arm of clock-track problem ``p`` (the field's packages read URDF only)."""
    problem = config.problems[p]
    mech, _ = problem_mechanism(problem, config._folder)
    if getattr(mech, "kind", None) == "parallel":
        if len(mech.unknown_names) != 6 or tuple(mech.pose_units[3:]) != ("deg",) * 3:
            raise FkoptError(f"tracks.clock.problems: '{problem.name}' is not a 6-DOF parallel mechanism "
                             "(x, y, z, three angles): the FK clock judges poses in m and rad")
        return mech
    if getattr(mech, "kind", None) != "serial" or not hasattr(mech, "path") or not hasattr(mech, "tip_link"):
        raise FkoptError(f"tracks.clock.problems: '{problem.name}' is not a URDF arm (mechanism: urdf) or a "
                         "6-DOF parallel mechanism; the clock track's IK solvers read URDF files")
    return mech


def read_submissions(config: SuiteConfig, tracks) -> pd.DataFrame | None:
    """Every outside submission of the clock track, verified by fkopt's FK (answers rows)."""
    if not tracks or not config.tracks.clock.submissions:
        return None
    from .submissions import read_submission
    from .clock import is_ik
    arms = {config.problems[p].name: (track_arm(config, p), queries) for p, queries in tracks}
    arms = {name: v for name, v in arms.items() if is_ik(v[0])}       # submissions: IK answers
    return pd.concat([read_submission(config, k, arms) for k in range(len(config.tracks.clock.submissions))],
                     ignore_index=True)


def validate_track(config: SuiteConfig, p: int) -> None:
    """Every clock-track solver built once on arm ``p``: a missing package or an arm a package
    misreads is one line before any work."""
    from .clock import make_solver, track_settings
    arm = track_arm(config, p)
    solvers, reference, timeouts = track_settings(config.tracks.clock, arm)
    for name in dict.fromkeys([reference, *solvers]):
        try:
            make_solver(name, arm, timeout=max(timeouts) / 1e3, rng=np.random.default_rng(0))
        except FkoptError as err:
            raise FkoptError(f"tracks.clock.solvers[{name}] on problems[{config.problems[p].name}]: {err}") from None


def solve_track(payload: dict) -> dict:
    """Worker: the clock (and throughput) track on one arm; returns every answer, JSON-able."""
    from .clock import run_clock, run_throughput, track_settings
    config = suite_from_dict(payload["config"], "suite task")
    config._folder = Path(payload["folder"]) if payload["folder"] else None
    p, clock, tp = payload["problem"], config.tracks.clock, config.tracks.throughput
    arm = track_arm(config, p)
    name = config.problems[p].name
    queries = np.asarray(payload["queries"], dtype=float)
    start = time.perf_counter()
    solvers, reference, timeouts = track_settings(clock, arm)
    answers = run_clock(arm, name, queries, solvers, timeouts_ms=timeouts, reference=reference, seed=config.seed)
    answers.insert(1, "set", clock.set)
    rate = None
    if tp is not None:
        from .clock import is_ik
        batches = tp.batches if is_ik(arm) else tp.fk_batches
        rate = run_throughput(arm, name, queries, solvers, batches=tuple(batches), repeats=tp.repeats,
                              reference=reference, seed=config.seed).to_dict(orient="list")
    return {"fingerprint": payload["fingerprint"], "track": "clock", "problem": p,
            "answers": answers.to_dict(orient="list"), "throughput": rate, "wall_s": time.perf_counter() - start}


def solve_task(payload: dict) -> dict:
    """Worker: one (problem, solver) task on the cases (checked poses) the payload carries;
    returns its record, JSON-able (a task file): run rows as columns of lists, wall time. A
    track task (``payload["track"]``) goes to :func:`solve_track`."""
    if payload.get("track"):
        return solve_track(payload)
    config = suite_from_dict(payload["config"], "suite task")
    config._folder = Path(payload["folder"]) if payload["folder"] else None
    problem = config.problems[payload["problem"]]
    solver = config.solvers[payload["solver"]]
    cases = payload["cases"]
    mech, _ = problem_mechanism(problem, config._folder)
    dim = len(mech.unknown_names)
    cfg = task_config(config, problem, solver, dim)
    points = np.stack([c[2] for c in cases])
    batched = make_problem(cfg, mech, targets_of(mech, points))
    seeds = [task_seed(config.seed, i, f"{problem.name}/{name}/{solver.key}") for name, i, _ in cases]
    spec = cfg.algorithms[0]
    start = time.perf_counter()
    result = solve_cases(cfg, spec, batched, seeds, x0=start_point(spec, mech))
    wall = time.perf_counter() - start
    rows = run_rows(config, problem, solver, cases, result, dim)
    return {"fingerprint": payload["fingerprint"], "problem": payload["problem"], "solver": payload["solver"],
            "dim": dim, "rows": rows.to_dict(orient="list"), "trace": task_trace(result, budget_of(config, dim)),
            "wall_s": wall, "solves": len(cases) * config.runs}


def run_rows(config: SuiteConfig, problem, solver, cases, result, dim: int) -> pd.DataFrame:
    budget = budget_of(config, dim)
    m = at_budget(result.history, result.evaluation_history, budget, config.targets)
    n, runs = len(cases), config.runs
    cols = {"problem": problem.name, "class": problem.problem_class,
            "set": np.repeat([c[0] for c in cases], runs), "pose": np.repeat([c[1] for c in cases], runs),
            "solver": solver.key, "track": solver.track, "run": np.tile(np.arange(runs), n),
            "dim": dim, "budget": budget}
    cols.update({k: np.asarray(v).reshape(n * runs) for k, v in m.items()})
    return pd.DataFrame(cols)


def fingerprint(config: SuiteConfig, manifest: dict) -> str:
    """Hash of everything that changes a task's numbers: the config's result-changing fields and
    the pose sets (a resumed suite must match it)."""
    from ..experiment.config import numeric_fields
    text = json.dumps([numeric_fields(config.stored_dump()), manifest], sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def record_problem(task, rec) -> str | None:
    """Why ``rec`` is not the finished record of ``task`` (a task file read back by --resume)."""
    if not isinstance(rec, dict):
        return f"holds a JSON {type(rec).__name__}, not a task record"
    if task.payload.get("track"):
        try:
            if int(rec["problem"]) != task.payload["problem"] or rec["track"] != task.payload["track"]:
                return "its problem/track are not its file name's"
            if not isinstance(rec["answers"], dict) or not all(isinstance(v, list) for v in rec["answers"].values()):
                return "answers: not a table of answers"
            float(rec["wall_s"])
        except KeyError as err:
            return f"field {err.args[0]!r} is missing"
        except (TypeError, ValueError) as err:
            return f"{type(err).__name__}: {str(err)[:120]}"
        return None
    try:
        if (int(rec["problem"]), int(rec["solver"])) != (task.payload["problem"], task.payload["solver"]):
            return "its problem/solver are not its file name's"
        rows = rec["rows"]
        n = len(task.payload["cases"]) * int(task.payload["config"]["runs"])
        if not isinstance(rows, dict) or any(not isinstance(v, list) or len(v) != n for v in rows.values()):
            return f"rows: not a table of {n} run rows"
        trace = rec["trace"]
        if not isinstance(trace, dict) or any(not isinstance(trace.get(k), list)
                                              for k in ("row", "evaluations", "best_fitness")):
            return "trace: not the run traces (row, evaluations, best_fitness)"
        int(rec["dim"]), float(rec["wall_s"]), int(rec["solves"])
    except KeyError as err:
        return f"field {err.args[0]!r} is missing"
    except (TypeError, ValueError) as err:
        return f"{type(err).__name__}: {str(err)[:120]}"
    return None


@dataclass
class _Context:
    sets: dict
    manifest: dict
    started: float


def suite_plan(config: SuiteConfig, source: str | None = None) -> Plan:
    """A suite as tasks of the one runner: one per (problem, solver), every pose of the
    problem's selected sets a case of one batched solve; kept as task files while the suite runs
    (``--resume``), not in the published folder (its run rows are)."""
    started = time.perf_counter()
    if source and config._folder is None:
        config._folder = Path(source).parent
    sets, manifest = load_pose_sets(config)
    fp = fingerprint(config, manifest)
    data = config.model_dump(mode="json")
    folder = str(config._folder) if config._folder is not None else ""
    tasks = [Task(f"p{p}-s{s}", {"config": data, "folder": folder, "problem": p, "solver": s, "fingerprint": fp,
                                 "cases": _cases(config, sets, problem)}, f"{problem.name} / {solver.key}")
             for p, problem in enumerate(config.problems) for s, solver in enumerate(config.solvers)]
    tasks += [Task(f"t{p}", {"config": data, "folder": folder, "problem": p, "track": "clock", "fingerprint": fp,
                             "queries": queries.tolist()}, f"{config.problems[p].name} / clock track")
              for p, queries in track_cases(config, sets)]
    return Plan(tasks, solve_task, fingerprint=fp, stored=True, check=record_problem,
                context=_Context(sets, manifest, started), name=f"suite '{config.name}'")


def merge_suite(config: SuiteConfig, plan: Plan, ran: Ran, *, source: str | None = None, **_) -> SuiteResult:
    """The run rows of every task, then the imported outside results, and the timing table."""
    ctx: _Context = plan.context
    done = [{**ran.records[t.id], "rows": pd.DataFrame(ran.records[t.id]["rows"])} for t in plan.tasks
            if not t.payload.get("track")]
    tracked = [ran.records[t.id] for t in plan.tasks if t.payload.get("track")]
    answers = pd.concat([pd.DataFrame(r["answers"]) for r in tracked], ignore_index=True) if tracked else None
    submitted = read_submissions(config, track_cases(config, ctx.sets)) if tracked else None
    if submitted is not None:
        answers = pd.concat([answers, submitted], ignore_index=True)
    rates = [pd.DataFrame(r["throughput"]) for r in tracked if r.get("throughput")]
    throughput = pd.concat(rates, ignore_index=True) if rates else None
    frames = [r["rows"] for r in done]
    if config.outside:
        dims = {config.problems[r["problem"]].name: r["dim"] for r in done}
        instances = instances_of(config, ctx.sets)
        frames += [read_outside(config, k, dims, instances) for k in range(len(config.outside))]
    runs = pd.concat(frames, ignore_index=True)
    tim = pd.DataFrame([{"problem": config.problems[r["problem"]].name, "solver": config.solvers[r["solver"]].key,
                         "solves": r["solves"], "wall_s": r["wall_s"], "ms_per_solve": 1e3 * r["wall_s"] / r["solves"]}
                        for r in done])
    return SuiteResult(config, runs, tim, ctx.manifest, time.perf_counter() - ctx.started, source,
                       suite_trace(config, done, runs), answers, throughput)


def run_suite(config: SuiteConfig, *, source: str | None = None, progress=None, jobs: int = 1,
              executor: str = "local", scheduler: str | None = None) -> SuiteResult:
    """Every (problem, solver) task computed (no task files, nothing written), then the
    imported outside results: the suite's result (``fkopt suite`` runs it through
    :func:`fkopt.experiment.kinds.run_config`, which keeps task files and resumes)."""
    plan = suite_plan(config, source)
    ran = run_tasks(plan, executor=executor, jobs=jobs, scheduler=scheduler, progress=progress)
    return merge_suite(config, plan, ran, source=source)
