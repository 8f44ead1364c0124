"""``fkopt reproduce``: run every config under a folder (any kind) and write the report.

:func:`plan` loads and validates every file and checks every output folder before anything
runs (one bad file: nothing is computed); :func:`run_all` runs them through the one pipeline
(:func:`fkopt.experiment.kinds.run_config`; each result is written aside and swapped into place;
studies keep no task files) and :func:`fkopt.reproduce.report.write_report` writes REPORT.md,
TIMING.md and index.csv. ``reproduce`` regenerates results by design: a stored result of a
changed config is replaced (``force``).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from ..errors import FkoptError
from ..experiment.kinds import load_any, prepare_output, run_config, validate_any
from ..files import output_folder


@dataclass
class Planned:
    path: Path
    config: Any
    tasks: int


@dataclass
class Done:
    path: Path
    folder: Path
    wall_s: float
    files: int


def plan(configs: str | Path, out: str | Path) -> list[Planned]:
    configs = Path(configs)
    if not configs.is_dir():
        raise FkoptError(f"--configs: {configs} is not a folder")
    files = sorted(configs.rglob("*.yaml"))
    if not files:
        raise FkoptError(f"{configs}: no experiment files (*.yaml) found")
    planned = []
    seen: dict[tuple, Path] = {}
    output_folder(out)
    for f in files:
        config = load_any(f)
        tasks = validate_any(config, str(f))
        key = tuple(config.folder_parts)
        if key in seen:
            raise FkoptError(f"{f}: writes {'/'.join(key)}, like {seen[key]}; paper/name must differ")
        seen[key] = f
        try:
            prepare_output(config, out, force=True)
        except FkoptError as err:
            raise FkoptError(f"{f}: {err}") from None
        planned.append(Planned(f, config, tasks))
    return planned


def run_all(planned: list[Planned], out: str | Path,
            started: Callable[[Planned], Callable[[str, int, int], None] | None] | None = None,
            finished: Callable[[Done], None] | None = None) -> list[Done]:
    """Run the planned configs in order; ``started(p)`` may return a progress callback."""
    done = []
    for p in planned:
        progress = started(p) if started else None
        outcome = run_config(p.config, out, source=str(p.path), progress=progress, force=True, keep_tasks=False)
        d = Done(p.path, outcome.folder, outcome.wall_s, len(list(outcome.folder.iterdir())))
        done.append(d)
        if finished:
            finished(d)
    return done
