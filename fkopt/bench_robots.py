"""``fkopt bench --section robots``: ``fkopt.inverse`` on real arms beside roboticstoolbox's ETS ``ik_LM``.

Arms: the Franka Panda, UR5 and Kinova j2s6s200 of example-robot-data
(:data:`fkopt.mechanisms.urdf.EXAMPLE_ROBOTS`) and the wang7dof arm (fkopt's DH model in mm;
roboticstoolbox reads the same arm from ``mechanisms/data/wang7dof.urdf``, in m). Per arm,
``n`` random reachable poses (FK of joints drawn uniformly inside the limits, fixed seed), the
same poses and the same tolerance for both: 0.1 mm and 1e-3 rad geodesic, joints within the
limits, every answer of both libraries verified by fkopt's FK here (no solver's own verdict is
counted). roboticstoolbox's ETS ``ik_LM`` (C++, one pose per call, ``ilimit=30, slimit=100,
joint_limits=True``) stops at E = 1/2 |e|^2 < tol with e = (position error, rotation vector);
it gets tol = 1/2 (1e-4 m)^2, which implies both fkopt tolerances (stricter on rotation).
Continuous joints: both libraries' answers wrapped into [-180, 180) deg before the check.

Rows per arm: the first call of the process (start table of 4096 configurations, k-d tree,
scipy import on the first arm) on its own row; batched (all poses in one call, best of the
repetitions, after the first call) in µs per pose; one pose at a time (median); rtb's time per
pose; the ratios fkopt / rtb. The two are timed alternately in this process (a batched fkopt
call, then rtb over the same poses; one pose of fkopt, then the same pose in rtb), so that their
ratio sees the same machine load. Skipped with a message when roboticstoolbox-python or
example-robot-data is missing (the fkopt rows of the wang7dof arm are still measured).
"""
from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

TOL_M = (1e-4, 1e-3)              # 0.1 mm in m, 1e-3 rad
TOL_MM = (0.1, 1e-3)              # the DH arm is in mm
ARMS = ("panda", "ur5", "kinova")


def _rtb_ets(path: Path, base: str, tip: str):
    """roboticstoolbox's ETS of the chain base -> tip of a URDF file (the field adapter's
    :func:`fkopt.adapters.field.rtb.chain_ets`: a copy without meshes, joints numbered 0..n-1),
    or an error message when rtb cannot be imported."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import roboticstoolbox  # noqa: F401
    except Exception as err:          # ImportError, or a broken install
        return None, f"roboticstoolbox-python not importable ({type(err).__name__}: {err}); " \
                     "pip install roboticstoolbox-python: the rtb rows are skipped"
    from .adapters.field import ArmURDF
    from .adapters.field.rtb import chain_ets
    return chain_ets(ArmURDF.from_file(path, base, tip)), None


def _check(m, q, Tt, tol, scale):
    """Rows of joints q (deg) whose tip frame (fkopt's FK) is within tol of targets Tt (4x4,
    lengths times ``scale`` = the arm's unit per m) and inside the limits."""
    T = m.fk_matrix(q)
    perr = np.linalg.norm(T[:, :3, 3] - Tt[:, :3, 3] * scale, axis=-1)
    M = np.einsum("kji,kjl->kil", T[:, :3, :3], Tt[:, :3, :3])
    ang = np.arccos(np.clip((np.trace(M, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0))
    return (perr <= tol[0]) & (ang <= tol[1]) & m.in_bounds(q, tol=0.0)


def bench_robots(rows, quick: bool, messages: list[str]) -> None:
    from . import kinematics, mechanism
    from .mechanisms import urdf
    sec = "robots"
    n = 200 if quick else 1000
    ns = 20 if quick else 100
    reps = 1 if quick else 2
    arms = []
    if urdf.example_robots_folder() is None:
        messages.append("example-robot-data not installed (pip install example-robot-data): "
                        "robots section measures the wang7dof arm only")
    else:
        for name in ARMS:
            t = time.perf_counter()
            m = urdf.example_robot(name)
            rows.add(sec, f"{name} load", (time.perf_counter() - t) * 1e3, "ms",
                     f"parse {Path(m.path).name} ({m.base_link} -> {m.tip_link}, {m.dof} joints)"
                     + ("; the process's first URDF" if not arms else ""))
            arms.append((name, m, m.path, m.base_link, m.tip_link, TOL_M, 1.0, m.periodic_mask()))
    # the DH arm (mm); rtb reads it as URDF, whose q1 is continuous (rtb's answers wrapped)
    arms.append(("wang7dof", mechanism("7dof-arm"), urdf.DEFAULT_FILE, "link0", "tool", TOL_MM, 1000.0,
                 mechanism("urdf").periodic_mask()))
    rtb_failed = None
    for name, m, path, base, tip, tol, scale, periodic in arms:
        rng = np.random.default_rng(2026)
        Q = m.bounds[:, 0] + rng.random((n, m.dof)) * (m.bounds[:, 1] - m.bounds[:, 0])
        P = m.fk(Q)
        Tt = m.fk_matrix(Q)
        Tt[:, :3, 3] /= scale                                   # targets in m for rtb
        kinematics._TABLES.clear()
        t = time.perf_counter()
        kinematics.inverse(m, P[:64], tol=tol)
        t_first = time.perf_counter() - t
        kinematics._TABLES.clear()
        t = time.perf_counter()
        kinematics._start_table(m, 4096)
        t_table = time.perf_counter() - t
        kinematics.inverse(m, P[:64], tol=tol)                  # the tree again, for the rows below
        rows.add(sec, f"{name} inverse first call (64 poses)", t_first * 1e3, "ms",
                 f"start table (4096 FK evaluations: {t_table * 1e3:.1f} ms again afterwards), its k-d tree"
                 + (", scipy.spatial import" if name == arms[0][0] else "") + " and the solve")
        kinematics.inverse(m, P[0], tol=tol)
        ets, rtb_failed = (None, rtb_failed) if rtb_failed else _rtb_ets(path, base, tip)
        if ets is not None:
            ets, version = ets
            if ets.n != m.dof:
                rtb_failed = f"rtb's chain of {name} has {ets.n} joints, fkopt's {m.dof}: rtb rows skipped"
                ets = None
        if rtb_failed and ets is None:
            messages.append(rtb_failed)
        rtol = 0.5 * (TOL_M[0]) ** 2

        def rtb_all(idx):
            qs, ts = np.empty((len(idx), m.dof)), np.empty(len(idx))
            for j, k in enumerate(idx):
                t0 = time.perf_counter()
                sol = ets.ik_LM(Tt[k], ilimit=30, slimit=100, tol=rtol, joint_limits=True)
                ts[j] = time.perf_counter() - t0
                qs[j] = np.degrees(getattr(sol, "q", None) if hasattr(sol, "q") else sol[0])
            qs[:, periodic] = (qs[:, periodic] + 180.0) % 360.0 - 180.0
            return qs, ts

        best_f, best_r = np.inf, np.inf
        for _ in range(reps):                                   # alternating: fkopt batch, rtb loop
            t = time.perf_counter()
            inv = kinematics.inverse(m, P, tol=tol)
            best_f = min(best_f, time.perf_counter() - t)
            if ets is not None:
                q_r, ts_r = rtb_all(range(n))
                best_r = min(best_r, ts_r.sum())
        ok = _check(m, inv.joints, Tt, tol, scale)
        us = best_f / n * 1e6
        lie = int((inv.solved & ~ok).sum())
        r_us = best_r / n * 1e6
        rows.add(sec, f"{name} inverse batch {n}", us, "µs/pose",
                 f"best of {reps}; " + (f"rtb {r_us:.0f} µs/pose, ratio fkopt/rtb {us / r_us:.2f} (target <= 1)"
                                        if ets is not None else "no rtb"))
        rows.add(sec, f"{name} inverse solved", 100.0 * ok.mean(), "%",
                 f"{n} random reachable poses, 0.1 mm and 1e-3 rad, verified; target >= 99.5 %; "
                 f"reported solved but not: {lie}; Jacobians per pose {inv.evaluations['jacobian'].mean():.1f}")
        if ets is not None:
            rok = _check(m, q_r, Tt, tol, scale)
            rows.add(sec, f"{name} rtb ik_LM solved", 100.0 * rok.mean(), "%",
                     f"rtb {version} ETS ik_LM, same {n} poses, verified by fkopt's FK")
        tf, tr = [], []
        for k in range(ns):                                     # alternating, one pose each
            t = time.perf_counter()
            kinematics.inverse(m, P[k], tol=tol)
            tf.append(time.perf_counter() - t)
            if ets is not None:
                tr.append(rtb_all([k])[1][0])
        f_ms = float(np.median(tf)) * 1e3
        note = f"median of {ns} (mean {np.mean(tf) * 1e3:.2f} ms)"
        if ets is not None:
            r_ms = float(np.median(tr)) * 1e3
            note += (f"; rtb median {r_ms:.3f} ms (mean {np.mean(tr) * 1e3:.3f}), ratio fkopt/rtb "
                     f"{f_ms / r_ms:.2f} (target <= 4)")
        rows.add(sec, f"{name} inverse one pose", f_ms, "ms/pose", note)
