"""kinbench's ``paths`` track: IK along frozen paths, on one branch (issue 40).

**The path set** (frozen like a pose set: ``python -m fkopt.kinbench.freeze paths SUITE.yaml``
writes it once, :data:`fkopt.kinbench.releases.RELEASES` holds its files' SHA-256): per arm of
``tracks.paths.problems``, ``<folder>/<problem>.csv`` holds each path's two end configurations
(rows 2k and 2k + 1: path k's start and end, the arm's joints in public units, ``%.17g``) and
``manifest.json`` each file's SHA-256. Path k is the joint-space segment between them sampled at
:data:`WAYPOINTS` evenly spaced configurations: the start is drawn uniformly inside the limits
less a :data:`MARGIN` (rad), the end at most ``STEP * (WAYPOINTS - 1)`` rad away per joint (kept
inside the same box), each from the problem's own stream (:func:`fkopt.kinbench.posesets.set_rng`
of the manifest's seed, the problem and ``"paths"``); so every joint moves at most :data:`STEP`
rad between waypoints and a branch with steps <= :data:`BOUND` exists by construction. The
targets are the waypoints' tip frames by fkopt's FK; every entry starts at the path's first
configuration (the robot stands there).

**Entries** (the registry's ``path`` role, :data:`fkopt.registry.PATH_SOLVERS`):
``fkopt.inverse_path`` (one call per path) and rtb's ``ik_LM`` and TRAC-IK seeded with the
previous waypoint's answer, as MoveIt's Cartesian paths call KDL or TRAC-IK
(:mod:`fkopt.adapters.field.track_entries`; TRAC-IK with the track's ``timeout_ms`` per waypoint,
MoveIt's default 5 ms). All pinned to one core, paths interleaved with the entries in a rotated order.

**Success** of a path: every waypoint's answer reproduces its target within :data:`TOL`
(1e-6 m, 1e-6 rad, fkopt's FK), lies inside the limits, and no joint moves more than
:data:`BOUND` rad (length unit for a prismatic joint; continuous joints by their wrapped
difference) between consecutive answers, the first counted from the path's start. Time per
waypoint: the path's wall time / waypoints, as a ratio to the reference's on the same path
(median and p95 over paths).

**Stored answers** (``paths.csv.gz``, a timing file): every waypoint's answer of every entry on
every path, with its verdict and joint step; ``fkopt check`` judges them again and recomputes
``leaderboard-paths.csv`` (:func:`reverify_paths`).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.adapters.field import NotApplicable
from fkopt.adapters.field.cores import pinned
from fkopt.errors import FkoptError
from fkopt.files import csv_numbers, parse_json, read_input
from fkopt.kinbench.answer_checks import _close
from fkopt.kinbench.clock import query_rng, rotated, timed
from fkopt.kinbench.physical import ik_verdicts
from fkopt.kinbench.posesets import csv_bytes, parse_set_csv, problem_mechanism, set_rng, sha256_bytes
from fkopt.kinbench.releases import check_folder_release
from fkopt.registry import clock_solver
from fkopt.run.config_base import files_folder
from fkopt.kinbench.solution_sets import TOL, entry_of, not_applicable_of

#: Waypoints per path, largest joint step of the generating segment (rad), the margin kept
#: from the limits at its start (rad), and the step bound of a successful path (rad).
WAYPOINTS, STEP, MARGIN, BOUND = 100, 0.02, 0.1, 0.05
MANIFEST = "manifest.json"
MAX_PATH_BYTES = 4 << 20
#: The columns of every row of paths.csv.gz, before the joints q0..
COLUMNS = ("problem", "path", "solver", "entry", "waypoint", "seconds", "cpu_seconds", "reference_seconds",
           "position_m", "rotation_rad", "in_limits", "step_rad", "not_applicable")


# -- the frozen path set --------------------------------------------------------------------------
def generate(arm, problem: str, seed: int, paths: int) -> np.ndarray:
    """(paths, 2, dof): each path's start and end configuration, public units (module docstring)."""
    rng = set_rng(seed, problem, "paths")
    to_si = np.asarray(arm._to_si, float) * np.ones(arm.dof)
    lo, hi = arm.bounds[:, 0] * to_si + MARGIN, arm.bounds[:, 1] * to_si - MARGIN
    if np.any(hi <= lo):
        raise FkoptError(f"tracks.paths: a joint of {problem} spans less than {2 * MARGIN} rad")
    a = lo + (hi - lo) * rng.random((paths, arm.dof))
    b = np.clip(a + rng.uniform(-1.0, 1.0, (paths, arm.dof)) * STEP * (WAYPOINTS - 1), lo, hi)
    return np.stack([a, b], axis=1) / to_si


def waypoints(ends: np.ndarray) -> np.ndarray:
    """(paths, WAYPOINTS, dof) configurations evenly spaced from each path's start to its end."""
    s = np.linspace(0.0, 1.0, WAYPOINTS)[None, :, None]
    return ends[:, :1] + s * (ends[:, 1:2] - ends[:, :1])


def write_path_set(config, folder: Path, paths: int) -> Path:
    """The path set of every problem of ``tracks.paths`` into ``folder`` (frozen data: run once, commit)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    manifest = {"version": folder.name, "seed": config.seed, "paths_per_problem": paths, "waypoints": WAYPOINTS,
                "step_rad": STEP, "margin_rad": MARGIN, "generator": "fkopt.kinbench.paths.generate",
                "rows": "path k: rows 2k (start) and 2k + 1 (end), public units", "problems": {}}
    for name in config.tracks.paths.problems:
        problem = next(p for p in config.problems if p.name == name)
        arm, _ = problem_mechanism(problem, files_folder(config))
        data = csv_bytes(arm.unknown_names, generate(arm, name, config.seed, paths).reshape(-1, arm.dof))
        (folder / f"{name}.csv").write_bytes(data)
        manifest["problems"][name] = {"mechanism": problem.mechanism.model_dump(mode="json"),
                                      "unknowns": list(arm.unknown_names), "file": f"{name}.csv",
                                      "sha256": sha256_bytes(data), "paths": paths}
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return folder


def load_path_sets(config, files: Path | None = None) -> dict[str, np.ndarray]:
    """{problem: (paths, 2, dof)} of ``tracks.paths`` (its first ``paths`` paths), every file
    checked against the manifest's SHA-256 and mechanism spec, and a released set against
    :data:`fkopt.kinbench.releases.RELEASES`; any mismatch one line naming the file."""
    track = config.tracks.paths
    base = Path(files if files is not None else (files_folder(config) or "."))
    folder = base / track.path_set
    mpath = folder / MANIFEST
    if not mpath.is_file():
        raise FkoptError(f"{mpath}: path-set manifest not found (tracks.paths.path_set: '{track.path_set}' names a "
                         "folder beside the suite file; python -m fkopt.kinbench.freeze paths SUITE.yaml writes it)")
    manifest = parse_json(read_input(mpath, 1 << 20, within=folder), str(mpath))
    problems = manifest.get("problems") if isinstance(manifest, dict) else None
    if not isinstance(problems, dict) or manifest.get("waypoints") != WAYPOINTS or manifest.get("step_rad") != STEP:
        raise FkoptError(f"{mpath}: not a path-set manifest of {WAYPOINTS} waypoints, steps of {STEP} rad "
                         "(fields problems, waypoints, step_rad)")
    check_folder_release(track.path_set, base, folder)
    out = {}
    for name in track.problems:
        entry = problems.get(name)
        problem = next(p for p in config.problems if p.name == name)
        if not isinstance(entry, dict) or not isinstance(entry.get("file"), str) or not isinstance(entry.get("unknowns"), list):
            raise FkoptError(f"{mpath}: problems.{name}: missing (needs file, sha256, unknowns, mechanism)")
        if entry.get("mechanism") != problem.mechanism.model_dump(mode="json"):
            raise FkoptError(f"problems[{name}].mechanism: differs from the mechanism its paths in {folder} were "
                             "generated for; a new mechanism needs a new path set")
        path = folder / entry["file"]
        data = read_input(path, MAX_PATH_BYTES, field=f"{mpath}: problems.{name}.file", within=folder)
        if sha256_bytes(data) != entry.get("sha256"):
            raise FkoptError(f"{path}: SHA-256 {sha256_bytes(data)[:16]}... differs from the manifest's; the frozen "
                             "path set was changed")
        pts = parse_set_csv(data, path, entry["unknowns"])
        if len(pts) % 2:
            raise FkoptError(f"{path}: {len(pts)} rows; a path set holds two rows (start, end) per path")
        ends = pts.reshape(-1, 2, pts.shape[1])
        if track.paths is not None and track.paths > len(ends):
            raise FkoptError(f"tracks.paths.paths: {track.paths}, but {path} holds {len(ends)} paths; "
                             f"allowed: 1 to {len(ends)} (or omit it: every path of the set)")
        out[name] = ends[:track.paths]
    return out


# -- verdicts ---------------------------------------------------------------------------------------
def steps(arm, J: np.ndarray, start: np.ndarray) -> np.ndarray:
    """(..., w): each answer's largest joint move from the previous one (the first from ``start``),
    rad (length unit for a prismatic joint), continuous joints by their wrapped difference."""
    prev = np.concatenate([np.broadcast_to(start[..., None, :], J[..., :1, :].shape), J[..., :-1, :]], axis=-2)
    d = J - prev
    per = arm.periodic_mask()
    d[..., per] = (d[..., per] + 180.0) % 360.0 - 180.0
    to_si = np.asarray(arm._to_si, float) * np.ones(arm.dof)
    with np.errstate(invalid="ignore"):
        return np.where(np.isfinite(d).all(axis=-1), np.abs(d * to_si).max(axis=-1), np.inf)


def path_verdicts(arm, J: np.ndarray, Q: np.ndarray) -> dict:
    """Per waypoint (rows of J, Q: (w, dof) one path): position_m, rotation_rad, in_limits, step_rad."""
    v = ik_verdicts(arm, J, arm.fk_matrix(Q))
    return {"position_m": v["position_m"], "rotation_rad": v["rotation_rad"], "in_limits": v["in_limits"],
            "step_rad": steps(arm, J, Q[0])}


def run_paths(arm, problem: str, ends: np.ndarray, solvers: list[str], *, reference: str, timeout_ms: float,
              seed: int = 0, settings: dict | None = None) -> pd.DataFrame:
    """Every entry on every path of one arm, interleaved (rotated per path), pinned to one core."""
    Q = waypoints(ends)
    T = arm.fk_matrix(Q)
    names = list(dict.fromkeys([reference, *solvers]))
    entries, why = {}, {}
    for name in names:
        try:
            entries[name] = clock_solver(name, arm, timeout=timeout_ms / 1e3, rng=np.random.default_rng(0))
        except NotApplicable as err:
            why[name] = str(err)
    if settings is not None:
        settings.update({name: dict(e.settings) for name, e in entries.items()})
    n = len(ends)
    J = {name: np.full((n, WAYPOINTS, arm.dof), np.nan) for name in entries}
    secs = {name: np.full(n, np.nan) for name in names}
    cpus = {name: np.full(n, np.nan) for name in names}
    order = list(entries)
    with pinned():
        for k in range(n):
            for name in rotated(order, k):
                entries[name].rng = query_rng(seed, problem, name, None, k)
                J[name][k], secs[name][k], cpus[name][k] = timed(entries[name].path, T[k], Q[k, 0])
    rows = []
    for name in names:
        for k in range(n):
            joints = J[name][k] if name in J else np.full((WAYPOINTS, arm.dof), np.nan)
            rows.append(path_rows(arm, problem, name, k, joints, Q[k], secs[name][k], cpus[name][k],
                                  secs[reference][k], why.get(name, "")))
    return pd.concat(rows, ignore_index=True)


def path_rows(arm, problem, solver, path, J, Q, seconds, cpu, reference_seconds, not_applicable="") -> pd.DataFrame:
    v = path_verdicts(arm, J, Q)
    frame = pd.DataFrame({"problem": problem, "path": int(path), "solver": solver, "entry": entry_of(solver),
                          "waypoint": np.arange(len(J)), "seconds": seconds, "cpu_seconds": cpu,
                          "reference_seconds": reference_seconds, **v, "not_applicable": not_applicable})
    for d in range(arm.dof):
        frame[f"q{d}"] = J[:, d]
    return frame


def path_success(g: pd.DataFrame) -> bool:
    """One entry's rows of one path: every waypoint within TOL and the limits, no step above BOUND."""
    return bool(((g["position_m"].to_numpy(float) <= TOL[0]) & (g["rotation_rad"].to_numpy(float) <= TOL[1])
                 & g["in_limits"].to_numpy(bool) & (g["step_rad"].to_numpy(float) <= BOUND)).all())


def paths_board(answers: pd.DataFrame, *, reference: str) -> pd.DataFrame:
    """Per (problem, solver): the share of paths that succeed, of waypoints within the tolerance
    and limits, of paths with a joint step above the bound; the median largest step; time per
    waypoint (us, and as a ratio to the reference's on the same path: median, p95)."""
    rows = []
    for (problem, solver), a in answers.groupby(["problem", "solver"], sort=False):
        why = not_applicable_of(a)
        row = {"problem": problem, "solver": solver, "entry": entry_of(solver), "paths": int(a["path"].nunique()),
               "waypoints": WAYPOINTS, "reference": reference, "not_applicable": why}
        if not why:
            per = a.groupby("path", sort=True)
            within = (a["position_m"].to_numpy(float) <= TOL[0]) & (a["rotation_rad"].to_numpy(float) <= TOL[1]) \
                & a["in_limits"].to_numpy(bool)
            first = per.first()
            largest = per["step_rad"].max().to_numpy(float)
            ratio = first["seconds"].to_numpy(float) / first["reference_seconds"].to_numpy(float)
            row.update({"success": float(np.mean([path_success(g) for _, g in per])),
                        "waypoints_within": float(within.mean()),
                        "paths_step_over_bound": float((largest > BOUND).mean()),
                        "largest_step_rad_median": float(np.median(largest)),
                        "time_us_per_waypoint_median": 1e6 * float(np.median(first["seconds"])) / WAYPOINTS,
                        "time_ratio_median": float(np.median(ratio)), "time_ratio_p95": float(np.percentile(ratio, 95))})
        rows.append(row)
    return pd.DataFrame(rows)


def table_problems(config, answers: pd.DataFrame, problem: str, arm, ends: np.ndarray) -> list[tuple]:
    """(row, column, stored, recomputed, rule) of every way one problem's rows of paths.csv.gz are
    not what the config implies: one row per (path, solver, waypoint) of the track, every verdict
    and step recomputed from the stored joints."""
    track = config.tracks.paths
    qcols = [f"q{d}" for d in range(arm.dof)]
    lacking = [c for c in (*COLUMNS, *qcols) if c not in answers.columns]
    if lacking:
        return [(problem, lacking[0], "missing", None, "a column of every paths row")]
    path, wp = csv_numbers(answers["path"]), csv_numbers(answers["waypoint"])
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(path) | (path < 0) | (path >= len(ends)) | (path % 1 != 0) \
            | ~np.isfinite(wp) | (wp < 0) | (wp >= WAYPOINTS) | (wp % 1 != 0)
    if bad.any():
        return [(problem, "path", str(answers["path"].iloc[int(np.flatnonzero(bad)[0])])[:30], None,
                 f"a path (0..{len(ends) - 1}) and waypoint (0..{WAYPOINTS - 1}) of the track")]
    keys = list(zip(path.astype(int), answers["solver"].astype(str), wp.astype(int)))
    want = {(k, s, w) for k in range(len(ends)) for s in dict.fromkeys([track.reference, *track.solvers])
            for w in range(WAYPOINTS)}
    if len(keys) != len(want) or set(keys) != want:
        odd = sorted(set(keys) ^ want)[:1] or [keys[0]]
        return [(problem, "rows", f"path {odd[0][0]} / {odd[0][1][:40]} / waypoint {odd[0][2]}", None,
                 "one row per (path, solver, waypoint) of the track")]
    Q = waypoints(ends)
    out = []
    g = answers.assign(_p=path.astype(int), _w=wp.astype(int)).sort_values(["solver", "_p", "_w"], kind="stable")
    J = np.stack([csv_numbers(g[c]) for c in qcols], axis=-1).reshape(-1, WAYPOINTS, arm.dof)
    k = g["_p"].to_numpy(int).reshape(-1, WAYPOINTS)[:, 0]
    v = {c: [] for c in ("position_m", "rotation_rad", "in_limits", "step_rad")}
    for j in range(len(J)):
        for c, x in path_verdicts(arm, J[j], Q[k[j]]).items():
            v[c].append(x)
    for col, x in v.items():
        x = np.concatenate(x)
        stored = g[col].to_numpy(float) if g[col].dtype == bool else csv_numbers(g[col])
        for i in np.flatnonzero(~_close(stored, np.asarray(x, float)))[:3]:
            r = g.iloc[i]
            out.append((f"{problem}/{r['solver']}/path {r['path']}/waypoint {r['waypoint']}", col, r[col], x[i],
                        "recomputed from the stored answer with fkopt's FK"))
    return out
