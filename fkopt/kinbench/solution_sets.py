"""kinbench's ``all-solutions`` track: every IK solution of a pose, measured against the analytic
sets and against the union of every entry's verified answers (issue 40).

**Queries.** Per arm of ``tracks.all-solutions.problems``: the first ``queries`` configurations of
the suite's frozen pose set ``set`` (kinbench v3's, released: :mod:`fkopt.kinbench.releases`);
the target of each is its tip frame by fkopt's FK. A 7-joint arm named in ``locked`` has that
joint locked in every entry at :data:`LOCK_SHARE` of its range (the query's value of it replaced),
so that its solutions are finite: fkopt through ``fixed=``, the field's entries on the 6-joint
chain left (:func:`fkopt.adapters.field.track_entries.locked_arm`); every answer is a point of
that chain (the locked joint's column dropped).

**Entries** (the registry's ``all-solutions`` role, :data:`fkopt.registry.ALL_SOLUTIONS_SOLVERS`):
``fkopt.inverse-all`` (``fkopt.inverse(arm, T, solutions="all")``), ``eaik-all`` (EAIK's analytic
set), and ``rtb-ik_LM-restarts`` / ``tracik-restarts``: the board's one-answer call from random
starts until a time budget has passed -- the **reference**'s (fkopt's) median time per pose on the
arm, measured first in the same job, so that they get the same time. Everything runs pinned to
one core (:func:`fkopt.adapters.field.cores.pinned`), poses interleaved with the entries in an
order rotated by one per pose.

**Verdicts.** Every returned answer is first mapped into the limits (a revolute joint shifted by
whole turns towards them, :func:`into_limits`), then judged by fkopt's FK against the target
(:func:`fkopt.kinbench.physical.ik_verdicts`): *verified* when within :data:`TOL` (1e-6 m,
1e-6 rad) and inside the limits. Answers are **distinct** modulo 2 pi per revolute joint: two
answers are one solution when every joint agrees within :data:`MATCH` (rad; 1e-6 of pose error
moves a joint by ~1e-4 rad away from singularities). Per pose, each entry's verified answers
merged into distinct solutions; the **analytic set** is the ``analytic`` entry's (EAIK's, where it
decomposes the arm); the **union** is every entry's distinct solutions merged. Recall of an entry:
the share of the analytic set's (the union's) solutions it holds, summed over poses;
``beyond_analytic``: its distinct verified solutions the analytic set lacks. Time per pose: its
call's wall time, as a ratio to the reference's on the same pose (median, p95).

**Stored answers** (``solutions.csv.gz``, a timing file: the restart entries' answers depend on
the time and their packages' unseeded restarts): per (problem, pose, solver) its distinct answers,
verified and unverified apart, each with ``copies`` (how many returned answers it stands for);
a pose with none has one row without joints. ``fkopt check`` judges every stored answer again
with fkopt's FK and recomputes the board (``leaderboard-solutions.csv``) from them (:func:`reverify`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.adapters.field import NotApplicable
from fkopt.adapters.field.cores import pinned
from fkopt.adapters.field.track_entries import locked_arm
from fkopt.errors import FkoptError
from fkopt.files import csv_numbers, read_stored_csv
from fkopt.kinbench.answer_checks import _close, differing_numbers
from fkopt.kinbench.clock import query_rng, rotated, timed
from fkopt.kinbench.physical import ik_verdicts
from fkopt.kinbench.posesets import load_pose_sets, problem_mechanism
from fkopt.registry import clock_solver
from fkopt.run.config_base import files_folder

#: Verification of every answer (m, rad): these tracks' tolerance.
TOL = (1e-6, 1e-6)
#: Two answers are one solution when every joint agrees within this (rad, revolute joints modulo 2 pi).
MATCH = 1e-3
#: A locked joint's value: this share of its range above its lower limit.
LOCK_SHARE = 0.3
#: The columns of every row of solutions.csv.gz, before the joints q0..
COLUMNS = ("problem", "pose", "solver", "entry", "answer", "copies", "seconds", "cpu_seconds", "reference_seconds",
           "budget_seconds", "position_m", "rotation_rad", "in_limits", "not_applicable")
ORGANISER = ("fkopt.inverse-all", "fkopt.inverse_path")


def entry_of(name: str) -> str:
    return "organiser" if name in ORGANISER else "outside"


def not_applicable_of(rows: pd.DataFrame) -> str:
    """Why an entry's rows hold no answers ('' when it ran; a column read back empty is NaN)."""
    why = rows["not_applicable"].iloc[0] if len(rows) else ""
    return why if isinstance(why, str) else ""


# -- joints modulo 2 pi -------------------------------------------------------------------------
def _revolute(arm) -> np.ndarray:
    return np.asarray(arm.unknown_units) == "deg"


def into_limits(arm, Q: np.ndarray) -> np.ndarray:
    """Rows of public joints with every revolute joint shifted by whole turns towards its limits
    (the fewest turns that bring it inside; unchanged when none does or it is inside)."""
    Q = np.array(Q, dtype=float, ndmin=2)
    lo, hi = arm.bounds[:, 0], arm.bounds[:, 1]
    up = np.ceil((lo - Q) / 360.0)
    down = -np.ceil((Q - hi) / 360.0)
    k = np.where(Q < lo, up, np.where(Q > hi, down, 0.0))
    return np.where(_revolute(arm), Q + 360.0 * k, Q)


def gaps(arm, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """(len(A), len(B)): the largest joint difference (rad, length unit) of every pair, revolute
    joints modulo 2 pi."""
    d = np.asarray(A, float)[:, None, :] - np.asarray(B, float)[None, :, :]
    rev = _revolute(arm)
    d = np.where(rev, np.abs((d + 180.0) % 360.0 - 180.0), np.abs(d))
    scale = np.where(rev, np.pi / 180.0, 1.0)
    return (d * scale).max(axis=-1) if d.size else np.zeros((len(A), len(B)))


def distinct(arm, Q: np.ndarray, match: float = MATCH) -> tuple[np.ndarray, np.ndarray]:
    """(representatives, copies): rows of ``Q`` merged greedily in order, a row joining the first
    representative within ``match``; copies = how many rows each stands for."""
    reps, copies = [], []
    for q in np.asarray(Q, float).reshape(-1, arm.dof):
        if reps:
            g = gaps(arm, q[None], np.array(reps))[0]
            k = int(np.argmin(g))
            if g[k] <= match:
                copies[k] += 1
                continue
        reps.append(q)
        copies.append(1)
    return np.array(reps).reshape(-1, arm.dof), np.array(copies, dtype=int)


def held(arm, mine: np.ndarray, ref: np.ndarray, match: float = MATCH) -> np.ndarray:
    """(len(ref),): which rows of ``ref`` some row of ``mine`` matches."""
    if not len(ref):
        return np.zeros(0, bool)
    if not len(mine):
        return np.zeros(len(ref), bool)
    return (gaps(arm, ref, mine) <= match).any(axis=1)


# -- the track's arms and queries ---------------------------------------------------------------
def lock_of(arm, joint: str | None) -> dict[str, float]:
    """{joint: value} of the joint locked on ``arm`` (:data:`LOCK_SHARE` of its range), {} for none."""
    if not joint:
        return {}
    if joint not in arm.unknown_names:
        raise FkoptError(f"tracks.all-solutions.locked: '{joint}' is not a joint of {arm.name} "
                         f"({', '.join(arm.unknown_names)})")
    lo, hi = arm.bounds[arm.unknown_names.index(joint)]
    return {joint: float(lo + LOCK_SHARE * (hi - lo))}


def track_arms(config, name: str, files: Path | None = None):
    """(arm, fixed, solved): the problem's arm, its locked joints {name: value}, and the arm the
    answers are points of (the 6-joint chain left when a joint is locked)."""
    problem = next(p for p in config.problems if p.name == name)
    arm, _ = problem_mechanism(problem, files if files is not None else files_folder(config))
    if getattr(arm, "kind", None) != "serial" or not hasattr(arm, "chain"):
        raise FkoptError(f"tracks.all-solutions.problems: '{name}' is not a serial arm with a chain (URDF, MJCF, DH)")
    fixed = lock_of(arm, config.tracks.all_solutions.locked.get(name))
    return arm, fixed, (locked_arm(arm, fixed) if fixed else arm)


def full_sets(config, files: Path | None = None) -> dict:
    """The suite's pose sets, uncut by its ``poses`` (how many poses the swarms get)."""
    return load_pose_sets(config.model_copy(update={"poses": None}), files)[0]


def track_queries(config, sets: dict, name: str, arm, fixed: dict) -> np.ndarray:
    """The frozen configurations of the track's set (its first ``queries``; ``sets``:
    :func:`full_sets`), locked joints set."""
    track = config.tracks.all_solutions
    have = sets[(name, track.set)]
    if track.queries is not None and track.queries > len(have):
        raise FkoptError(f"tracks.all-solutions.queries: {track.queries}, but set '{track.set}' of problem {name} "
                         f"holds {len(have)} poses; allowed: 1 to {len(have)} (or omit it: every pose of the set)")
    Q = np.array(have[:track.queries], dtype=float)
    for joint, value in fixed.items():
        Q[:, arm.unknown_names.index(joint)] = value
    return Q


# -- running ------------------------------------------------------------------------------------
def run_solutions(arm, solved, fixed: dict, problem: str, queries: np.ndarray, solvers: list[str], *,
                  reference: str, seed: int = 0, settings: dict | None = None) -> pd.DataFrame:
    """Every entry on every query of one arm: the reference first over all queries (its median
    time per pose is the restart entries' budget), then the others pose by pose in a rotated
    order; every returned answer mapped into the limits, judged, and merged per (pose, solver)."""
    T = arm.fk_matrix(queries)
    n = len(queries)
    found: dict[str, list] = {}
    secs: dict[str, np.ndarray] = {}
    cpus: dict[str, np.ndarray] = {}
    why: dict[str, str] = {}
    options = {"fixed": fixed} if fixed else {}
    names = list(dict.fromkeys([reference, *solvers]))

    def call(entry, name, i):
        entry.rng = query_rng(seed, problem, name, None, i)     # no timeout: the clock's stream per (arm, entry, pose)
        Q, secs[name][i], cpus[name][i] = timed(entry.solutions, T[i])
        found[name][i] = np.asarray(Q, float).reshape(-1, solved.dof)

    with pinned():
        ref = clock_solver(reference, arm, timeout=1.0, rng=np.random.default_rng(0), **options)
        for name in names:
            found[name], secs[name], cpus[name] = [None] * n, np.full(n, np.nan), np.full(n, np.nan)
        for i in range(n):
            call(ref, reference, i)
        budget = float(np.median(secs[reference]))
        entries = {}
        for name in names[1:]:
            try:
                entries[name] = clock_solver(name, arm, timeout=budget, rng=np.random.default_rng(0), **options)
            except NotApplicable as err:
                why[name] = str(err)
        if settings is not None:
            settings.update({name: dict(e.settings) for name, e in [(reference, ref), *entries.items()]})
            settings.update({name: {"not_applicable": w} for name, w in why.items()})
        order = list(entries)
        for i in range(n):
            for name in rotated(order, i):
                call(entries[name], name, i)
    rows = []
    for name in names:
        for i in range(n):
            rows.append(pose_rows(solved, problem, name, i, found[name][i], T[i], secs[name][i], cpus[name][i],
                                  secs[reference][i], budget, why.get(name, "")))
    return pd.concat(rows, ignore_index=True)


def pose_rows(solved, problem: str, solver: str, pose: int, Q, T, seconds, cpu, reference_seconds, budget,
              not_applicable: str = "") -> pd.DataFrame:
    """One entry's answers on one pose as rows: mapped into the limits, judged, verified and
    unverified answers each merged into distinct rows with their copies; one row without joints
    when there are none."""
    dof = solved.dof
    Q = np.zeros((0, dof)) if Q is None else np.asarray(Q, float).reshape(-1, dof)
    if len(Q):
        Q = into_limits(solved, Q)
    v = ik_verdicts(solved, Q, np.broadcast_to(T, (len(Q), 4, 4))) if len(Q) else None
    parts, copies = [], []
    if v is not None:
        ok = verified(v)
        for keep in (ok, ~ok):
            reps, c = distinct(solved, Q[keep])
            parts.append(reps)
            copies.append(c)
    rows = np.concatenate(parts) if parts else np.zeros((0, dof))
    c = np.concatenate(copies) if copies else np.zeros(0, int)
    if not len(rows):
        rows, c = np.full((1, dof), np.nan), np.zeros(1, int)
    v = ik_verdicts(solved, rows, np.broadcast_to(T, (len(rows), 4, 4)))
    frame = pd.DataFrame({"problem": problem, "pose": int(pose), "solver": solver, "entry": entry_of(solver),
                          "answer": np.arange(len(rows)) if c.sum() else -1, "copies": c, "seconds": seconds,
                          "cpu_seconds": cpu, "reference_seconds": reference_seconds, "budget_seconds": budget,
                          "position_m": v["position_m"], "rotation_rad": v["rotation_rad"],
                          "in_limits": v["in_limits"], "not_applicable": not_applicable})
    for d in range(dof):
        frame[f"q{d}"] = rows[:, d]
    return frame


def verified(v: dict) -> np.ndarray:
    return (v["position_m"] <= TOL[0]) & (v["rotation_rad"] <= TOL[1]) & v["in_limits"]


# -- the board ----------------------------------------------------------------------------------
def solutions_board(answers: pd.DataFrame, arms: dict, *, reference: str, analytic: str) -> pd.DataFrame:
    """Per (problem, solver): answers returned and failing, distinct verified solutions, recall
    against the analytic set and against the union, solutions beyond the analytic set, time per
    pose (ms, and as a ratio to the reference's on the same pose). ``arms``: problem -> the arm
    its answers are points of."""
    rows = []
    for problem, a in answers.groupby("problem", sort=False):
        arm = arms[problem]
        qcols = [f"q{d}" for d in range(arm.dof)]
        names = list(dict.fromkeys(a["solver"]))
        na = {s: not_applicable_of(a[a["solver"] == s]) for s in names}
        live = [s for s in names if not na[s]]
        tally = {s: dict(distinct=0, analytic_held=0, union_held=0, beyond=0) for s in names}
        total_analytic = total_union = 0
        for _, g in a.groupby("pose", sort=True):
            mine = {}
            for s in live:
                r = g[(g["solver"] == s) & (g["copies"] > 0)]
                ok = verified({"position_m": r["position_m"].to_numpy(float),
                               "rotation_rad": r["rotation_rad"].to_numpy(float),
                               "in_limits": r["in_limits"].to_numpy(bool)})
                mine[s] = r[qcols].to_numpy(float)[ok]
            ref = mine.get(analytic) if analytic in live else None
            union, _ = distinct(arm, np.concatenate([mine[s] for s in live])) if live else (np.zeros((0, arm.dof)), None)
            total_union += len(union)
            total_analytic += len(ref) if ref is not None else 0
            for s in live:
                tally[s]["distinct"] += len(mine[s])
                tally[s]["union_held"] += int(held(arm, mine[s], union).sum())
                if ref is not None:
                    tally[s]["analytic_held"] += int(held(arm, mine[s], ref).sum())
                    tally[s]["beyond"] += int((~held(arm, ref, mine[s])).sum()) if len(mine[s]) else 0
        for s in names:
            g = a[a["solver"] == s]
            per_pose = g.groupby("pose", sort=True).first()
            row = {"problem": problem, "solver": s, "entry": entry_of(s), "poses": int(a["pose"].nunique()),
                   "reference": reference, "analytic": analytic, "not_applicable": na[s]}
            if not na[s]:
                ok = verified({"position_m": g["position_m"].to_numpy(float),
                               "rotation_rad": g["rotation_rad"].to_numpy(float),
                               "in_limits": g["in_limits"].to_numpy(bool)})
                c = g["copies"].to_numpy(int)
                ratio = per_pose["seconds"].to_numpy(float) / per_pose["reference_seconds"].to_numpy(float)
                t = tally[s]
                row.update({"answers": int(c.sum()), "failed": int(c[~ok].sum()), "distinct": t["distinct"],
                            "analytic_solutions": total_analytic if analytic in live else np.nan,
                            "recall_analytic": t["analytic_held"] / total_analytic
                            if analytic in live and total_analytic else np.nan,
                            "beyond_analytic": t["beyond"] if analytic in live else np.nan,
                            "union_solutions": total_union,
                            "recall_union": t["union_held"] / total_union if total_union else np.nan,
                            "time_ms_median": 1e3 * float(np.median(per_pose["seconds"])),
                            "time_ratio_median": float(np.median(ratio)),
                            "time_ratio_p95": float(np.percentile(ratio, 95)),
                            "budget_ms": 1e3 * float(per_pose["budget_seconds"].iloc[0])})
            rows.append(row)
    return pd.DataFrame(rows)


# -- checking -------------------------------------------------------------------------------------
def table_problems(config, answers: pd.DataFrame, problem: str, arm, solved, Q: np.ndarray) -> list[tuple]:
    """(row, column, stored, recomputed, rule) of every way ``answers`` (one problem's rows of
    solutions.csv.gz) are not what the config implies: every (pose, solver) of the track
    present, no other; every verdict recomputed from the stored joints with fkopt's FK."""
    track = config.tracks.all_solutions
    out = []
    qcols = [f"q{d}" for d in range(solved.dof)]
    lacking = [c for c in (*COLUMNS, *qcols) if c not in answers.columns]
    if lacking:
        return [(problem, lacking[0], "missing", None, "a column of every solutions row")]
    pose = csv_numbers(answers["pose"])
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(pose) | (pose < 0) | (pose >= len(Q)) | (pose % 1 != 0)
    if bad.any():
        return [(problem, "pose", str(answers["pose"].iloc[int(np.flatnonzero(bad)[0])])[:30], None,
                 f"a pose of the track (0..{len(Q) - 1})")]
    want = {(i, s) for i in range(len(Q)) for s in dict.fromkeys([track.reference, *track.solvers])}
    have = set(zip(pose.astype(int), answers["solver"].astype(str)))
    if have != want:
        odd = sorted(have ^ want)[0]
        return [(problem, "rows", f"pose {odd[0]} / {odd[1][:40]}", None,
                 "rows of every (pose, solver) of the track, no other")]
    T = arm.fk_matrix(Q)
    joints = np.stack([csv_numbers(answers[c]) for c in qcols], axis=-1)
    v = ik_verdicts(solved, joints, T[pose.astype(int)])
    for col in ("position_m", "rotation_rad", "in_limits"):
        stored = answers[col].to_numpy(float) if answers[col].dtype == bool else csv_numbers(answers[col])
        for k in np.flatnonzero(~_close(stored, np.asarray(v[col], float)))[:3]:
            r = answers.iloc[k]
            out.append((f"{problem}/{r['solver']}/pose {r['pose']}", col, r[col], np.asarray(v[col])[k],
                        "recomputed from the stored answer with fkopt's FK"))
    return out


def board_mismatches(folder: Path, name: str, board: pd.DataFrame | None, key: list[str]) -> list[tuple]:
    """(file, row, column, stored, recomputed, rule) of every number of the stored board ``name``
    that differs from ``board`` (recomputed from the stored answers)."""
    if board is None or board.empty:
        return []
    if not (Path(folder) / name).exists():
        return [(name, "-", "file", "missing", None, "the board of the stored answers")]
    try:
        stored = read_stored_csv(folder, name, dtype={k: str for k in key})
    except (FkoptError, KeyError, ValueError) as err:
        return [(name, "-", "file", str(err)[:200], None, "a readable board")]
    if len(stored) != len(board) or any(k not in stored for k in key) \
            or set(map(tuple, stored[key].values)) != set(map(tuple, board[key].astype(str).values)):
        return [(name, "-", "rows", len(stored), len(board), "one row per (problem, solver) of the stored answers")]
    merged = stored.merge(board.astype({k: str for k in key}), on=key, suffixes=("", "_recomputed"))
    return [(name, "/".join(str(r[c]) for c in key), col, r[col], r[f"{col}_recomputed"],
             "recomputed from the stored answers") for r, col in differing_numbers(merged, board, key)]
