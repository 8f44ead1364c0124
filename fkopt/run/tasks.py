"""The one runner: a config's tasks, run on an executor, kept as task files, resumed.

Every kind of config (:mod:`fkopt.run.pipeline`) turns into a :class:`Plan`: a list of
:class:`Task` s -- an experiment's algorithm on all its cases, a study's chunk of poses for one
algorithm, a suite's (problem, solver), an assembly search -- and the worker function that
computes one (a module-level function object, pickled by reference, so a task can run in this
process, a local worker process or on a Dask worker; :mod:`.executors`). A task's numbers never
depend on where or next to what it ran: each carries its own seeds.

:func:`run_tasks` runs the tasks a caller has not already computed and hands every record to
``progress``. With a :class:`TaskStore` (the kinds whose plans say ``stored``: experiments,
studies and suites) each finished record is written at once as ``tasks/<task id>.json`` in the hidden work
folder ``OUT/<paper>/.<name>.partial/`` (:func:`work_folder`; a temporary file renamed into
place, so a file is complete or absent), with its SHA-256 in ``tasks/manifest.json``. An
interrupted run therefore loses at most the tasks that were running, and ``resume=True`` keeps
every task file that (1) still has its recorded digest, (2) belongs to a config with the same
fingerprint and (3) passes the plan's own check of a record; anything else is one line naming
the file. The previous result ``OUT/<paper>/<name>/`` is untouched until the new one is
written; its ``tasks/`` (when the kind keeps them) seed a resume of a finished run.
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping

from fkopt.errors import FkoptError
from fkopt.files import inside, parse_json, read_stored, stored_sha256, write_file_atomically, write_json_atomically
from fkopt.progress import listening
from fkopt.run.executors import execute, worker_count

TASKS = "tasks"
MANIFEST = "manifest.json"
#: Manifests of task folders written by earlier fkopt releases (read by ``fkopt check``).
OLD_MANIFESTS = ("study.json",)
#: How to carry on after a refused task file.
REDO = "delete it to recompute that task, or rerun without --resume to start over"


def task_files(folder: Path) -> list[Path]:
    """The JSON files of a task folder, sorted, but the atomic writer's hidden temporaries
    (``.<name>.<random>.json``: a task id never starts with a dot)."""
    return sorted(p for p in Path(folder).glob("*.json") if not p.name.startswith("."))


@dataclass(frozen=True)
class Task:
    id: str              # unique in its plan; the task file's name (letters, digits, ``_.+-``)
    payload: Any         # what the worker function needs (picklable; JSON-able when stored)
    label: str = ""      # for progress


@dataclass
class Plan:
    """The tasks of one config and how to compute, keep and check them."""

    tasks: list[Task]
    solve: Callable[[Any], Any]    # payload -> record; a module-level function (picklable by reference)
    fingerprint: str = ""          # of everything that changes a task's numbers
    stored: bool = False           # records are JSON and kept as task files (--resume)
    keep: bool = False             # the published folder keeps its tasks/ (studies)
    #: why a reused record is not this task's finished record (None: it is); stored plans only
    check: Callable[[Task, Any], str | None] | None = None
    #: in-process shortcut for the worker function (the live objects, no rebuild from the payload)
    local: Callable[[Any], Any] | None = None
    #: may the tasks run in worker processes next to other work without changing anything the
    #: result judges? (experiments: yes, their timing sample runs afterwards; studies' tracking
    #: times and assembly searches are timed claims: no)
    anywhere: bool = False
    context: Any = None            # what the kind's merge needs (mechanism, cases, pose sets, ...)
    name: str = ""
    #: tasks that measure wall time (an experiment's single-run timing sample,
    #: :mod:`fkopt.run.timing`): run after every task above, in this process through
    #: ``local``, one at a time with nothing else running; never on a worker, never taken from
    #: ``done`` or a task file, never stored. Empty when the caller wants no timings (``fkopt check``).
    timed: list[Task] = field(default_factory=list)


@dataclass(frozen=True)
class Kind:
    """What the pipeline (:mod:`fkopt.run.pipeline`) needs to know about one kind of config:
    how to read and check it, the tasks it turns into (:class:`Plan`) and how their records
    become the result that :func:`fkopt.run.writers.write_outputs` writes. Running, task files,
    resuming, writing aside and swapping in, and rerunning for ``fkopt check`` are the pipeline's.
    Defined here, below every kind's module; a kind registers itself with the engine
    (:func:`fkopt.run.kinds.register`), so the kinds import the engine and never the reverse."""

    name: str
    from_dict: Callable[[dict, str], Any]          # (mapping, where) -> validated config
    #: (config, source, timing=True) -> its tasks (timing=False: no Plan.timed); building the plan
    #: builds everything a run needs (mechanism, cases, problems, pose sets) and solves nothing: it
    #: is the validation of a run (:func:`fkopt.run.pipeline.plan_config`)
    plan: Callable[..., Plan]
    #: (config, plan) -> estimated bytes of the run, from what the plan built (nothing built again)
    validate: Callable[[Any, Plan], int]
    #: (config, plan, ran, source=, timing=, folder=) -> the :class:`fkopt.run.result.RunResult`
    #: the writers read (what only this kind has in its ``own`` slot)
    merge: Callable[..., Any]
    #: the files of its results folder, in the order they are written (:class:`fkopt.run.writers.Output`,
    #: function objects: tables before the figures drawn from them)
    outputs: tuple = ()
    #: result -> the content of its meta.json (without the file digests)
    meta: Callable[[Any], dict] | None = None
    #: the pydantic model of its file (the config reference, fkopt.run.config_reference)
    model: type | None = None
    #: (result, folder) -> what the command line prints after a run: a summary table, or lines
    #: (the first continues the folder's line); None: the folder alone
    console: Callable[[Any, Any], Any] | None = None
    #: does ``fkopt reproduce`` run its files? (a suite: no; ``fkopt suite`` / ``make bench-suite``)
    reproduced: bool = True
    #: (config, runs.csv frame) -> [(where, rows of that problem, make the problem)]: the problems
    #: whose fitness ``fkopt check`` recomputes from the stored ``x`` (None: no such check)
    stored_problems: Callable[[Any, Any], list] | None = None
    #: (folder, config, meta) -> [(file, where, column, stored, recomputed, rule)]: what ``fkopt
    #: check`` judges again in a stored folder besides rerunning it (a suite: its clock answers)
    recheck: Callable[[Any, Any, dict], list] | None = None
    #: (stored result, results root) -> its section of REPORT.md (None: the experiment section)
    report_section: Callable[[Any, Any], str] | None = None
    #: (folder, meta) -> the IOH functions of a stored folder (:class:`fkopt.run.iohformat.Function`)
    #: that ``fkopt export`` writes; None: no per-run trace to export (a study, an assembly search)
    ioh_functions: Callable[[Any, dict], list] | None = None
    #: record columns its runs.csv leaves out: those its folder fixes (one kind, one problem) and
    #: those it names otherwise (:func:`fkopt.run.record.runs_table`)
    not_in_runs: frozenset = frozenset()
    #: record column -> the name its files give it (experiment and study folders: ``solver`` is
    #: ``algorithm``, :data:`fkopt.run.record.ALGORITHM_NAMES`)
    file_names: Mapping[str, str] = field(default_factory=dict, hash=False)


@dataclass
class Ran:
    records: dict[str, Any]                            # task id -> record, in plan order
    computed: list[str] = field(default_factory=list)  # ids computed by this call
    wall_s: float = 0.0


def reason_or_none(why: Callable[[], str | None]) -> str | None:
    """``why()`` -- a plan's check of a record read back from a task file -- with a malformed
    record's missing field or wrong type as the reason instead of an exception."""
    try:
        return why()
    except KeyError as err:
        return f"field {str(err.args[0])[:40]!r} is missing"
    except (TypeError, ValueError, IndexError, AttributeError) as err:
        return f"{type(err).__name__}: {str(err)[:120]}"


def work_folder(out: str | Path, config) -> Path:
    """Where an unfinished run of ``config`` (any kind) keeps its task files:
    ``OUT/<paper>/.<name>.partial/`` (hidden: never taken for a result)."""
    paper, name = config.folder_parts
    return Path(out) / paper / f".{name}.partial"


def run_remote(item: tuple[Callable[[Any], Any], str, Any]) -> tuple[str, Any]:
    """Worker entry: ``(worker function, task id, payload) -> (task id, record)``."""
    solve, ident, payload = item
    return ident, solve(payload)


#: SHA-256 of a task file, read bounded (a FIFO or a device where a task file should be is one line).
sha256 = stored_sha256


def read_manifest(tasks: Path) -> dict | None:
    """The manifest of a task folder (or an older release's), None when there is none."""
    for name in (MANIFEST, *OLD_MANIFESTS):
        if not (tasks / name).exists():
            continue
        try:
            data = parse_json(read_stored(tasks, name, unpack=False), str(tasks / name))
        except FkoptError:
            continue
        return data if isinstance(data, dict) else None
    return None


class TaskStore:
    """Task files of one run under ``work/tasks`` (every path checked inside ``out``)."""

    def __init__(self, out: str | Path, work: Path, final: Path, name: str, config: dict, fingerprint: str):
        self.out, self.work, self.final = out, Path(work), Path(final)
        self.tasks = self.work / TASKS
        self.name, self.config, self.fingerprint = name, config, fingerprint
        self.digests: dict[str, str] = {}
        for path in (self.work, self.tasks, self.tasks / MANIFEST, self.final, self.final / TASKS):
            inside(out, path)

    # -- opening ---------------------------------------------------------------------------------
    def open(self, plan: Plan, resume: bool) -> dict[str, Any]:
        """Make the work folder ready; returns the finished records that may be reused."""
        if not resume:
            if self.work.is_symlink():
                self.work.unlink()
            shutil.rmtree(self.work, ignore_errors=True)
        elif not self.work.exists() and (self.final / TASKS).is_dir():
            # resume a finished run: start from a copy of its task files (the folder stays as it is)
            sources = task_files(self.final / TASKS)
            for path in sources:
                inside(self.out, path)
            self.tasks.mkdir(parents=True)
            for path in sources:
                shutil.copyfile(path, self.tasks / path.name)
        records = self._reusable(plan) if resume else {}
        self.tasks.mkdir(parents=True, exist_ok=True)
        inside(self.out, self.tasks)
        self.digests = {k: v for k, v in self.digests.items() if k in records}
        self._write_manifest()
        return records

    def _reusable(self, plan: Plan) -> dict[str, Any]:
        stored = read_manifest(self.tasks) if self.tasks.is_dir() else None
        if stored is None:
            return {}
        if stored.get("fingerprint") not in (None, self.fingerprint):
            raise FkoptError(f"--resume: the tasks kept for {self.final} belong to another version of {self.name} "
                             "(its config or pose sets changed); rerun without --resume to start over")
        digests = stored.get("tasks")
        if not isinstance(digests, dict):
            return {}     # written by an older fkopt, without digests: nothing is trusted, all redone
        self.digests = {str(k): str(v) for k, v in digests.items()}
        planned = {t.id: t for t in plan.tasks}
        out = {}
        for path in sorted(self.tasks.glob(".*.json")):
            # an unfinished temporary of the atomic writer (fkopt.files.write_file_atomically: ".<name>.<random>.json"),
            # left where an interrupt or a killed worker came between its creation and its rename: never a task
            path.unlink(missing_ok=True)
        for path in task_files(self.tasks):
            if path.name in (MANIFEST, *OLD_MANIFESTS):
                continue
            inside(self.out, path, "--resume")
            data = read_stored(self.tasks, path.name, unpack=False)    # once: the bytes hashed are the bytes read
            if self.digests.get(path.stem) != hashlib.sha256(data).hexdigest():
                raise FkoptError(f"{path}: changed since fkopt wrote it (its SHA-256 is not the one recorded in "
                                 f"{MANIFEST}); {REDO}")
            try:
                rec = json.loads(data.decode("utf-8"))
            except (ValueError, RecursionError) as err:
                raise FkoptError(f"{path}: unreadable task file ({type(err).__name__}); {REDO}") from None
            if isinstance(rec, dict) and rec.get("fingerprint") not in (None, self.fingerprint):
                raise FkoptError(f"{path}: belongs to another version of {self.name} (its config or pose sets changed); "
                                 "rerun without --resume to start over")
            task = planned.get(path.stem)
            problem = ("no task of this run has that id" if task is None
                       else plan.check(task, rec) if plan.check else None)
            if problem:
                raise FkoptError(f"{path}: not a finished task of this run ({problem}); {REDO}")
            out[path.stem] = rec
        return out

    # -- writing ---------------------------------------------------------------------------------
    def _write_manifest(self) -> None:
        write_json_atomically(self.tasks / MANIFEST,
                              {"name": self.name, "fingerprint": self.fingerprint, "config": self.config,
                               "tasks": dict(sorted(self.digests.items()))}, separators=(",", ":"))

    def add(self, ident: str, record: Any) -> None:
        path = inside(self.out, self.tasks / f"{ident}.json")
        data = json.dumps(record, separators=(",", ":")).encode("utf-8")
        # The manifest names the file's digest before the file appears: a Ctrl-C between the two
        # leaves a named task without a file (recomputed by --resume), never a finished file the
        # manifest does not name (which --resume must refuse as changed since fkopt wrote it).
        self.digests[ident] = hashlib.sha256(data).hexdigest()
        self._write_manifest()
        write_file_atomically(path, lambda p: p.write_bytes(data))

    def publish_into(self, folder: Path) -> None:
        """Move the task files into the folder about to be published."""
        inside(self.out, self.tasks)
        os.replace(self.tasks, Path(folder) / TASKS)

    def discard(self) -> None:
        shutil.rmtree(self.work, ignore_errors=True)


def task_file_problems(folder: Path) -> list[tuple[str, str]]:
    """(file, problem) for every task file of a published ``folder/tasks`` whose bytes no longer
    have the SHA-256 its manifest recorded when it was written, or that no record names
    (``fkopt check``). A folder written before digests were recorded has none to compare: ``[]``
    (its task files are never reused by ``--resume`` either)."""
    tasks = Path(folder) / TASKS
    stored = read_manifest(tasks) if tasks.is_dir() else None
    digests = stored.get("tasks") if isinstance(stored, dict) else None
    if not isinstance(digests, dict):
        return []
    out = []
    files = {p.stem: p for p in task_files(tasks) if p.name not in (MANIFEST, *OLD_MANIFESTS)}
    for ident in sorted(set(files) | set(digests)):
        path = files.get(ident)
        if path is None:
            out.append((f"{TASKS}/{ident}.json", "missing"))
        elif ident not in digests:
            out.append((f"{TASKS}/{path.name}", f"not recorded in {MANIFEST}"))
        elif path.is_symlink() or sha256(path) != digests[ident]:
            out.append((f"{TASKS}/{path.name}", "changed since written"))
    return out


#: Seconds between reports of a running task's fraction (fkopt.progress) to ``progress.running``.
RUNNING_EVERY_S = 0.2


def _within(progress, label: str, done: int, total: int):
    """A :func:`fkopt.progress.listening` callback for a running task: when ``progress`` has a
    ``running`` method, ``progress.running(label, done + fraction, total)``, at most every 0.2 s
    (a plain ``progress(label, done, total)`` callable hears finished tasks only, whole numbers)."""
    running = getattr(progress, "running", None)
    if running is None:
        return None
    last = [0.0]

    def heard(fraction: float) -> None:
        now = time.perf_counter()
        if now - last[0] >= RUNNING_EVERY_S:
            last[0] = now
            running(label, done + fraction, total)
    return heard


def run_tasks(plan: Plan, *, executor: str = "local", jobs: int = 1, scheduler: str | None = None,
              store: TaskStore | None = None, resume: bool = False,
              progress: Callable[[str, int, int], None] | None = None,
              done: dict[str, Any] | None = None) -> Ran:
    """Every task of ``plan`` not in ``done`` (records computed elsewhere, e.g. by ``fkopt
    reproduce``'s worker pool) nor reusable from ``store`` (``resume``); ``progress(label, done,
    total)`` after each. An exception (a failed task, KeyboardInterrupt, one raised by
    ``progress``) stops the run; with a store, every task finished so far stays on disk."""
    start = time.perf_counter()
    timed = {t.id for t in plan.timed}
    # timings are measured by this run, never taken from elsewhere
    records: dict[str, Any] = {k: v for k, v in (done or {}).items() if k not in timed}
    if store is not None:
        records.update(store.open(plan, resume))
    labels = {t.id: t.label for t in plan.tasks + plan.timed}
    total = len(plan.tasks) + len(plan.timed)
    computed: list[str] = []

    def finished(item: tuple[str, Any]) -> None:
        ident, record = item
        if store is not None and ident not in timed:
            store.add(ident, record)
        records[ident] = record
        computed.append(ident)
        if progress:
            progress(labels[ident], len(records), total)

    if progress and records:
        progress("resumed", len(records), total)
    pending = [t for t in plan.tasks if t.id not in records]
    if executor == "local" and worker_count(jobs, len(pending)) == 1:
        for t in pending:                # in this process: the bar also moves inside each task
            # (fkopt.progress: iterations, rows); plan.local uses the live objects, nothing rebuilt
            solve = plan.local or plan.solve
            with listening(_within(progress, t.label, len(records), total)):
                record = solve(t.payload)
            finished((t.id, record))
    else:
        execute(run_remote, [(plan.solve, t.id, t.payload) for t in pending], executor=executor, jobs=jobs,
                scheduler=scheduler, on_result=finished)
    missing = [t.id for t in plan.tasks if t.id not in records]
    if missing:  # pragma: no cover - execute() raises before this can happen
        raise FkoptError(f"{plan.name}: {len(missing)} task(s) did not finish (first: {missing[0]})")
    for t in plan.timed:                 # after every solve, here, alone (see Plan.timed)
        finished((t.id, plan.local(t.payload)))
    return Ran({t.id: records[t.id] for t in plan.tasks + plan.timed}, computed, time.perf_counter() - start)
