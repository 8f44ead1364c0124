"""The ``all-solutions`` and ``paths`` tracks (:mod:`.solution_sets`, :mod:`.paths`) as tasks of a
suite: one task per (track, arm) in the suite's plan (:func:`track_tasks`), its worker
(:func:`solve_task`) and --resume check (:func:`record_problem`), the merged answer tables
(:func:`merge_tables`), the files they make (``solutions.csv.gz``, ``leaderboard-solutions.csv``,
``paths.csv.gz``, ``leaderboard-paths.csv``: timing files) and ``fkopt check``'s re-verification
of the stored answers (:func:`reverify`)."""
from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.adapters.field import NotApplicable
from fkopt.errors import FkoptError
from fkopt.files import read_stored_csv
from fkopt.kinbench import paths as path_track
from fkopt.kinbench import solution_sets
from fkopt.kinbench.config import suite_from_dict
from fkopt.kinbench.posesets import problem_mechanism
from fkopt.registry import clock_solver
from fkopt.run.config_base import files_folder
from fkopt.run.tasks import Task

#: track -> (task-id prefix, answers file, board file)
FILES = {"all-solutions": ("a", "solutions.csv.gz", "leaderboard-solutions.csv"),
         "paths": ("w", "paths.csv.gz", "leaderboard-paths.csv")}


def _track(config, name: str):
    t = config.tracks
    return None if t is None else (t.all_solutions if name == "all-solutions" else t.paths)


def track_tasks(config, sets: dict, files: Path | None, data: dict, fingerprint: str) -> list[Task]:
    """One task per (track, arm): its frozen queries (all-solutions) or paths in the payload."""
    tasks = []
    folder = str(files) if files is not None else ""
    index = {p.name: k for k, p in enumerate(config.problems)}
    track = _track(config, "all-solutions")
    if track is not None and config.poses is not None:
        sets = solution_sets.full_sets(config, files)
    for name in (track.problems if track is not None else []):
        arm, fixed, _ = solution_sets.track_arms(config, name, files)
        Q = solution_sets.track_queries(config, sets, name, arm, fixed)
        tasks.append(Task(f"a{index[name]}", {"config": data, "folder": folder, "problem": index[name],
                                              "track": "all-solutions", "fingerprint": fingerprint,
                                              "queries": Q.tolist()}, f"{name} / all-solutions track"))
    if _track(config, "paths") is not None:
        for name, ends in path_track.load_path_sets(config, files).items():
            tasks.append(Task(f"w{index[name]}", {"config": data, "folder": folder, "problem": index[name],
                                                  "track": "paths", "fingerprint": fingerprint,
                                                  "ends": ends.tolist()}, f"{name} / paths track"))
    return tasks


def _load() -> list[float] | None:
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def solve_task(payload: dict) -> dict:
    """Worker: one track on one arm; every answer, JSON-able."""
    config = suite_from_dict(payload["config"], "suite task")
    files = Path(payload["folder"]) if payload["folder"] else None
    name = config.problems[payload["problem"]].name
    start, load_start, settings = time.perf_counter(), _load(), {}
    if payload["track"] == "all-solutions":
        track = config.tracks.all_solutions
        arm, fixed, solved = solution_sets.track_arms(config, name, files)
        answers = solution_sets.run_solutions(arm, solved, fixed, name, np.asarray(payload["queries"], float),
                                              list(track.solvers), reference=track.reference, seed=config.seed,
                                              settings=settings)
    else:
        track = config.tracks.paths
        arm = _path_arm(config, name, files)
        answers = path_track.run_paths(arm, name, np.asarray(payload["ends"], float), list(track.solvers),
                                       reference=track.reference, timeout_ms=track.timeout_ms, seed=config.seed,
                                       settings=settings)
    return {"fingerprint": payload["fingerprint"], "track": payload["track"], "problem": payload["problem"],
            "answers": answers.to_dict(orient="list"), "wall_s": time.perf_counter() - start,
            "load_avg": {"start": load_start, "end": _load()},
            "settings": json.loads(json.dumps(settings, default=str))}


def _path_arm(config, name: str, files: Path | None):
    arm, _ = problem_mechanism(next(p for p in config.problems if p.name == name),
                               files if files is not None else files_folder(config))
    if getattr(arm, "kind", None) != "serial" or not hasattr(arm, "chain"):
        raise FkoptError(f"tracks.paths.problems: '{name}' is not a serial arm with a chain (URDF, MJCF, DH)")
    return arm


def record_problem(task, rec: dict) -> str | None:
    """Why ``rec`` is not the finished record of track task ``task`` (a task file read back by
    --resume): its answers' columns, rows and every verdict recomputed (:func:`_problems`)."""
    if not isinstance(rec.get("answers"), dict) or not all(isinstance(v, list) for v in rec["answers"].values()):
        return "answers: not a table of answers"
    if len({len(v) for v in rec["answers"].values()}) != 1:
        return "answers: columns of different lengths"
    payload = task.payload
    config = suite_from_dict(payload["config"], "suite task")
    files = Path(payload["folder"]) if payload["folder"] else None
    name = config.problems[payload["problem"]].name
    found = _problems(config, payload["track"], name, pd.DataFrame(rec["answers"]), files,
                      np.asarray(payload.get("queries") or payload.get("ends"), float))
    return None if not found else f"answers {found[0][0]}: {found[0][1]} {str(found[0][2])[:60]} ({found[0][4]})"


def _problems(config, track: str, name: str, answers: pd.DataFrame, files, frozen: np.ndarray) -> list[tuple]:
    if track == "all-solutions":
        arm, _, solved = solution_sets.track_arms(config, name, files)
        return solution_sets.table_problems(config, answers, name, arm, solved, frozen)
    return path_track.table_problems(config, answers, name, _path_arm(config, name, files), frozen)


def validate(config, files: Path | None = None) -> None:
    """Every entry of both tracks built once on each of its arms: a missing package or an arm a
    package misreads is one line before any work."""
    for track in FILES:
        spec = _track(config, track)
        for name in (spec.problems if spec is not None else []):
            if track == "all-solutions":
                arm, fixed, _ = solution_sets.track_arms(config, name, files)
                options = {"fixed": fixed} if fixed else {}
            else:
                arm, options = _path_arm(config, name, files), {}
            for solver in dict.fromkeys([spec.reference, *spec.solvers]):
                try:
                    clock_solver(solver, arm, timeout=0.005, rng=np.random.default_rng(0), **options)
                except NotApplicable:         # a "not applicable" row of the board
                    continue
                except FkoptError as err:
                    raise FkoptError(f"tracks.{track}.solvers[{solver}] on problems[{name}]: {err}") from None


def merge_tables(config, plan, ran) -> dict[str, pd.DataFrame | None]:
    """{"all-solutions": every answer of the track or None, "paths": ...} of a finished plan."""
    out = {}
    for track in FILES:
        recs = [ran.records[t.id] for t in plan.tasks if t.payload.get("track") == track]
        out[track] = pd.concat([pd.DataFrame(r["answers"]) for r in recs], ignore_index=True) if recs else None
    return out


# -- the files ------------------------------------------------------------------------------------
def _answers(sr, track: str) -> pd.DataFrame | None:
    return (getattr(sr, "branch_answers", None) or {}).get(track)


def solutions_table(sr) -> pd.DataFrame | None:
    """solutions.csv.gz: every distinct answer of the all-solutions track with its verdict."""
    return _answers(sr, "all-solutions")


def paths_table(sr) -> pd.DataFrame | None:
    """paths.csv.gz: every waypoint's answer of the paths track with its verdict and joint step."""
    return _answers(sr, "paths")


def _solved_arms(config, names, files=None) -> dict:
    return {name: solution_sets.track_arms(config, name, files)[2] for name in names}


def solutions_board_table(sr, files: Path | None = None) -> pd.DataFrame | None:
    """leaderboard-solutions.csv (:func:`fkopt.kinbench.solution_sets.solutions_board`)."""
    a = _answers(sr, "all-solutions")
    if a is None or a.empty:
        return None
    track = sr.config.tracks.all_solutions
    arms = _solved_arms(sr.config, list(dict.fromkeys(a["problem"].astype(str))), files or getattr(sr, "files", None))
    return solution_sets.solutions_board(a, arms, reference=track.reference, analytic=track.analytic)


def paths_board_table(sr) -> pd.DataFrame | None:
    """leaderboard-paths.csv (:func:`fkopt.kinbench.paths.paths_board`)."""
    a = _answers(sr, "paths")
    if a is None or a.empty:
        return None
    return path_track.paths_board(a, reference=sr.config.tracks.paths.reference)


# -- fkopt check ------------------------------------------------------------------------------------
def reverify(folder: Path, config) -> list[tuple]:
    """(file, row, column, stored, recomputed, rule) of every stored answer of the two tracks that
    is missing, extra, or whose verdict fkopt's FK does not reproduce; then of every board number
    not recomputed from the stored answers."""
    from types import SimpleNamespace

    out, tables = [], {}
    for track, (_, answers_file, board_file) in FILES.items():
        spec = _track(config, track)
        if spec is None:
            continue
        try:
            a = read_stored_csv(folder, answers_file, dtype={"problem": str, "solver": str})
        except FkoptError as err:
            missing = not (Path(folder) / answers_file).exists()
            out.append((answers_file, "-", "file", "missing" if missing else str(err)[:200], None,
                        f"every answer of the {track} track"))
            continue
        if track == "all-solutions":
            sets = solution_sets.full_sets(config)
            frozen = {}
            for name in spec.problems:
                arm, fixed, _ = solution_sets.track_arms(config, name)
                frozen[name] = solution_sets.track_queries(config, sets, name, arm, fixed)
        else:
            frozen = path_track.load_path_sets(config)
        found = []
        if "problem" not in a.columns:
            found.append((answers_file, "-", "problem", "missing", None, "a column of every row"))
        else:
            strays = sorted(set(a["problem"].astype(str)) - set(spec.problems))
            if strays:
                found.append((answers_file, strays[0][:40], "problem", strays[0][:40], None,
                              f"a problem of tracks.{track}.problems"))
            for name in spec.problems:
                found += [(answers_file, *row) for row in
                          _problems(config, track, name, a[a["problem"] == name].reset_index(drop=True), None,
                                    frozen[name])]
        out += found
        if not found:
            tables[track] = a
    sr = SimpleNamespace(config=config, branch_answers=tables, files=None)
    if "all-solutions" in tables:
        out += solution_sets.board_mismatches(folder, FILES["all-solutions"][2], solutions_board_table(sr),
                                              ["problem", "solver"])
    if "paths" in tables:
        out += solution_sets.board_mismatches(folder, FILES["paths"][2], paths_board_table(sr), ["problem", "solver"])
    return out
