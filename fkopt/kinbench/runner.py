"""Run a suite on the experiment layer's one solve path.

One task is one (problem, solver): every pose of every selected set of the problem is a case of
one batched problem (:func:`fkopt.experiment.runner.make_problem`), solved by
:func:`fkopt.experiment.runner.solve_cases` for ``runs`` runs in one call. Case seeds:
:func:`fkopt.experiment.runner.task_seed` of (suite seed, pose index within its set,
``"<problem>/<set>/<solver label>"``); run k of a case is its k-th child stream
(:mod:`fkopt.streams`), so a task's numbers do not depend on which other problems, sets,
solvers or workers there are. Tasks run in this process, in local worker processes or on Dask
(:func:`fkopt.study.executors.execute`).

Budget: a run of a problem of dimension n may spend ``B = budget_per_dim * n`` fitness
evaluations (an analytic Jacobian counts as one, as everywhere in fkopt). The solver gets
``ceil(B / population)`` iterations and stops once below the smallest target; every measure is
read from the run's cumulative evaluation counts at the last iteration within ``B``.
"""
from __future__ import annotations

import hashlib
import json
import math
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import FkoptError
from ..experiment.config import RunConfig
from ..files import inside, write_json_atomically
from ..experiment.runner import make_problem, solve_cases, start_point, task_seed
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
    return len(config.problems) * len(config.solvers), need


def solve_task(payload: dict) -> dict:
    """Worker: one (problem, solver) task on the cases (checked poses) the payload carries;
    returns its run rows and wall time (picklable)."""
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
    return {"problem": payload["problem"], "solver": payload["solver"], "dim": dim,
            "rows": run_rows(config, problem, solver, cases, result, dim),
            "trace": task_trace(result, budget_of(config, dim)),
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
    text = json.dumps([numeric_fields(config.model_dump(mode="json")), manifest], sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _task_file(work: Path, p: int, s: int) -> Path:
    return work / f"p{p}-s{s}.json"


def _finished_tasks(work: Path, fp: str) -> dict[tuple[int, int], dict]:
    """Tasks an interrupted run of the same suite finished (unreadable files are redone)."""
    out = {}
    for path in sorted(work.glob("p*-s*.json")):
        inside(work, path, "--resume")
        try:
            rec = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        redo = "delete it to recompute that task, or rerun without --resume to start over"
        if not isinstance(rec, dict):
            raise FkoptError(f"--resume: {path} holds a JSON {type(rec).__name__}, not a task record; {redo}")
        if rec.get("fingerprint") != fp:
            raise FkoptError(f"--resume: {path} belongs to another version of the suite (its config or pose "
                             "sets changed); rerun without --resume to start over")
        try:
            key = (int(rec["problem"]), int(rec["solver"]))
            if path.name != _task_file(work, *key).name or not isinstance(rec["rows"], dict) or not isinstance(rec["trace"], dict):
                raise ValueError("its problem/solver are not its file name's, or rows is not a table")
            rec["rows"] = pd.DataFrame(rec["rows"])
        except (KeyError, TypeError, ValueError) as err:
            raise FkoptError(f"--resume: {path} is not a finished task of this suite ({type(err).__name__}: "
                             f"{str(err)[:120]}); {redo}") from None
        out[key] = rec
    return out


def run_suite(config: SuiteConfig, *, source: str | None = None, progress=None, jobs: int = 1,
              executor: str = "local", scheduler: str | None = None, work: Path | None = None,
              resume: bool = False) -> SuiteResult:
    """Every (problem, solver) task, then the imported outside results. With ``work``, each
    finished task is written there as it arrives (``p<i>-s<j>.json``), and ``resume=True`` keeps
    the tasks an interrupted run of the same suite left there and computes only the others."""
    from ..study.executors import execute
    start = time.perf_counter()
    if source and config._folder is None:
        config._folder = Path(source).parent
    sets, manifest = load_pose_sets(config)
    fp = fingerprint(config, manifest)
    data = config.model_dump(mode="json")
    folder = str(config._folder) if config._folder is not None else ""
    if work is not None:
        if not resume:
            shutil.rmtree(work, ignore_errors=True)
        work.mkdir(parents=True, exist_ok=True)
    kept = _finished_tasks(work, fp) if work is not None and resume else {}
    payloads = [{"config": data, "folder": folder, "problem": p, "solver": s,
                 "cases": _cases(config, sets, problem)}
                for p, problem in enumerate(config.problems) for s in range(len(config.solvers))
                if (p, s) not in kept]
    done: list[dict] = list(kept.values())
    total = len(done) + len(payloads)

    def collect(rec: dict) -> None:
        if work is not None:
            stored = {**rec, "fingerprint": fp, "rows": rec["rows"].to_dict(orient="list")}
            write_json_atomically(inside(work, _task_file(work, rec["problem"], rec["solver"])), stored)
        done.append(rec)
        if progress:
            progress(f"{config.problems[rec['problem']].name} / {config.solvers[rec['solver']].key}",
                     len(done), total)

    execute(solve_task, payloads, executor=executor, jobs=jobs, scheduler=scheduler, on_result=collect)
    done.sort(key=lambda r: (r["problem"], r["solver"]))
    frames = [r["rows"] for r in done]
    if config.outside:
        dims = {config.problems[r["problem"]].name: r["dim"] for r in done}
        instances = instances_of(config, sets)
        frames += [read_outside(config, k, dims, instances) for k in range(len(config.outside))]
    runs = pd.concat(frames, ignore_index=True)
    tim = pd.DataFrame([{"problem": config.problems[r["problem"]].name, "solver": config.solvers[r["solver"]].key,
                         "solves": r["solves"], "wall_s": r["wall_s"], "ms_per_solve": 1e3 * r["wall_s"] / r["solves"]}
                        for r in done])
    return SuiteResult(config, runs, tim, manifest, time.perf_counter() - start, source, suite_trace(config, done, runs))
