"""One pipeline for every kind of config file: load, validate, plan the output, run, write, check.

Kinds (the file's ``kind:`` key; an experiment file has none):

* experiments: :mod:`fkopt.experiment.config` (:data:`EXPERIMENT` below);
* ``kind: assembly``: all forward solutions, :mod:`fkopt.experiment.assembly`;
* ``kind: study``: workspace studies, :mod:`fkopt.study` (its :class:`Kind` is in
  :mod:`fkopt.study.kind`);
* ``kind: suite``: benchmark suites (kinbench), :mod:`fkopt.kinbench` (:mod:`fkopt.kinbench.kind`).

Each kind is a :class:`Kind`, named in :data:`KINDS` by a ``"module:attribute"`` string imported
on first use (like :mod:`fkopt.registry`), so this floor never imports the study floor above it,
and adding a config kind is one module plus one line here and its list of files in
:data:`fkopt.outputs.OUTPUTS` (which must stay on the floor of :mod:`fkopt.compare`, which reads
the roles). Everything else is shared:

* :func:`load_any` -- the one loader (:func:`fkopt.files.load_mapping`: size, UTF-8, no aliases,
  no duplicate keys) and the one validator entry point (pydantic, one-line errors);
* :func:`validate_any` -- builds everything a config needs without running it (unknown names,
  poses outside the workspace, ...) and refuses a job whose memory estimate does not fit
  (:func:`check_memory`);
* :func:`prepare_output` -- the results folder, checked before any computation (safe names,
  inside ``--out``, writable, not a file) and the overwrite policy (:func:`check_overwrite`);
* :func:`run_config` -- run and write (aside, then swapped into place);
* :func:`rerun_files` -- rerun into a scratch folder, for ``fkopt check``.

What the kinds share beyond this module: one solve path (:func:`fkopt.experiment.runner.solve_cases`
-- an experiment's cases, a study's pose chunks and a tracking step's trajectories are all cases
of one problem), one list of output files with their roles and one writer (:mod:`fkopt.outputs`),
one checker (:mod:`fkopt.reproduce.check` through :func:`rerun_files`). What stays a study's own:
its pose sets, its task files (the unit of ``--jobs``, Dask and ``--resume``) and its
statistics; a study keeps per-(pose, run) records, not the per-iteration histories an
experiment's figures need.
"""
from __future__ import annotations

import importlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from ..errors import FkoptError
from ..files import load_mapping, output_folder
from ..outputs import write_outputs, write_result

#: kind -> "module:attribute" of its :class:`Kind`.
KINDS: dict[str, str] = {
    "experiment": "fkopt.experiment.kinds:EXPERIMENT",
    "study": "fkopt.study.kind:STUDY",
    "assembly": "fkopt.experiment.assembly:ASSEMBLY",
    "suite": "fkopt.kinbench.kind:SUITE",
}
#: Share of the currently available memory a job may be estimated to need.
MEMORY_SHARE = 0.8


@dataclass(frozen=True)
class Kind:
    """What the pipeline needs to know about one kind of config."""

    name: str
    from_dict: Callable[[dict, str], Any]          # (mapping, where) -> validated config
    validate: Callable[[Any], tuple[int, int]]     # config -> (tasks, estimated bytes); no work done
    run: Callable[..., "Outcome"]                  # (config, out, source=, progress=, **options)
    rerun_files: Callable[[Any, Path, str | None], None]   # deterministic files into a folder


@dataclass
class Outcome:
    folder: Path
    wall_s: float
    result: Any = None


def kind_of(name: str | None) -> Kind:
    key = name or "experiment"
    if key not in KINDS:
        raise FkoptError(f"kind: '{name}' unknown; allowed: {', '.join(k for k in KINDS if k != 'experiment')} "
                         "(an experiment file has no kind)")
    module, attr = KINDS[key].split(":")
    return getattr(importlib.import_module(module), attr)


def config_kind(config) -> Kind:
    return kind_of(getattr(config, "kind", None))


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


def available_memory() -> int:
    """Bytes of memory available now (``MemAvailable``; else the physical memory)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError):
        pass
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 1 << 62


def check_memory(needed: int, what: str) -> None:
    """Refuse a job estimated to need more than :data:`MEMORY_SHARE` of the available memory."""
    avail = available_memory()
    if needed > MEMORY_SHARE * avail:
        raise FkoptError(f"{what} needs about {needed / 2**30:.1f} GiB of memory, more than the "
                         f"{avail / 2**30:.1f} GiB available; reduce runs, population, iterations or cases")


def validate_any(config, where: str | None = None) -> int:
    """Build everything a config needs without running it; returns its number of tasks."""
    try:
        tasks, needed = config_kind(config).validate(config)
        check_memory(needed, "this job (runs x population x iterations x cases)")
    except FkoptError as err:
        raise FkoptError(f"{where}: {err}" if where else str(err)) from None
    return tasks


# -- output ----------------------------------------------------------------------------------------
def stored_config(folder: Path) -> dict | None:
    """The config recorded in ``folder/meta.json`` (None when there is none or it is unreadable)."""
    try:
        data = json.loads((folder / "meta.json").read_text(encoding="utf-8"))
        return data["config"] if isinstance(data, dict) and isinstance(data.get("config"), dict) else None
    except (OSError, ValueError, KeyError):
        return None


def check_overwrite(folder: Path, config, force: bool) -> None:
    """A folder that exists may be replaced only by a result of the same numbers, or with force.

    * not a results folder (no readable meta.json, not empty): never replaced;
    * made from a config whose result-changing fields differ (anything but title, description,
      printed values and check): replaced only with ``force``.
    """
    from .config import numeric_fields
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
    if numeric_fields(stored) != numeric_fields(config.model_dump(mode="json")):
        raise FkoptError(f"{folder}: holds a result of a different config (its result-changing fields "
                         "differ); rerun with --force to replace it")


def prepare_output(config, out: str | Path, force: bool = False) -> Path:
    """The checked results folder of ``config`` under ``out`` (nothing is computed or written)."""
    folder = output_folder(out, *config.folder_parts)
    check_overwrite(folder, config, force)
    return folder


def run_config(config, out: str | Path, *, source: str | None = None, progress=None, force: bool = False,
               checked: bool = False, **options) -> Outcome:
    """Validate, check the output, run and write one config of any kind.

    ``checked=True``: the caller has already run :func:`validate_any` and :func:`prepare_output`.
    """
    kind = config_kind(config)
    if not checked:
        validate_any(config, source)
        prepare_output(config, out, force)

    def publish_check(folder: Path) -> None:
        # checked again at publish time: another fkopt run may have written a result of a
        # different config there while this one computed (two runs at once into one paper/name)
        try:
            check_overwrite(folder, config, force)
        except FkoptError as err:
            raise FkoptError(f"{err} (it was written by another fkopt run while this one computed; "
                             "nothing of this run was published)") from None
    options.setdefault("publish_check", publish_check)
    return kind.run(config, out, source=source, progress=progress, **options)


def rerun_files(config, folder: Path, source: str | None = None) -> None:
    """Rerun ``config`` in this process and write its deterministic files into ``folder``."""
    config_kind(config).rerun_files(config, folder, source)


# -- experiments -----------------------------------------------------------------------------------
def _experiment_validate(config) -> tuple[int, int]:
    from ..solve import batch_bytes, chunk_size
    from .runner import keeps_x_history, validate_experiment
    mech, cases, _ = validate_experiment(config)
    dim, keep_x = len(mech.unknown_names), keeps_x_history(config, mech)
    need = 0   # every algorithm's records stay in memory until the folder is written: the solves' sum
    for spec in config.algorithms:
        pop = spec.population or config.population
        its = spec.iterations or config.iterations
        size = chunk_size(len(cases), config.runs, pop, its, dim, batch=config.batch,
                          snapshots=len(config.snapshots), x_history=keep_x)
        need += batch_bytes(len(cases) * config.runs, size, pop, its, dim, len(config.snapshots), keep_x)
        need += algorithm_resources(spec, pop, its, dim)
    return len(config.algorithms) * len(cases), need


def algorithm_resources(spec, population: int, iterations: int, dim: int) -> int:
    """An algorithm's own memory beyond fkopt's arrays (an adapter's library population), or a
    one-line error naming it when its settings cannot run -- for every algorithm of a config,
    before the first one starts (:meth:`fkopt.algorithms.base.Algorithm.resources`)."""
    from ..solve import make_algorithm
    try:
        return int(make_algorithm(spec.name, spec.params).resources(population, iterations, dim))
    except FkoptError as err:
        raise FkoptError(f"algorithms[{spec.key}]: {err}") from None


def _experiment_run(config, out, *, source=None, progress=None, solved=None, publish_check=None, **_) -> Outcome:
    from .runner import run_experiment
    er = run_experiment(config, source=source, progress=progress, solved=solved)
    return Outcome(write_result("experiment", er, out, publish_check), er.wall_s, er)


def _experiment_rerun(config, folder: Path, source: str | None) -> None:
    from .runner import run_experiment
    write_outputs("experiment", run_experiment(config, source=source, timing=False), folder,
                  figures=False, timing=False)


def _experiment_from_dict(data: dict, where: str):
    from .config import experiment_from_dict
    if "kind" in data:
        data = {k: v for k, v in data.items() if k != "kind"}
    return experiment_from_dict(data, where)


EXPERIMENT = Kind("experiment", _experiment_from_dict, _experiment_validate, _experiment_run, _experiment_rerun)

