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
from types import SimpleNamespace

import numpy as np
import pandas as pd

#: Relative tolerance of recomputed floats against the stored CSV's (written with 10 digits;
#: answers with 17).
RTOL = 1e-8


def _close(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a, b = np.asarray(a, float), np.asarray(b, float)
    same_inf = (np.isinf(a) & np.isinf(b) & (np.sign(a) == np.sign(b))) | (np.isnan(a) & np.isnan(b))
    with np.errstate(invalid="ignore"):
        return same_inf | np.isclose(a, b, rtol=RTOL, atol=1e-12)


def reverify(folder: Path, config) -> list[tuple[str, str, str, object, object, str]]:
    """(file, row, column, stored, recomputed, rule) of every disagreement; [] when the stored
    board follows from the stored answers."""
    from fkopt.kinbench.clock import answer_prefix, targets_of, verdicts
    from fkopt.kinbench.posesets import load_pose_sets
    from fkopt.kinbench.reports import robots_board_table
    from fkopt.kinbench.runner import track_arm, track_cases
    folder = Path(folder)
    path = folder / "answers.csv.gz"
    if config.tracks is None or config.tracks.clock is None or not path.exists():
        return []
    answers = pd.read_csv(path, dtype={"robot": str, "solver": str})
    sets, _ = load_pose_sets(config)
    out = []
    index = {p.name: k for k, p in enumerate(config.problems)}
    queries = dict(track_cases(config, sets))
    rule = "recomputed from the stored answer with fkopt's FK"
    for robot, g in answers.groupby("robot", sort=False):
        if robot not in index or index[robot] not in queries:
            out.append(("answers.csv.gz", robot, "robot", robot, None, "a problem of tracks.clock.problems"))
            continue
        mech = track_arm(config, index[robot])
        Q = queries[index[robot]]
        q = g["query"].to_numpy(int)
        if (q < 0).any() or (q >= len(Q)).any():
            out.append(("answers.csv.gz", robot, "query", int(q.max()), len(Q) - 1, "a query of the track"))
            continue
        cols = [f"{answer_prefix(mech)}{d}" for d in range(Q.shape[1])]
        v = verdicts(mech, g[cols].to_numpy(float), Q[q], targets_of(mech, Q[q]))
        for col in ("position_m", "rotation_rad", "leg_residual", "in_limits"):
            bad = ~_close(g[col].to_numpy(float), np.asarray(v[col], float))
            for k in np.flatnonzero(bad)[:3]:
                r = g.iloc[k]
                out.append(("answers.csv.gz", f"{robot}/{r['solver']}/query {r['query']}", col, r[col],
                            np.asarray(v[col])[k], rule))
    tp_path = folder / "throughput.csv"
    throughput = pd.read_csv(tp_path) if tp_path.exists() else None
    board = robots_board_table(SimpleNamespace(config=config, answers=answers, throughput=throughput))
    stored_path = folder / "leaderboard-robots.csv"
    if board is None or not stored_path.exists():
        return out
    key = ["solver", "robot", "timeout_ms"]
    stored = pd.read_csv(stored_path, dtype={"solver": str, "robot": str}).astype({"timeout_ms": float})
    board = board.astype({"timeout_ms": float})
    if len(stored) != len(board) or set(map(tuple, stored[key].values)) != set(map(tuple, board[key].values)):
        return out + [("leaderboard-robots.csv", "-", "rows", len(stored), len(board),
                       "one row per (solver, robot, timeout) of the stored answers")]
    merged = stored.merge(board, on=key, suffixes=("", "_recomputed"))
    for col in board.columns:
        if col in key or f"{col}_recomputed" not in merged or not pd.api.types.is_numeric_dtype(board[col]):
            continue
        bad = ~_close(merged[col].to_numpy(float), merged[f"{col}_recomputed"].to_numpy(float))
        for k in np.flatnonzero(bad)[:3]:
            r = merged.iloc[k]
            out.append(("leaderboard-robots.csv", f"{r['solver']}/{r['robot']}/{r['timeout_ms']:g} ms", col, r[col],
                        r[f"{col}_recomputed"], "recomputed from the stored answers"))
    return out
