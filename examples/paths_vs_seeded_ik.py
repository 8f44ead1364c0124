"""IK along paths: fkopt.inverse_path against roboticstoolbox's ik_LM and TRAC-IK, each seeded
with the previous waypoint's answer (as MoveIt's Cartesian paths do), side by side in one process.

The paths (a frozen set: a pure function of ``--seed``, its SHA-256 printed): per arm, ``--paths``
joint-space segments from a configuration drawn inside the limits (a 0.1 rad margin) to one at
most 1.98 rad away per joint (kept inside the limits), sampled at 100 waypoints, so every joint
step is at most 0.02 rad and a branch with steps <= 0.05 rad exists by construction; the targets
are their tip frames. A path succeeds when every waypoint's answer reproduces its target within
1e-6 m and 1e-6 rad (fkopt's FK, geodesic angle) and no joint moves more than 0.05 rad between
waypoints. Time per waypoint: median over paths of (path time / 100).

    PYTHONPATH=. python examples/paths_vs_seeded_ik.py --paths 50 --json docs/figures/paths_vs_seeded_ik.json
"""
from __future__ import annotations

import argparse
import hashlib
import json
import time
from pathlib import Path

import numpy as np

import fkopt
from fkopt.adapters.field.rtb import RtbLM
from fkopt.adapters.field.tracik import TracIK

SUITES = Path(__file__).resolve().parents[1] / "configs" / "suites"
ARMS = ("ur5", "kinova-j2s6s200", "z1", "panda", "iiwa-mj")
WAYPOINTS, STEP, BOUND, TOL = 100, 0.02, 0.05, 1e-6


def stored(name):
    from fkopt.kinbench.robots import ARMS as ALL
    a = next(a for a in ALL if a.name == name)
    return fkopt.mechanism(a.format, file=str(SUITES / a.file), base=a.base, tip=a.tip)


def path_set(m, paths: int, seed: int) -> np.ndarray:
    """Joint paths (paths, WAYPOINTS, n) in deg (see the module docstring)."""
    rng = np.random.default_rng([seed, m.dof])
    lo, hi = np.radians(m.bounds[:, 0]) + 0.1, np.radians(m.bounds[:, 1]) - 0.1
    a = lo + (hi - lo) * rng.random((paths, m.dof))
    b = np.clip(a + rng.uniform(-1.0, 1.0, (paths, m.dof)) * STEP * (WAYPOINTS - 1), lo, hi)
    s = np.linspace(0.0, 1.0, WAYPOINTS)[None, :, None]
    return np.degrees(a[:, None] + s * (b - a)[:, None])


def errors(m, q, T):
    F = m.fk_matrix(q)
    dp = np.linalg.norm(F[:, :3, 3] - T[:, :3, 3], axis=1)
    M = F[:, :3, :3] @ np.swapaxes(T[:, :3, :3], 1, 2)
    c = np.clip((np.trace(M, axis1=1, axis2=2) - 1) / 2, -1, 1)
    s = 0.5 * np.linalg.norm(np.stack([M[:, 2, 1] - M[:, 1, 2], M[:, 0, 2] - M[:, 2, 0], M[:, 1, 0] - M[:, 0, 1]],
                                      axis=1), axis=1)
    return dp, np.arctan2(s, c)


def verdict(m, J, T) -> bool:
    dp, dr = errors(m, J, T)
    steps = np.abs(np.diff(np.radians(J), axis=0)).max() if len(J) > 1 else 0.0
    return bool((dp <= TOL).all() and (dr <= TOL).all() and steps <= BOUND)


def seeded_rtb(w, T, q0_deg):
    q = np.radians(q0_deg)
    out = []
    for t in T:
        sol = w._call(t, q0=q, ilimit=w.ILIMIT, slimit=1, tol=w.TOL, joint_limits=True)
        q = np.asarray(sol.q, dtype=float)
        out.append(w.public(q))
    return np.array(out)


def seeded_tracik(w, T, q0_deg):
    from scipy.spatial.transform import Rotation
    q = np.radians(q0_deg)
    out = []
    for t in T:
        x, y, z, qw = Rotation.from_matrix(t[:3, :3]).as_quat()
        got = w._pt.ik(w._solver, q, *t[:3, 3], x, y, z, qw)
        if got[0] > 0:
            q = np.asarray(got[1:], dtype=float)
        out.append(w.public(q))
    return np.array(out)


def measure(name: str, paths: int, seed: int) -> dict:
    m = stored(name)
    Q = path_set(m, paths, seed)
    T = m.fk_matrix(Q)
    digest = hashlib.sha256(np.ascontiguousarray(Q).tobytes()).hexdigest()[:16]
    entries = {"fkopt.inverse_path": lambda k: fkopt.inverse_path(m, T[k], start=Q[k, 0]).joints}
    for label, cls, fn in (("rtb ik_LM, seeded", RtbLM, seeded_rtb), ("TRAC-IK, seeded", TracIK, seeded_tracik)):
        try:
            if cls is TracIK:
                # the adapter's eps (1e-5 per component, for the board's rungs) is above this
                # bench's 1e-6: the same wrapper with eps 1e-7
                cls = type("TracIKFine", (TracIK,), {"EPS": 1e-7})
            w = cls(m, timeout=0.005, rng=np.random.default_rng(seed))
            entries[label] = (lambda w, fn: lambda k: fn(w, T[k], Q[k, 0]))(w, fn)
        except Exception as err:                        # an entry that cannot read the arm: say why
            entries[label] = f"not available: {err}"
    row = {"arm": name, "dof": m.dof, "paths": paths, "waypoints": WAYPOINTS, "path_set_sha256_16": digest,
           "loadavg": open("/proc/loadavg").read().split()[:3], "entries": {}}
    for label, run in entries.items():
        if isinstance(run, str):
            row["entries"][label] = run
            continue
        run(0)                                           # compile / warm up outside the clock
        ok, times, breaks = 0, [], 0
        for k in range(paths):
            t0 = time.perf_counter()
            J = run(k)
            times.append((time.perf_counter() - t0) / WAYPOINTS)
            ok += verdict(m, J, T[k])
        row["entries"][label] = {"success": ok / paths, "median_us_per_waypoint": 1e6 * float(np.median(times))}
    base = row["entries"]["fkopt.inverse_path"]["median_us_per_waypoint"]
    for v in row["entries"].values():
        if isinstance(v, dict):
            v["time_ratio_to_fkopt"] = v["median_us_per_waypoint"] / base
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paths", type=int, default=50)
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--arms", nargs="*", default=list(ARMS))
    ap.add_argument("--json", type=Path, default=None)
    a = ap.parse_args(argv)
    rows = []
    for name in a.arms:
        rows.append(measure(name, a.paths, a.seed))
        print(json.dumps(rows[-1]), flush=True)
    if a.json:
        a.json.parent.mkdir(parents=True, exist_ok=True)
        a.json.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
