"""One pipeline for every kind of config file: load, validate, plan the output, run, write, check.

Kinds (the file's ``kind:`` key; an experiment file has none) are views of one thing, a set of
tasks (problem x poses x solver x runs) whose records a writer turns into files:

* an experiment (:mod:`fkopt.kinds.experiment`) is a suite of one
  problem with listed poses: one task per algorithm, solving every case in one batch;
* ``kind: study`` (:mod:`fkopt.kinds.study`, :mod:`fkopt.kinds.study.kind`) is a suite of one mechanism with
  a generated pose set: one task per (pose chunk, algorithm) or per tracked algorithm;
* ``kind: assembly`` (:mod:`fkopt.kinds.assembly.kind`) is a suite whose solver returns many
  solutions: one task, the search;
* ``kind: suite`` (kinbench, :mod:`fkopt.kinbench`, :mod:`fkopt.kinbench.kind`): many problems,
  pose sets and solvers, one task per (problem, solver).

Each kind is a :class:`~fkopt.run.tasks.Kind` (function objects) that registers itself in
:data:`fkopt.run.kinds.KINDS`; the engine imports no kind. A kind says only how to read and
validate its file, how it turns into a :class:`~fkopt.run.tasks.Plan`, how the records become its
result object and which files it writes. Everything else is shared, once:

* :func:`load_any` -- the one loader (:func:`fkopt.files.load_mapping`: size, UTF-8, no aliases,
  no duplicate keys) and the one validator entry point (pydantic, one-line errors);
* :func:`plan_config` -- the one validation: the config's plan, which builds everything a run
  needs without running it (unknown names, poses outside the workspace, ...), and the refusal of
  a job whose memory estimate does not fit (:func:`check_memory`); :func:`run_config` runs that
  plan, so nothing is validated or built twice (:func:`validate_any`: its task count);
* :func:`prepare_output` -- the results folder, checked before any computation (safe names,
  inside ``--out``, writable, not a file) and the overwrite policy (:func:`check_overwrite`);
* :func:`run_config` -- the one runner (:func:`fkopt.run.tasks.run_tasks`: this process,
  worker processes or Dask; task files with digests and ``--resume``), the one writer
  (:func:`fkopt.run.writers.write_outputs`, written aside and swapped into place);
* :func:`rerun_files` -- the same tasks in this process into a scratch folder, for the one
  checker (:mod:`fkopt.reproduce.check`).

Below the tasks, one solve path (:func:`fkopt.run.solving.solve_cases`): an experiment's
cases, a study's pose chunks, a tracking step's trajectories and a suite's poses are all cases of
one problem, seeded by :func:`fkopt.run.solving.task_seed`. Adding a config kind is one package
that registers its :class:`~fkopt.run.tasks.Kind` (with its outputs); adding an output is one maker
function and one :class:`~fkopt.run.writers.Output` line in its kind.
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fkopt.errors import FkoptError
from fkopt.files import load_mapping, output_folder, parse_json, read_stored, run_lock, short_token, write_atomically
from fkopt.run.writers import write_outputs
from fkopt.run.config_base import numeric_fields
from fkopt.run.executors import check_scheduler, validate_executor
from fkopt.run.kinds import KINDS, config_kind, kind_of  # noqa: F401 (the registry, re-exported)
from fkopt.run.memory import check_memory
from fkopt.run.tasks import TASKS, Kind, Plan, TaskStore, read_manifest, run_tasks, work_folder


@dataclass
class Outcome:
    folder: Path
    wall_s: float
    result: Any = None
    computed: list = field(default_factory=list)    # ids of the tasks this run computed (not resumed)


def from_dict(data: dict, where: str):
    """Validate a config mapping of any kind; errors are one line naming ``where``."""
    kind = data.get("kind")
    if kind is not None and not isinstance(kind, str):
        raise FkoptError(f"{where}: kind: expected text, got {kind!r}")
    try:
        k = kind_of(kind)
    except FkoptError as err:
        raise FkoptError(f"{where}: {err}") from None
    return k.from_dict(data, where)


def load_any(path: str | Path):
    """An experiment, study or assembly config, by the file's ``kind``; a config with file fields
    (a URDF's ``geometry.file``) resolves its relative paths beside the file, as ``load_config``."""
    config = from_dict(load_mapping(path, "config fields"), str(path))
    if "_folder" in getattr(type(config), "__private_attributes__", {}):
        config._folder = Path(path).parent
    return config


def plan_config(config, where: str | None = None, source: str | None = None, timing: bool = True) -> Plan:
    """The one validation of a run: ``config``'s plan, which builds everything the run needs
    (mechanism, cases, problems, pose sets) and solves nothing, and its memory estimate, from
    what the plan built. Bad input fails here, one line naming ``where``; the plan is what
    :func:`run_config` then runs (``plan=``), so nothing is validated or built twice."""
    kind = config_kind(config)
    try:
        plan = kind.plan(config, source, timing=timing)
        check_memory(kind.validate(config, plan), "this job (runs x population x iterations x cases)")
    except FkoptError as err:
        raise FkoptError(f"{where}: {err}" if where else str(err)) from None
    return plan


def validate_any(config, where: str | None = None) -> int:
    """Build everything a config needs without running it (:func:`plan_config`); returns its
    number of tasks (what a progress bar counts: solves and planned timing tasks)."""
    plan = plan_config(config, where, where)
    return len(plan.tasks) + len(plan.timed)


# -- output ----------------------------------------------------------------------------------------
def stored_config(folder: Path) -> dict | None:
    """The config recorded in ``folder/meta.json``, else in the manifest of its kept task files
    (a finished study whose tables were deleted is still fkopt's); None when there is none."""
    try:
        data = parse_json(read_stored(folder, "meta.json"), "meta.json") if (folder / "meta.json").exists() else None
    except FkoptError:
        data = None
    if data is None:
        data = read_manifest(folder / TASKS)
    return data["config"] if isinstance(data, dict) and isinstance(data.get("config"), dict) else None


def check_overwrite(folder: Path, config, force: bool) -> None:
    """A folder that exists may be replaced only by a result of the same numbers, or with force.

    * not a results folder (no readable meta.json, not empty): never replaced;
    * made from a config whose result-changing fields differ (anything but title, description,
      printed values and check): replaced only with ``force``.
    """
    if not folder.exists():
        return
    stored = stored_config(folder)
    if stored is None:
        if any(folder.iterdir()):
            raise FkoptError(f"{folder}: exists and is not a results folder (no readable meta.json); "
                             "refusing to replace it (move it away or choose another --out)")
        return
    if force:
        return
    # a kind may record its config without fields left at defaults newer than its stored results
    dump = config.stored_dump() if hasattr(config, "stored_dump") else config.model_dump(mode="json")
    old, new = numeric_fields(stored), numeric_fields(dump)
    if old != new:
        changed = changed_fields(old, new)
        shown = "; ".join(changed[:3]) + (f"; and {len(changed) - 3} more" if len(changed) > 3 else "")
        raise FkoptError(f"{folder}: holds a result of a different config ({shown}); "
                         "rerun with --force to replace it")


def _short(value) -> str:
    return short_token(json.dumps(value, sort_keys=True, default=str))


def changed_fields(old, new, path: str = "") -> list[str]:
    """Where two config mappings differ, each as ``field.path: stored -> now`` (lists by index)."""
    if isinstance(old, dict) and isinstance(new, dict):
        out = []
        for key in sorted(set(old) | set(new), key=str):
            where = f"{path}.{key}" if path else str(key)
            if key not in new:
                out.append(f"{where}: {_short(old[key])} -> (removed)")
            elif key not in old:
                out.append(f"{where}: (absent) -> {_short(new[key])}")
            else:
                out += changed_fields(old[key], new[key], where)
        return out
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        return [c for i, (a, b) in enumerate(zip(old, new)) for c in changed_fields(a, b, f"{path}[{i}]")]
    return [] if old == new else [f"{path or 'config'}: {_short(old)} -> {_short(new)}"]


def prepare_output(config, out: str | Path, force: bool = False) -> Path:
    """The checked results folder of ``config`` under ``out`` (nothing is computed or written)."""
    folder = output_folder(out, *config.folder_parts)
    check_overwrite(folder, config, force)
    return folder


def run_config(config, out: str | Path, *, source: str | None = None, progress=None, force: bool = False,
               checked: bool = False, jobs: int = 1, executor: str = "local", scheduler: str | None = None,
               resume: bool = False, keep_tasks: bool = True, solved: dict | None = None,
               plan: Plan | None = None) -> Outcome:
    """Validate, check the output, run and write one config of any kind -- the one pipeline.

    The config's :class:`~fkopt.run.tasks.Plan` runs through
    :func:`~fkopt.run.tasks.run_tasks` (``jobs``/``executor``/``scheduler``; task files
    and ``resume`` for the kinds that keep them, which ``keep_tasks=False`` drops from the
    published folder); ``solved``: records of some tasks computed elsewhere (task id -> record,
    ``fkopt reproduce``'s worker pool). The kind's merge makes the result, every file of
    :data:`fkopt.run.writers.OUTPUTS` is written aside and swapped into place
    (:func:`fkopt.files.write_atomically`), and the work folder is removed.
    ``plan``: the config's validated plan (:func:`plan_config`; made here when None).
    ``checked=True``: the caller has already run :func:`prepare_output`.
    """
    kind = config_kind(config)
    validate_executor(executor, jobs, scheduler)
    if plan is None:
        plan = plan_config(config, source, source)
    if not checked:
        prepare_output(config, out, force)
    folder = output_folder(out, *config.folder_parts)   # safe, inside OUT, writable: before any work
    check_scheduler(executor, scheduler)                # reachable before a .partial is touched
    with run_lock(out, folder):      # one run per paper/name at a time
        return _run_locked(kind, plan, config, out, folder, source=source, progress=progress, force=force, jobs=jobs,
                           executor=executor, scheduler=scheduler, resume=resume, keep_tasks=keep_tasks,
                           solved=solved)


def _run_locked(kind: Kind, plan: Plan, config, out, folder: Path, *, source, progress, force, jobs, executor,
                scheduler, resume, keep_tasks, solved) -> Outcome:
    start = time.perf_counter()
    store = None
    if plan.stored:
        store = TaskStore(out, work_folder(out, config), folder, plan.name,
                          config.model_dump(mode="json"), plan.fingerprint)
    try:
        ran = run_tasks(plan, executor=executor, jobs=jobs, scheduler=scheduler, store=store, resume=resume,
                        progress=progress, done=solved)
    except Exception:
        if store is not None and not store.digests:     # a failure before any task finished: nothing to resume
            store.discard()
        raise
    result = kind.merge(config, plan, ran, source=source, timing=True, folder=folder)
    result.folder = folder
    wall = getattr(result, "wall_s", None)        # the kind's own account (solves made elsewhere too)
    wall = time.perf_counter() - start if wall is None else wall

    def fill(tmp: Path) -> None:
        write_outputs(kind, result, tmp)
        if store is not None and plan.keep and keep_tasks:
            store.publish_into(tmp)

    def publish_check(target: Path) -> None:
        # checked again at publish time: another fkopt run may have written a result of a
        # different config there while this one computed (two runs at once into one paper/name)
        try:
            check_overwrite(target, config, force)
        except FkoptError as err:
            raise FkoptError(f"{err} (it was written by another fkopt run while this one computed; "
                             "nothing of this run was published)") from None

    write_atomically(folder, fill, publish_check)
    if store is not None:
        store.discard()
    return Outcome(folder, wall, result, list(ran.computed))


def run_in_memory(config, source: str | None = None, *, progress=None, timing: bool = True,
                  jobs: int = 1, executor: str = "local", scheduler: str | None = None):
    """Every task of ``config`` computed (no task files, nothing written); the kind's result."""
    kind = config_kind(config)
    plan = kind.plan(config, source, timing=timing)
    ran = run_tasks(plan, executor=executor, jobs=jobs, scheduler=scheduler, progress=progress)
    return kind.merge(config, plan, ran, source=source, timing=timing, folder=None)


def rerun_files(config, folder: Path, source: str | None = None) -> None:
    """Rerun ``config`` in this process and write its deterministic files into ``folder``
    (``fkopt check``)."""
    result = run_in_memory(config, source, timing=False)
    write_outputs(config_kind(config), result, folder, figures=False, timing=False)
