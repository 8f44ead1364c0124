"""Run an experiment: every algorithm on every case for ``runs`` seeded runs.

Seeds: the (case, algorithm) task with case index c and algorithm label L gets the integer
seed ``SeedSequence([seed, c, crc32(L)]).generate_state(1)[0]`` and its run k the k-th child
stream of that (see :mod:`fkopt.numerics.streams`). Reordering algorithms in a file or running one
algorithm alone therefore reproduces the same numbers -- and so does batching: each algorithm
solves all cases of the experiment in one :func:`fkopt.solve` call (cases x runs rows), passing
these per-case seeds, and the result is sliced back into one record per (case, algorithm).

An exact solver's entry with ``params: {solutions: all}`` searches every solution of each case
once instead, with the same per-case seed (:mod:`.case_solutions`; ``solutions.csv``).
"""
from __future__ import annotations

import hashlib
import json
import math
import time
from pathlib import Path
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from fkopt.errors import FkoptError
from fkopt.kinematics.as_algorithms import ExactSolver
from fkopt.registry import algorithm_class
from fkopt.run.record import ALONE, BATCH, concat, run_record, timing_record
from fkopt.run.result import RunResult, dataclass_from_json, dataclass_to_json
from fkopt.run.trace import COLUMNS as TRACE_COLUMNS, case_trace, concat_traces, trace_frame
from fkopt.solve import Result, chunk_size, make_algorithm
from fkopt.kinds.experiment.config import experiment_from_dict, ExperimentConfig, RandomCases
from fkopt.kinds.experiment.case_solutions import (CaseSet, merge_sets, search_cases, set_record_problem,
                                                  wants_every_solution)
from fkopt.run.config_base import AlgorithmSpec, files_folder, numeric_fields
from fkopt.run.solving import (_check_in_bounds, build_mechanism, make_problem, outputs_of, pose_error, solve_cases,  # noqa: F401
                               start_point, task_seed)
from fkopt.run.tasks import Plan, Ran, Task, reason_or_none, run_tasks
from fkopt.run.timing import sample_plan, time_case


@dataclass
class Case:
    """One forward/inverse problem instance of an experiment."""

    index: int
    label: str
    inputs: np.ndarray                 # what the solver must reproduce: joints (parallel) / pose (serial)
    target: np.ndarray | None          # the true/nominal answer in the compared space (pose), if known
    given_joints: np.ndarray | None = None     # joints as given in the file (parallel)
    joints_from_pose: np.ndarray | None = None  # fkopt's inverse map of the nominal pose (parallel)
    reference: np.ndarray | None = None
    reference_label: str = "reference"
    printed: dict = field(default_factory=dict)


@dataclass
class CaseSolve:
    """One algorithm's runs on one case, with their per-iteration curves: what the flat run record
    (one row per run, :mod:`fkopt.run.record`) cannot hold and the convergence table and figures
    draw (best-so-far fitness, evaluations and points per iteration, snapshots, an algorithm's own
    records). A view of the task's :class:`~fkopt.solve.Result`, built at merge time."""

    case: Case
    spec: AlgorithmSpec
    problem: object
    result: Result
    position_error_history: np.ndarray | None = None   # serial arms: (runs, iterations + 1)


@dataclass
class ExperimentOwn:
    """What only an experiment has (the :attr:`fkopt.run.result.RunResult.own` slot): its
    mechanism, its cases and every (case, algorithm)'s curves, case by case (every algorithm of
    case 1, then case 2, ...), each algorithm's solve time per case (amortised), and the solution
    sets of its ``solutions: all`` entries (:mod:`.case_solutions`), case by case too."""

    mechanism: object
    cases: list[Case]
    solves: list[CaseSolve]
    solve_s: dict[str, float]
    sets: list[CaseSet] = field(default_factory=list)

    @property
    def compared_names(self) -> tuple[str, ...]:
        return self.mechanism.pose_names

    @property
    def compared_units(self) -> tuple[str, ...]:
        return self.mechanism.pose_units


def build_cases(config: ExperimentConfig, mech) -> list[Case]:
    serial = mech.kind == "serial"
    if isinstance(config.cases, RandomCases):
        rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(config.cases.seed)))
        u = rng.random((config.cases.random, len(mech.unknown_names)))
        x = mech.bounds[:, 0] + u * (mech.bounds[:, 1] - mech.bounds[:, 0])
        cases = []
        for i, xi in enumerate(x):
            if serial:  # random joints -> a reachable target pose
                pose = mech.fk(xi)
                cases.append(Case(i, f"random-{i + 1}", inputs=pose, target=pose, given_joints=xi))
            else:
                cases.append(Case(i, f"random-{i + 1}", inputs=mech.ik(xi), target=xi))
        return cases
    cases = []
    for i, spec in enumerate(config.cases):
        where = f"cases[{i}]"
        label = spec.label or f"case-{i + 1}"
        reference = (mech.vector(spec.reference, mech.pose_names, f"{where}.reference")
                     if spec.reference is not None else None)
        pose = mech.vector(spec.pose, mech.pose_names, f"{where}.pose") if spec.pose is not None else None
        joints = mech.vector(spec.joints, mech.joint_names, f"{where}.joints") if spec.joints is not None else None
        if serial:
            if joints is not None:
                _check_in_bounds(mech, joints, f"{where}.joints")
            target = pose if pose is not None else mech.fk(joints)
            cases.append(Case(i, label, inputs=target, target=target, given_joints=joints,
                              reference=reference, reference_label=spec.reference_label, printed=spec.printed))
            continue
        from_pose = None
        if pose is not None:
            _check_in_bounds(mech, pose, f"{where}.pose")
            from_pose = mech.ik(pose)
        inputs = joints if joints is not None else from_pose
        cases.append(Case(i, label, inputs=inputs, target=pose, given_joints=joints,
                          joints_from_pose=from_pose, reference=reference,
                          reference_label=spec.reference_label, printed=spec.printed))
    return cases


def build_problem(config: ExperimentConfig, mech, case: Case):
    return make_problem(config, mech, case.inputs)


def validate_experiment(config: ExperimentConfig, folder: Path | None = None):
    """Build everything a run needs without running it (so bad input fails before any work);
    relative files resolve in ``folder`` (:func:`build_mechanism`)."""
    mech = build_mechanism(config, folder)
    cases = build_cases(config, mech)
    for spec in config.algorithms:
        _check_every_solution(spec, mech)         # unknown names/parameters fail here
        start_point(spec, mech)
    problems = [build_problem(config, mech, c) for c in cases]
    for spec in one_answer_entries(config):  # a batch that cannot fit in memory fails here, not midway
        try:
            chunk_size(len(cases), config.runs, spec.population or config.population,
                       spec.iterations or config.iterations, len(mech.unknown_names), batch=config.batch,
                       snapshots=len(config.snapshots), x_history=keeps_x_history(config, mech))
        except FkoptError as err:
            raise FkoptError(f"algorithms[{spec.key}]: {err}") from None
    return mech, cases, problems


def _check_every_solution(spec: AlgorithmSpec, mech) -> None:
    """An entry's algorithm built from its params; ``solutions`` on an algorithm that is no exact
    solver, or a ``solutions: all`` entry this mechanism cannot take (wrong kind, unknown joints in
    ``fixed``, a redundant arm without ``fixed``/``spread``), is one line naming the entry."""
    where = f"algorithms[{spec.key}]"
    if "solutions" in spec.params and not issubclass(algorithm_class(spec.name), ExactSolver):
        raise FkoptError(f"{where}.params.solutions: only the exact solvers give every solution of a pose "
                         f"(inverse or exact on a serial arm, forward or exact on a parallel mechanism); "
                         f"'{spec.name}' gives one answer per run")
    algorithm = make_algorithm(spec.name, spec.params)
    if getattr(algorithm, "every_solution", False):
        if spec.start is not None:
            raise FkoptError(f"{where}.start: a search of every solution (solutions: all) takes no start")
        try:
            algorithm.check_solution_set(mech)
        except FkoptError as err:
            raise FkoptError(f"{where}: {err}") from None


def one_answer_entries(config: ExperimentConfig) -> list[AlgorithmSpec]:
    """The entries that solve one answer per run (every entry but the ``solutions: all`` ones)."""
    return [spec for spec in config.algorithms if not wants_every_solution(spec)]


def keeps_x_history(config: ExperimentConfig, mech) -> bool:
    """Does the experiment need each run's best-so-far point per iteration (variables.png, the
    position error of a serial arm)? Otherwise only the final points are kept."""
    return "variables" in config.figures or mech.kind == "serial"


def batched_problem(config: ExperimentConfig, mech, cases: list[Case]):
    """One problem with a case axis holding every case's inputs (see :mod:`fkopt.problems`)."""
    return make_problem(config, mech, np.stack([c.inputs for c in cases]))


def _prepare(config: ExperimentConfig, folder: Path | None):
    mech, cases, problems = validate_experiment(config, folder)
    one = len(cases) == 1         # a single case keeps the single-target problem (no case axis)
    batched = problems[0] if one else batched_problem(config, mech, cases)
    return mech, cases, problems, batched


def _seeds(config: ExperimentConfig, cases: list[Case], spec: AlgorithmSpec) -> list[int]:
    return [task_seed(config.seed, case.index, spec.key) for case in cases]


def fingerprint(config: ExperimentConfig, mech) -> str:
    """Hash of everything that changes a task's numbers: the config's result-changing fields and
    the mechanism as built (a resumed experiment must match it)."""
    text = json.dumps([numeric_fields(config.model_dump(mode="json")), mech.describe()], sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _solve_one(config: ExperimentConfig, mech, cases, problems, batched, a: int, fp: str) -> dict:
    """One algorithm on every case in one solve; its task record, JSON-able (a task file): the
    rows of the run record and the trace of every case (case by case), the solve's per-iteration
    arrays (``curves``: :class:`~fkopt.solve.Result`, for the convergence table and figures) and
    its wall time per case (amortised)."""
    spec = config.algorithms[a]
    seeds = _seeds(config, cases, spec)
    start = time.perf_counter()
    result = solve_cases(config, spec, batched, seeds[0] if len(cases) == 1 else seeds, x0=start_point(spec, mech),
                         batch=config.batch, snapshots=config.snapshots, x_history=keeps_x_history(config, mech))
    wall = (time.perf_counter() - start) / len(cases)     # amortised over the cases
    rows, traces = [], []
    for i, (case, problem) in enumerate(zip(cases, problems)):
        r = result if len(cases) == 1 else result.case(i)
        pos = problem.position_error(r.x_history) if hasattr(problem, "position_error") else None
        rows.append(case_rows(config, mech, case, spec, r, seeds[i], pos).to_dict(orient="list"))
        traces.append(case_trace(case.label, spec.key, r).to_dict(orient="list"))
    return {"fingerprint": fp, "algorithm": a, "solver": spec.key, "wall_s": wall, "rows": rows, "trace": traces,
            "curves": dataclass_to_json(result)}


@dataclass
class _Context:
    mech: object
    cases: list[Case]
    problems: list
    batched: object
    prepared_s: float     # building the plan (validation); the run's own time adds the tasks' and the merge's


def experiment_plan(config: ExperimentConfig, source: str | None = None, timing: bool = True) -> Plan:
    """An experiment as tasks of the one runner (:mod:`fkopt.run.tasks`): one task per
    algorithm, solving every case in one call (an experiment is a suite of one problem with
    listed poses), kept as a task file while the experiment runs (``--resume``), not in the
    published folder; and (``timing``) one timing task per timed case (:mod:`.timing`'s sample:
    every algorithm's runs solved alone, interleaved), run after the solves, in this process
    (:attr:`~fkopt.run.tasks.Plan.timed`). In this process a task uses the live mechanism
    and cases; a worker process rebuilds them from the payload (:func:`solve_task`), with the
    same numbers."""
    started = time.perf_counter()
    folder = files_folder(config, source)        # relative files resolve beside the config
    mech, cases, problems, batched = _prepare(config, folder)
    fp = fingerprint(config, mech)
    data = config.model_dump_json()
    tasks = [Task(f"a{a:02d}", {"config": data, "folder": None if folder is None else str(folder), "algorithm": a,
                                "fingerprint": fp}, spec.key)
             for a, spec in enumerate(config.algorithms)]
    timed_cases, per = sample_plan(len(cases), config.runs)
    timed = [Task(f"t{c:02d}", {"timing": c, "runs": per}, f"timing · {cases[c].label}")
             for c in range(timed_cases)] if timing and one_answer_entries(config) else []

    def local(payload: dict):
        if "timing" in payload:
            return _time_one(config, cases, problems, payload["timing"], payload["runs"])
        return _task(config, mech, cases, problems, batched, payload["algorithm"], fp)
    return Plan(tasks, solve_task, fingerprint=fp, stored=True,
                check=lambda task, rec: record_problem(task, rec, config, cases),
                local=local, anywhere=True, timed=timed,
                context=_Context(mech, cases, problems, batched, time.perf_counter() - started),
                name=f"experiment '{config.name}'")


def _time_one(config: ExperimentConfig, cases: list[Case], problems: list, c: int, per: int) -> dict:
    """A timing task: every algorithm's runs ``0 .. per-1`` of case ``c`` solved alone,
    interleaved (:func:`fkopt.run.timing.time_case`); its rows of the timing record."""
    specs = one_answer_entries(config)
    entries = [(spec, problems[c], task_seed(config.seed, cases[c].index, spec.key)) for spec in specs]
    seconds = time_case(config, entries, per)
    return concat([timing_record("experiment", {"problem": config.name, "case": cases[c].label, "pose": cases[c].index,
                                                "solver": spec.key, "run": np.arange(len(s)), "runs": 1,
                                                "seconds": np.asarray(s, dtype=float), "mode": ALONE})
                   for spec, s in zip(specs, seconds)]).to_dict(orient="list")


def _task(config: ExperimentConfig, mech, cases, problems, batched, a: int, fp: str) -> dict:
    """Entry ``a``'s task: its runs on every case, or (``solutions: all``) every case's solution set."""
    if wants_every_solution(config.algorithms[a]):
        return search_cases(config, mech, cases, a, fp)
    return _solve_one(config, mech, cases, problems, batched, a, fp)


def solve_task(payload: dict) -> dict:
    """Worker: one algorithm of an experiment on all its cases, rebuilt from the payload."""
    config = experiment_from_dict(json.loads(payload["config"]), "experiment task")
    mech, cases, problems, batched = _prepare(config, Path(payload["folder"]) if payload.get("folder") else None)
    return _task(config, mech, cases, problems, batched, payload["algorithm"], payload["fingerprint"])


def record_problem(task: Task, rec, config: ExperimentConfig, cases: list[Case]) -> str | None:
    """Why ``rec`` (a task file read back by ``--resume``) is not the finished record of
    ``task``: its algorithm, one table of run rows and one trace per case, each row this
    task's case, solver and run, and per-iteration arrays of the runs' shape."""
    if not isinstance(rec, dict):
        return f"holds a JSON {type(rec).__name__}, not a task record"
    return reason_or_none(lambda: _sets_or_runs_problem(task, rec, config, cases))


def _sets_or_runs_problem(task: Task, rec: dict, config: ExperimentConfig, cases: list[Case]) -> str | None:
    if wants_every_solution(config.algorithms[task.payload["algorithm"]]):
        return set_record_problem(task, rec, config, cases)
    return _record_problem(task, rec, config, len(cases))


def _record_problem(task: Task, rec: dict, config: ExperimentConfig, n_cases: int) -> str | None:
    a = task.payload["algorithm"]
    spec = config.algorithms[a]
    if rec["algorithm"] != a or rec["solver"] != spec.key or isinstance(rec["algorithm"], bool):
        return "its algorithm is not the one its file name names"
    rows, traces = rec["rows"], rec["trace"]
    if not isinstance(rows, list) or len(rows) != n_cases or not isinstance(traces, list) or len(traces) != n_cases:
        return f"rows, trace: not one table per case ({n_cases})"
    runs = config.runs
    for i, (cols, trace) in enumerate(zip(rows, traces)):
        if not isinstance(cols, dict) or any(not isinstance(v, list) or len(v) != runs for v in cols.values()):
            return f"rows[{i}]: not a table of {runs} run rows"
        if cols.get("solver") != [spec.key] * runs or cols.get("pose") != [i] * runs \
                or cols.get("run") != list(range(runs)):
            return f"rows[{i}]: its solver, pose or runs are not this task's"
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in cols.get("final_fitness", [None])):
            return f"rows[{i}].final_fitness: not numbers"
        if not isinstance(trace, dict) or sorted(trace) != sorted(TRACE_COLUMNS) \
                or len({len(v) for v in trace.values() if isinstance(v, list)}) != 1:
            return f"trace[{i}]: not the columns {', '.join(TRACE_COLUMNS)} of equal length"
    result = dataclass_from_json(Result, rec["curves"])
    want = (runs,) if n_cases == 1 else (n_cases, runs)
    if np.shape(result.fitness) != want or np.shape(result.history)[:-1] != want:
        return f"curves: runs of shape {np.shape(result.fitness)}, expected {want}"
    if not math.isfinite(float(rec["wall_s"])) or float(rec["wall_s"]) < 0:
        return "wall_s: not a non-negative finite number"
    return None


def merge_experiment(config: ExperimentConfig, plan: Plan, ran: Ran, *, source: str | None = None,
                     **_) -> RunResult:
    """The experiment's :class:`~fkopt.run.result.RunResult` from its tasks' records: the run
    record and the trace, case by case (every algorithm of case 1, then case 2, ...), the
    timing record (each batch's share per run and the runs its timing tasks timed alone; none
    when the plan has none: ``fkopt check``) and the curves (:class:`ExperimentOwn`). The
    ``solutions: all`` entries add no runs: their sets go to ``own.sets`` (case by case), each
    search's time to the timing record as one batch; an experiment of only such entries has no
    run record and no trace (None)."""
    merging = time.perf_counter()
    ctx: _Context = plan.context
    mech, cases, problems = ctx.mech, ctx.cases, ctx.problems
    done = [ran.records[t.id] for t in plan.tasks]                  # one per algorithm, in config order
    every = [wants_every_solution(spec) for spec in config.algorithms]
    answered = [(spec, rec, dataclass_from_json(Result, rec["curves"]))
                for spec, rec, e in zip(config.algorithms, done, every) if not e]
    searched = [merge_sets(config, cases, rec) for rec, e in zip(done, every) if e]
    sets = [entry[i] for i in range(len(cases)) for entry in searched]      # case-major too
    solves, rows, traces = [], [], []
    for i, (case, problem) in enumerate(zip(cases, problems)):    # case-major, as the reports expect
        for spec, rec, result in answered:
            r = result if len(cases) == 1 else result.case(i)
            pos = problem.position_error(r.x_history) if hasattr(problem, "position_error") else None
            solves.append(CaseSolve(case, spec, problem, r, pos))
            rows.append(run_record("experiment", {k: v for k, v in rec["rows"][i].items() if k != "kind"}))
            traces.append(trace_frame(rec["trace"][i]))
    batches = [timing_record("experiment", {"problem": config.name, "case": s.case.label, "pose": s.case.index,
                                            "solver": s.spec.key, "run": s.result.run_ids, "runs": 1,
                                            "seconds": s.result.time_per_run, "mode": BATCH}) for s in solves]
    searches = [timing_record("experiment", {"problem": config.name, "case": s.case.label, "pose": s.case.index,
                                             "solver": s.spec.key, "run": [0], "runs": 1, "seconds": [s.wall_s],
                                             "mode": BATCH}) for s in sets]
    alone = [timing_record("experiment", {k: v for k, v in ran.records[t.id].items() if k != "kind"})
             for t in plan.timed]
    # the run's own time, wherever and however long before the plan was built
    wall = ctx.prepared_s + ran.wall_s + (time.perf_counter() - merging)
    # solves computed elsewhere (fkopt reproduce's workers) or resumed: their own time, measured where they ran
    wall += sum(ran.records[t.id]["wall_s"] * len(cases) for t in plan.tasks if t.id not in ran.computed)
    own = ExperimentOwn(mech, cases, solves, {rec["solver"]: float(rec["wall_s"]) for rec in done}, sets)
    timing = concat([_timing_in_order(alone, batches, solves), *searches]) if solves else concat(searches)
    return RunResult(config, concat(rows) if rows else None, timing, concat_traces(traces) if traces else None, own,
                     wall, source, list(ran.computed))


def _timing_in_order(alone: list, batches: list, solves: list[CaseSolve]):
    """The timing record as it always was ordered: per (case, algorithm), its runs timed alone,
    then its batch."""
    timed = concat(alone) if alone else None
    frames = []
    for s, batch in zip(solves, batches):
        if timed is not None:
            mine = timed[(timed["case"] == s.case.label) & (timed["solver"] == s.spec.key)]
            if len(mine):
                frames.append(mine)
        frames.append(batch)
    return concat(frames).reset_index(drop=True)


def case_rows(config: ExperimentConfig, mech, case: Case, spec: AlgorithmSpec, r: Result, seed: int,
              position_error_history: np.ndarray | None):
    """The run record's rows (:mod:`fkopt.run.record`) of one algorithm's runs on one case."""
    thr = config.threshold
    outputs = outputs_of(mech, r.x)
    cols = {"problem": config.name, "case": case.label, "pose": case.index, "solver": spec.key,
            "run": r.run_ids, "task_seed": seed, "final_fitness": r.fitness, "evaluations": r.evaluations,
            "iterations_done": r.iterations_done,
            # first iteration at which the run's final best-so-far fitness was reached
            "iterations_to_best": np.argmax(r.history <= r.history[:, -1:], axis=1)}
    if thr is not None:
        cols["iterations_to_threshold"] = r.iterations_to(thr)
        cols["evaluations_to_threshold"] = r.evaluations_to(thr)
    cols.update({f"x_{name}": r.x[:, j] for j, name in enumerate(r.variable_names)})
    if mech.kind == "serial":
        cols.update({f"pose_{name}": outputs[:, j] for j, name in enumerate(mech.pose_names)})
    if position_error_history is not None:
        cols["position_error"] = position_error_history[:, -1]
    target = case.target if case.target is not None else case.reference
    if target is not None:
        err = pose_error(mech, outputs, target)
        cols.update({f"abs_error_{name}": err[:, j] for j, name in enumerate(mech.pose_names)})
    cols.update({f"final_{key}": r.extras[key][:, -1] for key in r.extras})
    return run_record("experiment", cols)


def run_experiment(config: ExperimentConfig, *, progress: Callable[[str, int, int], None] | None = None,
                   source: str | None = None, timing: bool = True) -> RunResult:
    """Run every (case, algorithm) task in this process; ``progress(label, done, total)`` is
    called after each algorithm (one task of the one runner, :func:`experiment_plan`).

    ``timing=False`` skips the single-run timing sample (:mod:`.timing`): what ``fkopt check``
    reruns for, since timings are never compared.

    Every algorithm solves all cases in one call of :func:`fkopt.solve` (cases x runs rows),
    each case with its own :func:`task_seed`, so a case's numbers are those it gets alone.
    """
    plan = experiment_plan(config, source, timing=timing)
    return merge_experiment(config, plan, run_tasks(plan, progress=progress), source=source)
