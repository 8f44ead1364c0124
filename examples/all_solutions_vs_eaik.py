"""Every IK solution of a pose: fkopt's numeric search (``fkopt.inverse(arm, pose, solutions="all")``)
against EAIK's analytic sets (fkopt/adapters/field/eaik.py), side by side in one process.

Per arm: ``--poses`` targets, FK of configurations drawn uniformly inside the limits (seeded);
EAIK's exact (not least-squares) solutions inside the limits are the reference. Reports recall
(EAIK's in-limit solutions that fkopt also returns, equal modulo 360 deg within ``MATCH_DEG``), the
fkopt answers that fail verification by fkopt's FK (``fk_matrix``, 1e-9 m / 1e-9 rad), the
verified fkopt answers EAIK lacks (printed), median time per pose of both (wall, and CPU time of
the process, which a busy machine inflates less) and their ratio, the load average beside it,
fkopt's Jacobian evaluations per pose (median, mean: the cost without the clock) and the poses
whose set carries a certificate (Pieper's bound reached). Arms EAIK
cannot take are listed with EAIK's reason.

    PYTHONPATH=. python examples/all_solutions_vs_eaik.py --poses 1000 --json docs/figures/all_solutions_vs_eaik.json
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import fkopt
from fkopt.adapters.field import NotApplicable
from fkopt.adapters.field.eaik import EAIK
from fkopt.adapters.field.track_entries import locked_arm
from fkopt.kinbench.robots import ARMS

ARMS_MEASURED = ("ur3", "ur5", "ur10", "z1", "kinova-j2s6s200", "so101", "ur5e-mj", "spot-arm-mj")
#: 7-joint arms measured with one joint locked (its index) in both: EAIK takes the 6R chain left
#: (the Panda decomposes with joint 4, 5, 6 or 7 locked; xArm 7, Kinova Gen3, Sawyer, Baxter with none).
ARMS_LOCKED = {"panda": 6, "iiwa-mj": 2, "jaco-mj": 2, "xarm7": 2, "kinova3-mj": 2, "sawyer-mj": 2,
               "tiago-right-mj": 2, "baxter-right-mj": 2, "baxter-left": 2}
SUITES = Path(__file__).resolve().parents[1] / "configs" / "suites"
#: Two rows are the same solution when every joint agrees within this (deg) modulo 360: near a
#: singularity (an elbow almost straight) a solution is determined only to ~1e-5 rad by its pose,
#: while the two solutions on either side of it are ~1e-4 rad apart.
MATCH_DEG = 1e-3


def stored(name):
    a = next(a for a in ARMS if a.name == name)
    return fkopt.mechanism(a.format, file=str(SUITES / a.file), base=a.base, tip=a.tip)


def errors(m, q, T):
    """Position (m) and geodesic rotation (rad) error of FK(q) rows against T."""
    F = m.fk_matrix(np.atleast_2d(q))
    dp = np.linalg.norm(F[:, :3, 3] - T[:3, 3], axis=1)
    M = F[:, :3, :3] @ T[:3, :3].T
    c = np.clip((np.trace(M, axis1=1, axis2=2) - 1) / 2, -1, 1)
    s = 0.5 * np.linalg.norm(np.stack([M[:, 2, 1] - M[:, 1, 2], M[:, 0, 2] - M[:, 2, 0],
                                       M[:, 1, 0] - M[:, 0, 1]], axis=1), axis=1)
    return dp, np.arctan2(s, c)


def measure(name: str, poses: int, seed: int, lock: int | None = None) -> dict:
    m = stored(name)
    fixed = {}
    rng = np.random.default_rng(seed)
    q = m.bounds[:, 0] + (m.bounds[:, 1] - m.bounds[:, 0]) * rng.random((poses, m.dof))
    keep = np.arange(m.dof)
    try:
        if lock is None:
            ref = EAIK(m, timeout=1.0, rng=np.random.default_rng(seed))
        else:
            value = float(m.bounds[lock, 0] + 0.3 * (m.bounds[lock, 1] - m.bounds[lock, 0]))
            q[:, lock] = value
            fixed = {m.joint_names[lock]: value}
            keep = np.delete(keep, lock)
            ref = EAIK(locked_arm(m, fixed), timeout=1.0, rng=np.random.default_rng(seed))
    except NotApplicable as err:
        return {"arm": name, "locked": fixed, "eaik": f"not applicable: {err}"}
    T = m.fk_matrix(q)
    fkopt.inverse(m, T[0], solutions="all", fixed=fixed)    # compile / load the kernels outside the clock
    ref.solutions(T[0])
    t_fk, t_ea = [], []
    total = missed = extra = failed = returned = 0
    shown = []
    counts = []
    evals, certified = [], 0
    c_fk, c_ea = [], []
    for k in range(poses):
        c0, t0 = time.process_time(), time.perf_counter()
        got = fkopt.inverse(m, T[k], solutions="all", fixed=fixed)
        t_fk.append(time.perf_counter() - t0)
        c_fk.append(time.process_time() - c0)
        c0, t0 = time.process_time(), time.perf_counter()
        s = ref.solutions(T[k])
        t_ea.append(time.perf_counter() - t0)
        c_ea.append(time.process_time() - c0)
        mine = got.solutions
        full = mine
        evals.append(got.search["evaluations"])
        certified += got.search["rule"].startswith("certificate")
        returned += len(mine)
        counts.append(len(mine))
        if len(mine):
            dp, dr = errors(m, mine, T[k])
            failed += int(((dp > 1e-9) | (dr > 1e-9)).sum())
        mine = mine[:, keep]                                    # the locked joint is EAIK's constant
        theirs = s.joints[~s.least_squares & s.in_limits]
        if len(theirs):
            back = np.empty((len(theirs), m.dof))
            back[:, keep] = theirs
            if fixed:
                back[:, lock] = next(iter(fixed.values()))
            dp, dr = errors(m, back, T[k])
            theirs = theirs[(dp <= 1e-9) & (dr <= 1e-9)]       # EAIK's own answers verified the same way
        for row in theirs:
            total += 1
            if not len(mine) or np.abs((mine - row + 180.0) % 360.0 - 180.0).max(axis=1).min() > MATCH_DEG:
                missed += 1
        for row in mine:
            if not len(theirs) or np.abs((theirs - row + 180.0) % 360.0 - 180.0).max(axis=1).min() > MATCH_DEG:
                extra += 1
                if len(shown) < 3:
                    row = full[len(shown) * 0 + int(np.flatnonzero((mine == row).all(axis=1))[0])]
                    dp, dr = errors(m, row, T[k])
                    shown.append({"pose": k, "joints_deg": [round(float(v), 6) for v in row],
                                  "position_error_m": float(dp[0]), "rotation_error_rad": float(dr[0])})
    med_fk, med_ea = float(np.median(t_fk)), float(np.median(t_ea))
    return {"arm": name, "dof": m.dof, "locked": fixed, "poses": poses, "eaik_solutions": total, "missed": missed,
            "recall": 1.0 - missed / max(total, 1), "fkopt_solutions": returned, "failed_verification": failed,
            "fkopt_only_verified": extra, "fkopt_only_examples": shown,
            "mean_solutions": float(np.mean(counts)),
            "median_evaluations": float(np.median(evals)), "mean_evaluations": float(np.mean(evals)),
            "certified_poses": certified,
            "median_ms_fkopt": 1e3 * med_fk, "median_ms_eaik": 1e3 * med_ea, "ratio_fkopt_over_eaik": med_fk / med_ea,
            "p95_ms_fkopt": 1e3 * float(np.percentile(t_fk, 95)),
            "median_cpu_ms_fkopt": 1e3 * float(np.median(c_fk)), "median_cpu_ms_eaik": 1e3 * float(np.median(c_ea)), "loadavg": open("/proc/loadavg").read().split()[:3],
            "eaik_family": ref.settings.get("family")}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--arms", nargs="*", default=list(ARMS_MEASURED))
    ap.add_argument("--locked", nargs="*", default=list(ARMS_LOCKED), help="7-joint arms, one joint locked in both (ARMS_LOCKED)")
    ap.add_argument("--json", type=Path, default=None)
    a = ap.parse_args(argv)
    rows = []
    for name, lock in [(n, None) for n in a.arms] + [(n, ARMS_LOCKED[n]) for n in a.locked]:
        row = measure(name, a.poses, a.seed, lock)
        rows.append(row)
        print(json.dumps(row), flush=True)
    if a.json:
        a.json.parent.mkdir(parents=True, exist_ok=True)
        a.json.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
