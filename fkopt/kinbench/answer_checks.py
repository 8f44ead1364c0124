"""What the clock track's answers must be, counted and checked against the config that made
them: by ``fkopt check`` on a stored board (:func:`fkopt.kinbench.verify.reverify`) and by
``--resume`` on a clock-track task file (:func:`clock_record_problem`).

One answer per (query, solver, timeout) that the config implies: on each robot of
``tracks.clock.problems``, the reference and every solver of the track (``solvers`` for an arm,
``fk_solvers`` for a parallel mechanism, :func:`fkopt.kinbench.clock.track_settings`) answer
every query 0 .. n-1 of the track, either once (a solver without a wall-clock limit:
``given_timeout_ms`` empty) or once at every timeout of the track; a submission answers every
query of each robot it names, the same way. An answer deleted (a failure taken away), repeated
(a success counted twice), added, or a solver dropped changes the board without changing any
single verdict, so every stored answer's verdict being right proves nothing until they are
counted (issue 42).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from fkopt.files import csv_numbers, MAX_MAGNITUDE
from fkopt.kinbench.clock import (ANSWER_COLUMNS, answer_prefix, entry_of, is_ik, targets_of, track_arm,
                                  track_settings, verdicts)
from fkopt.kinbench.config import suite_from_dict

#: Relative tolerance of recomputed floats against the stored CSV's (written with 10 digits;
#: answers with 17).
RTOL = 1e-8


def _close(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a, b = np.asarray(a, float), np.asarray(b, float)
    same_inf = (np.isinf(a) & np.isinf(b) & (np.sign(a) == np.sign(b))) | (np.isnan(a) & np.isnan(b))
    with np.errstate(invalid="ignore"):
        return same_inf | np.isclose(a, b, rtol=RTOL, atol=1e-12)

def differing_numbers(merged: pd.DataFrame, board: pd.DataFrame, key) -> list[tuple[pd.Series, str]]:
    """(row of ``merged``, column) of every numeric column of a recomputed ``board`` whose stored
    value (``merged[col]``) differs from the recomputed one (``merged[col + "_recomputed"]``), at
    most three per column."""
    out = []
    for col in board.columns:
        if col in key or f"{col}_recomputed" not in merged or not pd.api.types.is_numeric_dtype(board[col]):
            continue
        bad = ~_close(csv_numbers(merged[col]), merged[f"{col}_recomputed"].to_numpy(float))
        out += [(merged.iloc[k], col) for k in np.flatnonzero(bad)[:3]]
    return out


RULE = "one answer per (query, solver, timeout) the config implies"


def key_problems(g: pd.DataFrame, robot: str, n: int, solvers, timeouts, optional=()) -> str | None:
    """Why the answers ``g`` of one robot are not one per (query, solver, timeout): every
    solver of ``solvers`` must answer, each of ``optional`` (submissions) may; ``n`` queries;
    ``timeouts`` (ms) of the track. None when they are."""
    names = g["solver"].astype(str).to_numpy()
    allowed = list(dict.fromkeys([*solvers, *optional]))
    extra = [s for s in pd.unique(names) if s not in allowed]
    if extra:
        return f"{robot}: answers of solver '{str(extra[0])[:40]}', which the config does not run on it " \
               f"(it runs {', '.join(allowed)})"
    query = csv_numbers(g["pose"])
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(query) | (query < 0) | (query >= n) | (query % 1 != 0)
    if bad.any():
        return f"{robot}: pose {g['pose'].astype(str).iloc[int(np.flatnonzero(bad)[0])][:30]} is not a query " \
               f"of the track (0..{n - 1})"
    given = csv_numbers(g["given_timeout_ms"])
    for name in allowed:
        mine = names == name
        count = int(mine.sum())
        if not count:
            if name in solvers:
                return f"{robot}/{name}: no answers; the config runs it on all {n} queries"
            continue
        t = given[mine]
        if np.isnan(t).all():
            want = n
            keys = list(zip(query[mine].astype(int).tolist(), [0.0] * count))
        elif np.isnan(t).any():
            return f"{robot}/{name}: given_timeout_ms empty on some answers only (once per query, or once per " \
                   "query and timeout)"
        else:
            want = n * len(timeouts)
            if not np.isin(t, np.asarray(timeouts, float)).all():
                return f"{robot}/{name}: given_timeout_ms {t[~np.isin(t, timeouts)][0]:g} is not a timeout of the " \
                       f"track ({', '.join(f'{x:g}' for x in timeouts)} ms)"
            keys = list(zip(query[mine].astype(int).tolist(), t.tolist()))
        if len(set(keys)) != count:
            return f"{robot}/{name}: {count - len(set(keys))} answers repeated"
        if count != want:
            return f"{robot}/{name}: {count} answers, the config implies {want}"
    return None


def expected_solvers(clock, mechanism) -> list[str]:
    """The solvers the clock track runs on ``mechanism``, the reference first."""
    solvers, reference, _ = track_settings(clock, mechanism)
    return list(dict.fromkeys([reference, *solvers]))


def _numbers(a, name: str, lo: float, hi: float, *, nan: bool = False) -> str | None:
    v = np.asarray(a, dtype=float)
    with np.errstate(invalid="ignore"):
        bad = (np.isnan(v) & (not nan)) | (~np.isnan(v) & ~((v >= lo) & (v <= hi)))
    if bad.any():
        return f"answers.{name}: row {int(np.flatnonzero(bad)[0])} is {v[bad][0]!r}, outside [{lo:g}, {hi:g}]" + \
            (" or NaN" if nan else "")
    return None


def clock_record_problem(task, rec: dict) -> str | None:
    """Why ``rec`` is not the finished clock-track record of ``task`` (a task file read back by
    ``--resume``; a digest proves the file is the one written, not what it holds): the robot,
    set, source and entry of every row; one answer per (query, solver, timeout) of the config;
    the times positive and finite; every verdict recomputed from the stored joints or pose with
    kinbench's own FK/IK (:func:`fkopt.kinbench.clock.verdicts`) -- joints moved with their
    verdicts kept are caught; the throughput rows' robots, solvers, batches and rates."""
    payload = task.payload
    from pathlib import Path
    config = suite_from_dict(payload["config"], "suite task")
    p = payload["problem"]
    robot = config.problems[p].name
    clock = config.tracks.clock
    arm = track_arm(config, p, Path(payload["folder"]) if payload["folder"] else None)
    queries = np.asarray(payload["queries"], dtype=float)
    n, dim = queries.shape
    answers = rec["answers"]
    cols = [*ANSWER_COLUMNS, *(f"{answer_prefix(arm)}{d}" for d in range(dim))]
    if sorted(answers) != sorted(cols):
        return f"answers: not the columns {', '.join(cols)}"
    lengths = {len(v) for v in answers.values()}
    if len(lengths) != 1:
        return "answers: columns of different lengths"
    for col in cols:
        if any(isinstance(v, (dict, list)) for v in answers[col]):
            return f"answers.{col}: not a column of plain values"
    g = pd.DataFrame(answers)
    for col, want in (("problem", robot), ("set", clock.set), ("source", "run")):
        wrong = g[col] != want
        if wrong.any():
            return f"answers.{col}: row {int(np.flatnonzero(wrong)[0])} is not {want!r}"
    _, _, timeouts = track_settings(clock, arm)
    why = key_problems(g, robot, n, expected_solvers(clock, arm), timeouts)
    if why:
        return why
    wrong = g["entry"] != g["solver"].map(entry_of)
    if wrong.any():
        return f"answers.entry: row {int(np.flatnonzero(wrong)[0])} is not its solver's entry"
    if any(not isinstance(v, bool) for v in g["claimed"]) or any(not isinstance(v, bool) for v in g["in_limits"]):
        return "answers.claimed, in_limits: not true/false"
    if any(not isinstance(v, str) for v in g["not_applicable"]):
        return "answers.not_applicable: not text"
    for col in ("seconds", "cpu_seconds", "reference_seconds", "given_timeout_ms", "position_m", "rotation_rad",
                "leg_residual", *cols[len(ANSWER_COLUMNS):]):
        if any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in g[col]):
            return f"answers.{col}: not numbers"
    big = float(np.finfo(float).max)
    why = (_numbers(g["seconds"], "seconds", 0, big) or _numbers(g["reference_seconds"], "reference_seconds", 0, big)
           or _numbers(g["cpu_seconds"], "cpu_seconds", 0, big, nan=True)
           or next(filter(None, (_numbers(g[c], c, -MAX_MAGNITUDE, MAX_MAGNITUDE, nan=True)
                                 for c in cols[len(ANSWER_COLUMNS):])), None))
    if why:
        return why
    q = g["pose"].to_numpy(int)
    answer = g[cols[len(ANSWER_COLUMNS):]].to_numpy(float)
    v = verdicts(arm, answer, queries[q], targets_of(arm, queries[q]))
    for col in ("position_m", "rotation_rad", "leg_residual", "in_limits"):
        bad = ~_close(g[col].to_numpy(float), np.asarray(v[col], float))
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            return f"answers.{col}: row {k} ({g['solver'].iloc[k]}, pose {q[k]}) is {g[col].iloc[k]!r}, " \
                   f"recomputed from its answer {np.asarray(v[col])[k]!r}"
    return _throughput_problem(config, arm, robot, rec.get("throughput"))


def _throughput_problem(config, arm, robot: str, rate) -> str | None:
    tp = config.tracks.throughput
    if tp is None:
        return None if rate is None else "throughput: present, but the config has no throughput track"
    if not isinstance(rate, dict) or any(not isinstance(v, list) for v in rate.values()):
        return "throughput: not a table"
    if not rate:
        return None
    need = ("solver", "robot", "entry", "batch", "queries_per_s", "reference", "reference_queries_per_s", "ratio")
    if any(c not in rate for c in need) or len({len(v) for v in rate.values()}) != 1:
        return f"throughput: not the columns {', '.join(need)} of equal length"
    t = pd.DataFrame(rate)
    solvers, reference, _ = track_settings(config.tracks.clock, arm)
    batches = list(tp.batches if is_ik(arm) else tp.fk_batches)
    if (t["robot"] != robot).any() or not t["solver"].isin(solvers).all() or (t["reference"] != reference).any():
        return "throughput: rows of another robot, solver or reference"
    if not t["batch"].isin(batches).all() or t.duplicated(["solver", "batch"]).any():
        return f"throughput.batch: not each of {batches} once per solver"
    for col in ("queries_per_s", "reference_queries_per_s", "ratio", *(c for c in t if c.startswith("success_"))):
        if any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in t[col]):
            return f"throughput.{col}: not numbers"
        hi = 1.0 if col.startswith("success_") else float(np.finfo(float).max)
        why = _numbers(t[col], col, 0, hi)
        if why:
            return why.replace("answers.", "throughput.")
    return None
