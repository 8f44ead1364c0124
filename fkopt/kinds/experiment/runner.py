"""Run an experiment: every algorithm on every case for ``runs`` seeded runs.

Seeds: the (case, algorithm) task with case index c and algorithm label L gets the integer
seed ``SeedSequence([seed, c, crc32(L)]).generate_state(1)[0]`` and its run k the k-th child
stream of that (see :mod:`fkopt.numerics.streams`). Reordering algorithms in a file or running one
algorithm alone therefore reproduces the same numbers -- and so does batching: each algorithm
solves all cases of the experiment in one :func:`fkopt.solve` call (cases x runs rows), passing
these per-case seeds, and the result is sliced back into one record per (case, algorithm).
"""
from __future__ import annotations

import json
import time
import zlib
from pathlib import Path
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from fkopt import registry
from fkopt.errors import FkoptError
from fkopt.run.record import ALONE, BATCH, concat, run_record, timing_record
from fkopt.problems import fk_problem, ik_problem
from fkopt.numerics.rotations import wrap_degrees
from fkopt.solve import Result, chunk_size, make_algorithm, solve
from fkopt.kinds.experiment.config import ExperimentConfig, RandomCases
from fkopt.run.config_base import AlgorithmSpec, files_folder
from fkopt.run.solving import (_check_in_bounds, build_mechanism, make_problem, outputs_of, pose_error, solve_cases,  # noqa: F401
                               start_point, task_seed)
from fkopt.run.tasks import Plan, Ran, Task, run_tasks
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
class TaskRecord:
    case: Case
    spec: AlgorithmSpec
    problem: object
    result: Result
    seed: int
    wall_s: float
    outputs: np.ndarray                # (runs, n_pose) the pose each run's answer corresponds to
    position_error_history: np.ndarray | None = None
    single_run_ids: np.ndarray | None = None   # runs timed alone (see .timing)
    single_run_s: np.ndarray | None = None


@dataclass
class ExperimentResult:
    config: ExperimentConfig
    mechanism: object
    cases: list[Case]
    records: list[TaskRecord]
    wall_s: float
    source: str | None = None
    record: object = None              # the run record (:mod:`fkopt.run.record`): one row per (case, algorithm, run)
    timing: object = None              # the timing record (:mod:`fkopt.run.record`): its timed samples

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
        make_algorithm(spec.name, spec.params)   # unknown names/parameters fail here
        start_point(spec, mech)
    problems = [build_problem(config, mech, c) for c in cases]
    for spec in config.algorithms:       # a batch that cannot fit in memory fails here, not midway
        try:
            chunk_size(len(cases), config.runs, spec.population or config.population,
                       spec.iterations or config.iterations, len(mech.unknown_names), batch=config.batch,
                       snapshots=len(config.snapshots), x_history=keeps_x_history(config, mech))
        except FkoptError as err:
            raise FkoptError(f"algorithms[{spec.key}]: {err}") from None
    return mech, cases, problems


def keeps_x_history(config: ExperimentConfig, mech) -> bool:
    """Does the experiment need each run's best-so-far point per iteration (variables.png, the
    position error of a serial arm)? Otherwise only the final points are kept."""
    return "variables" in config.figures or mech.kind == "serial"


def batched_problem(config: ExperimentConfig, mech, cases: list[Case]):
    """One problem with a case axis holding every case's inputs (see :mod:`fkopt.problems`)."""
    return make_problem(config, mech, np.stack([c.inputs for c in cases]))


@dataclass
class Solved:
    """What solving one algorithm on every case produced: the batched result and the wall time
    of the solve per case (amortised). Picklable, so another process can compute it
    (``fkopt reproduce --jobs N``); it holds no mechanism or problem."""

    result: Result
    wall_s: float


def _prepare(config: ExperimentConfig, folder: Path | None):
    mech, cases, problems = validate_experiment(config, folder)
    one = len(cases) == 1         # a single case keeps the single-target problem (no case axis)
    batched = problems[0] if one else batched_problem(config, mech, cases)
    return mech, cases, problems, batched


def _seeds(config: ExperimentConfig, cases: list[Case], spec: AlgorithmSpec) -> list[int]:
    return [task_seed(config.seed, case.index, spec.key) for case in cases]


def _solve_one(config: ExperimentConfig, mech, cases, batched, spec: AlgorithmSpec) -> Solved:
    seeds = _seeds(config, cases, spec)
    start = time.perf_counter()
    result = solve_cases(config, spec, batched, seeds[0] if len(cases) == 1 else seeds, x0=start_point(spec, mech),
                         batch=config.batch, snapshots=config.snapshots, x_history=keeps_x_history(config, mech))
    return Solved(result, (time.perf_counter() - start) / len(cases))    # amortised over the cases


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
    listed poses), and (``timing``) one timing task per timed case (:mod:`.timing`'s sample:
    every algorithm's runs solved alone, interleaved), run after the solves, in this process
    (:attr:`~fkopt.run.tasks.Plan.timed`). In this process a task uses the live mechanism
    and cases; a worker process rebuilds them from the payload (:func:`solve_task`), with the
    same numbers."""
    started = time.perf_counter()
    folder = files_folder(config, source)        # relative files resolve beside the config
    mech, cases, problems, batched = _prepare(config, folder)
    data = config.model_dump_json()
    tasks = [Task(f"a{a:02d}", {"config": data, "folder": None if folder is None else str(folder), "algorithm": a},
                  spec.key)
             for a, spec in enumerate(config.algorithms)]
    timed_cases, per = sample_plan(len(cases), config.runs)
    timed = [Task(f"t{c:02d}", {"timing": c, "runs": per}, f"timing · {cases[c].label}")
             for c in range(timed_cases)] if timing else []

    def local(payload: dict):
        if "timing" in payload:
            c = payload["timing"]
            entries = [(spec, problems[c], task_seed(config.seed, cases[c].index, spec.key))
                       for spec in config.algorithms]
            return time_case(config, entries, payload["runs"])
        return _solve_one(config, mech, cases, batched, config.algorithms[payload["algorithm"]])
    return Plan(tasks, solve_task, local=local, anywhere=True, timed=timed,
                context=_Context(mech, cases, problems, batched, time.perf_counter() - started), name=config.name)


def solve_task(payload: dict) -> Solved:
    """Worker: one algorithm of an experiment on all its cases, rebuilt from the payload."""
    from fkopt.kinds.experiment.config import experiment_from_dict
    config = experiment_from_dict(json.loads(payload["config"]), "experiment task")
    mech, cases, _, batched = _prepare(config, Path(payload["folder"]) if payload.get("folder") else None)
    return _solve_one(config, mech, cases, batched, config.algorithms[payload["algorithm"]])


def merge_experiment(config: ExperimentConfig, plan: Plan, ran: Ran, *, source: str | None = None,
                     **_) -> ExperimentResult:
    """The experiment's records from its tasks' :class:`Solved` s and the single-run times of
    its timing tasks (none when the plan has none: ``fkopt check``)."""
    merging = time.perf_counter()
    ctx: _Context = plan.context
    mech, cases, problems = ctx.mech, ctx.cases, ctx.problems
    by_algorithm: list[list[TaskRecord]] = []
    for task, spec in zip(plan.tasks, config.algorithms):
        done: Solved = ran.records[task.id]
        seeds = _seeds(config, cases, spec)
        recs = []
        for i, (case, problem) in enumerate(zip(cases, problems)):
            r = done.result if len(cases) == 1 else done.result.case(i)
            pos_hist = problem.position_error(r.x_history) if hasattr(problem, "position_error") else None
            recs.append(TaskRecord(case, spec, problem, r, seeds[i], done.wall_s, outputs_of(mech, r.x), pos_hist))
        by_algorithm.append(recs)
    # case-major order, as the reports expect (every algorithm of case 1, then case 2, ...)
    records = [recs[i] for i in range(len(cases)) for recs in by_algorithm]
    for task in plan.timed:               # seconds per algorithm of one timed case
        for recs, seconds in zip(by_algorithm, ran.records[task.id]):
            rec = recs[task.payload["timing"]]
            rec.single_run_ids, rec.single_run_s = np.arange(len(seconds)), np.asarray(seconds)
    # the run's own time, wherever and however long before the plan was built
    wall = ctx.prepared_s + ran.wall_s + (time.perf_counter() - merging)
    # solves computed elsewhere (fkopt reproduce's workers): their own time, measured where they ran
    wall += sum(ran.records[t.id].wall_s * len(cases) for t in plan.tasks if t.id not in ran.computed)
    return ExperimentResult(config, mech, cases, records, wall, source, experiment_record(config, mech, records),
                            experiment_timing(config, records))


def experiment_timing(config: ExperimentConfig, records: list[TaskRecord]):
    """The timing record (:mod:`fkopt.run.record`): every run timed alone, and every run's share
    of its batch (the amortised time, for information)."""
    frames = []
    for rec in records:
        common = {"problem": config.name, "case": rec.case.label, "pose": rec.case.index, "solver": rec.spec.key}
        if rec.single_run_s is not None:
            frames.append(timing_record("experiment", {**common, "run": rec.single_run_ids, "runs": 1,
                                                       "seconds": rec.single_run_s, "mode": ALONE}))
        frames.append(timing_record("experiment", {**common, "run": rec.result.run_ids, "runs": 1,
                                                   "seconds": rec.result.time_per_run, "mode": BATCH}))
    return concat(frames)


def experiment_record(config: ExperimentConfig, mech, records: list[TaskRecord]):
    """The run record (:mod:`fkopt.run.record`) of an experiment's task records, in their order."""
    thr = config.threshold
    frames = []
    for rec in records:
        r, case = rec.result, rec.case
        cols = {"problem": config.name, "case": case.label, "pose": case.index, "solver": rec.spec.key,
                "run": r.run_ids, "task_seed": rec.seed, "final_fitness": r.fitness, "evaluations": r.evaluations,
                "iterations_done": r.iterations_done,
                # first iteration at which the run's final best-so-far fitness was reached
                "iterations_to_best": np.argmax(r.history <= r.history[:, -1:], axis=1)}
        if thr is not None:
            cols["iterations_to_threshold"] = r.iterations_to(thr)
            cols["evaluations_to_threshold"] = r.evaluations_to(thr)
        cols.update({f"x_{name}": r.x[:, j] for j, name in enumerate(r.variable_names)})
        if mech.kind == "serial":
            cols.update({f"pose_{name}": rec.outputs[:, j] for j, name in enumerate(mech.pose_names)})
        if rec.position_error_history is not None:
            cols["position_error"] = rec.position_error_history[:, -1]
        target = case.target if case.target is not None else case.reference
        if target is not None:
            err = pose_error(mech, rec.outputs, target)
            cols.update({f"abs_error_{name}": err[:, j] for j, name in enumerate(mech.pose_names)})
        cols.update({f"final_{key}": r.extras[key][:, -1] for key in r.extras})
        frames.append(run_record("experiment", cols))
    return concat(frames)


def run_experiment(config: ExperimentConfig, *, progress: Callable[[str, int, int], None] | None = None,
                   source: str | None = None, timing: bool = True) -> ExperimentResult:
    """Run every (case, algorithm) task in this process; ``progress(label, done, total)`` is
    called after each algorithm (one task of the one runner, :func:`experiment_plan`).

    ``timing=False`` skips the single-run timing sample (:mod:`.timing`): what ``fkopt check``
    reruns for, since timings are never compared.

    Every algorithm solves all cases in one call of :func:`fkopt.solve` (cases x runs rows),
    each case with its own :func:`task_seed`, so a case's numbers are those it gets alone.
    """
    plan = experiment_plan(config, source, timing=timing)
    return merge_experiment(config, plan, run_tasks(plan, progress=progress), source=source)
