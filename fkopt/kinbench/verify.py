"""Re-verify a stored v3 board from its stored answers (``fkopt check`` runs this on a suite).

The clock track's times vary from run to run, so its files are timing files and a rerun's are
never compared with them byte for byte. What does not vary is how the board follows from the
answers: every stored answer (``answers.csv.gz``: the joints or pose a solver returned, from a
run here or a submission) is judged again with fkopt's FK against the frozen query it answered,
and the board (``leaderboard-robots.csv``) is recomputed from the stored answers and
throughput. An edited answer, verdict or board number is a mismatch; so is a board row a
solver never earned.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from fkopt.kinbench.answer_checks import _close, differing_numbers, expected_solvers, key_problems, RTOL, RULE
from fkopt.kinbench.clock import (answer_prefix, OLD_ANSWER_COLUMNS, targets_of, track_arm, track_cases,
                                  track_settings, verdicts)
from fkopt.errors import FkoptError
from fkopt.files import csv_numbers, read_stored_csv
from fkopt.kinbench.branch_tracks import reverify as reverify_branch_tracks
from fkopt.kinbench.posesets import load_pose_sets
from fkopt.kinbench.reports import robots_board


def reverify(folder: Path, config) -> list[tuple[str, str, str, object, object, str]]:
    """(file, row, column, stored, recomputed, rule) of every disagreement; [] when the stored
    board follows from the stored answers. The answers are counted first
    (:func:`fkopt.kinbench.answer_checks.key_problems`): one per (query, solver, timeout) the
    config implies, so a failure deleted, a success repeated or a solver dropped is a mismatch
    naming answers.csv.gz, as is a missing or unreadable file (read bounded, :func:`read_stored_csv`).
    The all-solutions and paths tracks: :func:`fkopt.kinbench.branch_tracks.reverify`."""
    folder = Path(folder)
    if config.tracks is None:
        return []
    return _reverify_clock(folder, config) + reverify_branch_tracks(folder, config)


def _reverify_clock(folder: Path, config) -> list[tuple[str, str, str, object, object, str]]:
    """:func:`reverify` of the clock track (module docstring)."""
    if config.tracks.clock is None:
        return []
    clock = config.tracks.clock
    try:
        answers = read_stored_csv(folder, "answers.csv.gz", dtype={"problem": str, "robot": str, "solver": str})
    except FkoptError as err:
        missing = not (folder / "answers.csv.gz").exists() and not (folder / "answers.csv.gz").is_symlink()
        return [("answers.csv.gz", "-", "file", "missing" if missing else str(err), None,
                 "every answer of the clock track, read to recompute the board")]
    old = [c for c in OLD_ANSWER_COLUMNS if c in answers.columns and OLD_ANSWER_COLUMNS[c] not in answers.columns]
    if old:       # written before the record's names (issue 39): one line, never a KeyError
        return [("answers.csv.gz", "-", "columns", ", ".join(old),
                 ", ".join(OLD_ANSWER_COLUMNS[c] for c in old),
                 "answers written before the columns were renamed to the run record's names: re-store this board")]
    lacking = [c for c in ("problem", "pose", "solver", "given_timeout_ms", "position_m", "rotation_rad",
                           "leg_residual", "in_limits") if c not in answers.columns]
    if lacking:
        return [("answers.csv.gz", "-", lacking[0], "missing", None, "a column of every answers row")]
    sets, _ = load_pose_sets(config)
    out = []
    index = {p.name: k for k, p in enumerate(config.problems)}
    queries = dict(track_cases(config, sets))
    rule = "recomputed from the stored answer with fkopt's FK"
    submitted = [s.solver for s in clock.submissions]
    for robot in clock.problems:                         # every robot of the track answered, counted
        g = answers[answers["problem"] == robot]
        mech = track_arm(config, index[robot])
        Q = queries[index[robot]]
        _, _, timeouts = track_settings(clock, mech)
        why = key_problems(g, robot, len(Q), expected_solvers(clock, mech), timeouts, submitted)
        if why:
            out.append(("answers.csv.gz", robot, "answers", why, None, RULE))
            continue
        q = csv_numbers(g["pose"]).astype(int)          # range-checked by key_problems
        cols = [f"{answer_prefix(mech)}{d}" for d in range(Q.shape[1])]
        if any(c not in g.columns for c in cols):
            out.append(("answers.csv.gz", robot, cols[0], "missing", None, "the answer's columns"))
            continue
        answer = np.stack([csv_numbers(g[c]) for c in cols], axis=-1) if len(g) else np.zeros((0, len(cols)))
        v = verdicts(mech, answer, Q[q], targets_of(mech, Q[q]))
        for col in ("position_m", "rotation_rad", "leg_residual", "in_limits"):
            stored = g[col].to_numpy(float) if g[col].dtype == bool else csv_numbers(g[col])
            bad = ~_close(stored, np.asarray(v[col], float))
            for k in np.flatnonzero(bad)[:3]:
                r = g.iloc[k]
                out.append(("answers.csv.gz", f"{robot}/{r['solver']}/pose {r['pose']}", col, r[col],
                            np.asarray(v[col])[k], rule))
    strays = sorted(set(answers["problem"].astype(str)) - set(clock.problems))
    if strays:
        out.append(("answers.csv.gz", strays[0][:40], "problem", strays[0][:40], None,
                    "a problem of tracks.clock.problems"))
    if out:
        return out          # the board of uncounted or misjudged answers means nothing
    try:
        throughput = read_stored_csv(folder, "throughput.csv") if (folder / "throughput.csv").exists() else None
        board = robots_board(config, answers, throughput)
        key = ["solver", "robot", "timeout_ms"]
        if board is None:
            return out
        if not (folder / "leaderboard-robots.csv").exists():
            return [("leaderboard-robots.csv", "-", "file", "missing", None, "the board of the stored answers")]
        stored = read_stored_csv(folder, "leaderboard-robots.csv", dtype={"solver": str, "robot": str})
        stored["timeout_ms"] = csv_numbers(stored["timeout_ms"])
    except (FkoptError, KeyError) as err:
        return [("leaderboard-robots.csv", "-", "file", str(err)[:200], None, "a readable board")]
    board = board.astype({"timeout_ms": float})
    if len(stored) != len(board) or set(map(tuple, stored[key].values)) != set(map(tuple, board[key].values)):
        return out + [("leaderboard-robots.csv", "-", "rows", len(stored), len(board),
                       "one row per (solver, robot, timeout) of the stored answers")]
    merged = stored.merge(board, on=key, suffixes=("", "_recomputed"))
    for r, col in differing_numbers(merged, board, key):
        out.append(("leaderboard-robots.csv", f"{r['solver']}/{r['robot']}/{r['timeout_ms']:g} ms", col, r[col],
                        r[f"{col}_recomputed"], "recomputed from the stored answers"))
    return out
