"""``fkopt reproduce``: run every config under a folder (any kind) and write the report.

:func:`plan` loads and validates every file and checks every output folder before anything
runs (one bad file: nothing is computed); :func:`run_all` runs them through the one pipeline
(:func:`fkopt.run.pipeline.run_config`; each result is written aside and swapped into place;
studies keep no task files) and :func:`fkopt.reproduce.report.write_report` writes REPORT.md,
TIMING.md and index.csv. ``reproduce`` regenerates results by design: a stored result of a
changed config is replaced (``force``).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from fkopt.errors import FkoptError
import fkopt.kinbench  # noqa: F401 (registers every built-in kind of config)
from fkopt.run.pipeline import config_kind, load_any, plan_config, prepare_output, run_config
from fkopt.files import output_folder
from fkopt.reproduce.engine import is_claims_file
from fkopt.run.executors import execute
from fkopt.run.tasks import run_remote


@dataclass
class Planned:
    path: Path
    config: Any
    tasks: int
    plan: Any = None       # the validated plan (fkopt.run.pipeline.plan_config), run as it is


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
    files = sorted(f for f in configs.rglob("*.yaml") if not is_claims_file(f))   # claims are no experiment
    if not files:
        raise FkoptError(f"{configs}: no experiment files (*.yaml) found")
    planned = []
    seen: dict[tuple, Path] = {}
    output_folder(out)
    for f in files:
        config = load_any(f)
        if not config_kind(config).reproduced:        # benchmark suites: fkopt suite / make bench-suite
            continue
        config_plan = plan_config(config, str(f), str(f))       # the one validation of this config
        tasks = len(config_plan.tasks) + len(config_plan.timed)
        key = tuple(config.folder_parts)
        if key in seen:
            raise FkoptError(f"{f}: writes {'/'.join(key)}, like {seen[key]}; paper/name must differ")
        seen[key] = f
        try:
            prepare_output(config, out, force=True)
        except FkoptError as err:
            raise FkoptError(f"{f}: {err}") from None
        planned.append(Planned(f, config, tasks, config_plan))
    return planned


def default_jobs() -> int:
    """Worker processes of ``fkopt reproduce`` by default: the CPUs this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def _cost(config) -> float:
    """A rough relative cost of an experiment's solves (its evaluation budget), to start the
    longest first (the workers then finish close together)."""
    cases = config.cases.random if hasattr(config.cases, "random") else len(config.cases)
    return sum(cases * config.runs * (a.population or config.population) * (a.iterations or config.iterations)
               for a in config.algorithms)


def solve_in_parallel(planned: list[Planned], jobs: int,
                      solving: Callable[[int, int], None] | None = None) -> dict[int, dict]:
    """The tasks of every config whose plan may run anywhere (experiments' solves), all of them
    in one pool of ``jobs`` worker processes; records by config index, then task id.

    Only such tasks run there: they are deterministic (each (case, run) has its own stream), so
    the numbers are those of a serial run. Everything measured in seconds that the report judges
    -- the single-run timing samples of :mod:`fkopt.run.timing`, and whole studies and
    assembly searches, whose times are claims -- runs afterwards in this process, one at a
    time, with the workers gone; only the batch's amortised time (``amortised_ms_per_run``, for
    information) is measured in a worker next to another.
    """
    if jobs <= 1:
        return {}
    items = []
    for i, p in enumerate(planned):
        plan = p.plan if p.plan is not None else config_kind(p.config).plan(p.config, str(p.path))
        if plan.anywhere:
            items += [(_cost(p.config) / len(plan.tasks), i, (plan.solve, t.id, t.payload)) for t in plan.tasks]
    if len({i for _, i, _ in items}) < 2:
        return {}
    items.sort(key=lambda item: -item[0])       # the longest first: the workers finish close together
    solved: dict[int, dict] = {}
    count = [0]

    def done(result) -> None:
        index, (ident, record) = result
        solved.setdefault(index, {})[ident] = record
        count[0] += 1
        if solving:
            solving(count[0], len(items))
    execute(_run_indexed, [(i, item) for _, i, item in items], jobs=jobs, on_result=done)
    return solved


def _run_indexed(pair):
    """Worker: one task of config ``index`` -> (index, (task id, record))."""
    index, item = pair
    return index, run_remote(item)


def run_all(planned: list[Planned], out: str | Path,
            started: Callable[[Planned], Callable[[str, int, int], None] | None] | None = None,
            finished: Callable[[Done], None] | None = None, *, jobs: int = 1,
            solving: Callable[[int, int], None] | None = None) -> list[Done]:
    """Run the planned configs in order; ``started(p)`` may return a progress callback.

    ``jobs > 1``: the experiments' solves first run in that many worker processes
    (:func:`solve_in_parallel`, ``solving(done, total)`` after each); then, here and one at a
    time, every config is completed (timing sample, studies, assembly searches) and written.
    """
    solved = solve_in_parallel(planned, jobs, solving)
    done = []
    for i, p in enumerate(planned):
        progress = started(p) if started else None
        outcome = run_config(p.config, out, source=str(p.path), progress=progress, force=True, keep_tasks=False,
                             solved=solved.get(i), plan=p.plan)
        d = Done(p.path, outcome.folder, outcome.wall_s, len(list(outcome.folder.iterdir())))
        done.append(d)
        if finished:
            finished(d)
    return done
