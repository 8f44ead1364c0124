"""Section ``kinematics`` of ``fkopt bench``: the exact solvers' targets side by side: 6-sps-cmm
``fkopt.forward`` on one pose beside a plain numpy Newton with the analytic Jacobian, batched over
10,000 poses, solved-and-verified rate; Dietmaier's 40 solutions (5 seeds); 6-sps-cmm
``all_solutions`` on poses anywhere in the box and near its bounds (bounded angles: the padded
start box); 7dof-arm ``fkopt.inverse`` on 1000 reachable poses batched and one at a time, beside
roboticstoolbox-python's ``ik_LM`` (run in the Python named by ``FKOPT_RTB_PYTHON``, or
/work/venv-rtb, when installed); the whole ``fkopt fk`` process beside ``python -c "import numpy"``."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

import fkopt
from fkopt.tools.bench.measuring import Rows, uniform
from fkopt.kinematics import solvers as kinematics
from fkopt.kinematics.assembly_modes import all_solutions
from fkopt.mechanisms.sps6 import DIETMAIER_LEGS
from fkopt.numerics.rotations import to_array


_RTB_SCRIPT = r"""
import json, sys, time
import numpy as np
import roboticstoolbox as rtb
d = json.load(sys.stdin)
links = [rtb.RevoluteDH(a=a, alpha=np.radians(al), d=dd, qlim=np.radians(lim))
         for a, al, dd, lim in zip(d["a"], d["alpha"], d["d"], d["limits"])]
robot = rtb.DHRobot(links)
T = np.array(d["T"])
robot.ik_LM(T[0])
qs, ok, times = [], [], []
for Ti in T:
    t = time.perf_counter()
    sol = robot.ik_LM(Ti, ilimit=30, slimit=100, tol=1e-10, joint_limits=True)
    times.append(time.perf_counter() - t)
    qs.append(np.degrees(sol.q).tolist())
    ok.append(bool(sol.success))
print(json.dumps({"q": qs, "success": ok, "times": times, "version": rtb.__version__}))
"""


def _rtb_python() -> str | None:
    """A Python with roboticstoolbox-python (``FKOPT_RTB_PYTHON``, else /work/venv-rtb), or None."""
    for cand in (os.environ.get("FKOPT_RTB_PYTHON"), "/work/venv-rtb/bin/python"):
        if cand and shutil.which(cand):
            return cand
    return None


def _forward_plain_newton(m, legs, iterations: int = 20):
    """A plain numpy Newton with the analytic Jacobian (no checks, no line search): the yardstick."""
    x = m.bounds.mean(axis=1)
    for _ in range(iterations):
        v, J = m.ik_jacobian(x[None])
        r = v[0] - legs
        if np.abs(r).max() < 1e-11:
            break
        x = x - np.linalg.solve(J[0], r)
    return x


def _process_times(cmds: list[list[str]], reps: int, env=None) -> list[float]:
    """Best wall time of each command over ``reps`` rounds, the commands alternating within a
    round (so that a ratio between them sees the same machine load)."""
    best = [np.inf] * len(cmds)
    for _ in range(reps):
        for i, cmd in enumerate(cmds):
            t = time.perf_counter()
            subprocess.run(cmd, capture_output=True, check=False, env=env)
            best[i] = min(best[i], time.perf_counter() - t)
    return best


def bench_kinematics(rows: Rows, quick: bool, rng, messages: list[str]) -> None:
    """Targets of the exact solvers (issue 12), measured side by side in this process."""
    sec = "kinematics"
    m = fkopt.mechanism("6-sps-cmm")
    # one pose in-process: fkopt.forward vs a plain numpy Newton with the analytic Jacobian
    n1 = 30 if quick else 200
    poses = uniform(m.bounds, (n1,), rng)
    legs = m.ik(poses)
    t_fwd, t_plain, ok_plain = [], [], 0
    kinematics.forward(m, legs[0])
    for L in legs:
        t = time.perf_counter()
        kinematics.forward(m, L)
        t_fwd.append(time.perf_counter() - t)
        t = time.perf_counter()
        x = _forward_plain_newton(m, L)
        t_plain.append(time.perf_counter() - t)
        ok_plain += bool(np.abs(m.ik(x) - L).max() <= 1e-9)
    f_ms, p_ms = np.median(t_fwd) * 1e3, np.median(t_plain) * 1e3
    rows.add(sec, "6-sps-cmm forward one pose", f_ms, "ms/pose",
             f"median of {n1} poses, fkopt.forward; target <= plain Newton: {'met' if f_ms <= p_ms else 'NOT met'}")
    rows.add(sec, "6-sps-cmm plain numpy Newton one pose", p_ms, "ms/pose",
             f"analytic J, from the box centre, no checks; solved {ok_plain}/{n1}")
    # batched
    nb = 2000 if quick else 10000
    poses = uniform(m.bounds, (nb,), rng)
    legs = m.ik(poses)
    t = time.perf_counter()
    res = kinematics.forward(m, legs)
    us = (time.perf_counter() - t) / nb * 1e6
    rows.add(sec, f"6-sps-cmm forward batch {nb}", us, "µs/pose", f"target <= 10 µs: {'met' if us <= 10 else 'NOT met'}")
    verified = (np.abs(m.ik(res.pose) - legs).max(axis=-1) <= 1e-9) & m.in_bounds(res.pose)
    rows.add(sec, "6-sps-cmm forward solved and verified", 100.0 * np.mean(verified & res.solved), "%",
             f"{nb} random poses in the box; max |ik(pose) - legs| <= 1e-9 m, pose in bounds")
    rows.add(sec, "6-sps-cmm forward evaluations per pose", float(np.mean(res.evaluations["residual"])), "evals",
             f"residual evaluations (and {np.mean(res.evaluations['jacobian']):.2f} analytic Jacobians)")
    # Dietmaier's 40 real solutions
    d6 = fkopt.mechanism("6-sps")
    seeds = range(2 if quick else 5)
    t = time.perf_counter()
    all_solutions(d6, DIETMAIER_LEGS, seed=1000)      # warm-up, reported on its own row
    rows.add(sec, "dietmaier all solutions, first call", (time.perf_counter() - t) * 1e3, "ms",
             "seed 1000, the process's first search (first touch of its arrays' memory); "
             "the seeds below are timed after it, as the other rows after their warm-up")
    found, times = [], []
    for seed in seeds:
        t = time.perf_counter()
        sols = all_solutions(d6, DIETMAIER_LEGS, seed=seed)
        times.append(time.perf_counter() - t)
        found.append(len(sols))
    rows.add(sec, "dietmaier all solutions", float(np.median(times)) * 1e3, "ms",
             f"median of {len(times)} seeds (max {max(times) * 1e3:.1f} ms); found {found}; target <= 50 ms and 40 each: "
             f"{'met' if max(times) <= 0.05 and min(found) == 40 else 'NOT met'}")
    # 6-sps-cmm (bounded angles): poses anywhere in the box, and near its bounds (every coordinate
    # within 5 % of a bound), own stream so that the rows below draw what they drew before
    prng = np.random.default_rng(2008)
    npose = 10 if quick else 40
    lo, hi = m.bounds.T
    anywhere = prng.random((npose, 6))
    near = np.where(prng.random((npose, 6)) < 0.5, 0.05 * prng.random((npose, 6)), 1 - 0.05 * prng.random((npose, 6)))
    all_solutions(m, m.ik(lo + 0.5 * (hi - lo)), seed=0)                # warm-up
    for label, U in (("anywhere", anywhere), ("near the bounds", near)):
        poses = lo + U * (hi - lo)
        times, hit = [], 0
        for pose in poses:
            t = time.perf_counter()
            sols = all_solutions(m, m.ik(pose), seed=0)
            times.append(time.perf_counter() - t)
            hit += bool(len(sols)) and bool(np.abs(sols.poses() - pose).max(-1).min() < 1e-6)
        rows.add(sec, f"6-sps-cmm all solutions, poses {label}", float(np.median(times)) * 1e3, "ms",
                 f"median of {npose} poses (max {max(times) * 1e3:.1f} ms), default settings, seed 0; "
                 f"the drawn pose among the solutions: {hit}/{npose}")
    # 7dof-arm inverse
    arm = fkopt.mechanism("7dof-arm")
    ni = 200 if quick else 1000
    Q = uniform(arm.bounds, (ni,), rng)
    P = arm.fk(Q)
    kinematics._TABLES.clear()
    t = time.perf_counter()
    kinematics.inverse(arm, P[:64], seed=0)              # warm-up: builds the start table
    rows.add(sec, "7dof-arm inverse first call (64 poses)", (time.perf_counter() - t) * 1e3, "ms",
             "includes building the 4096-configuration start table and its k-d tree, and importing "
             "scipy.spatial (once per process; a single pose needs neither scipy nor the tree)")
    reps = 1 if quick else 3
    best = np.inf
    for _ in range(reps):
        t = time.perf_counter()
        inv = kinematics.inverse(arm, P, seed=0)
        best = min(best, time.perf_counter() - t)
    us = best / ni * 1e6
    ok = (inv.position_error <= 0.1) & (inv.rotation_error <= 1e-3) & arm.in_bounds(inv.joints, tol=0.0)
    rows.add(sec, f"7dof-arm inverse batch {ni}", us, "µs/pose",
             f"best of {reps} calls; target <= 100 µs: {'met' if us <= 100 else 'NOT met'}")
    rows.add(sec, "7dof-arm inverse solved (0.1 mm, 1e-3 rad)", 100.0 * ok.mean(), "%",
             f"{ni} random reachable poses (fk of random in-limit joints), joints in limits; target >= 99.5 %")
    rows.add(sec, "7dof-arm inverse solved (default tol)", 100.0 * inv.solved.mean(), "%",
             f"position <= {inv.tol[0]:g} mm, orientation <= {inv.tol[1]:g} rad")
    rows.add(sec, "7dof-arm inverse Jacobians per pose", float(inv.evaluations["jacobian"].mean()), "evals",
             f"each with the forward map at the same point; mean restarts {inv.restarts.mean():.2f}")
    ns = 20 if quick else 100
    ts = []
    single_ok = 0
    kinematics.inverse(arm, P[0])
    for k in range(ns):
        t = time.perf_counter()
        r1 = kinematics.inverse(arm, P[k], seed=0)
        ts.append(time.perf_counter() - t)
        single_ok += bool(r1.position_error <= 0.1 and r1.rotation_error <= 1e-3)
    single_ms = float(np.median(ts)) * 1e3
    rows.add(sec, "7dof-arm inverse one pose", single_ms, "ms/pose",
             f"median of {ns} poses (mean {np.mean(ts) * 1e3:.2f} ms), solved {single_ok}/{ns}")
    py = None
    try:
        import roboticstoolbox  # noqa: F401
        py = sys.executable
    except ImportError:
        py = _rtb_python()
    if py is None:
        messages.append("roboticstoolbox-python not found (pip install roboticstoolbox-python, or set "
                        "FKOPT_RTB_PYTHON to a Python that has it): ik_LM comparison skipped")
        return
    g = arm.geometry
    payload = json.dumps({"a": g.a, "alpha": g.alpha, "d": g.d, "limits": [list(v) for v in g.limits],
                          "T": arm.fk_matrix(Q[:ns]).tolist()})
    proc = subprocess.run([py, "-c", _RTB_SCRIPT], input=payload, capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        messages.append(f"roboticstoolbox ik_LM failed: {proc.stderr.strip().splitlines()[-1:]}")
        return
    out = json.loads(proc.stdout)
    q = np.array(out["q"])
    p_r, R_r = arm.frame(q)
    perr = np.sqrt(sum((p_r[i] - P[:ns, i]) ** 2 for i in range(3)))
    Rt = to_array(arm.frame(Q[:ns])[1])
    M = np.einsum("nij,nkj->nik", to_array(R_r), Rt)
    ang = np.arccos(np.clip((np.trace(M, axis1=1, axis2=2) - 1) / 2, -1, 1))
    rok = (perr <= 0.1) & (ang <= 1e-3) & arm.in_bounds(q, tol=1e-9)
    rtb_ms = float(np.median(out["times"])) * 1e3
    rows.add(sec, "roboticstoolbox ik_LM one pose", rtb_ms, "ms/pose",
             f"rtb {out['version']}, same {ns} poses, median (mean {np.mean(out['times']) * 1e3:.2f} ms), "
             f"solved {int(rok.sum())}/{ns} (0.1 mm, 1e-3 rad, in limits); fkopt single pose faster: "
             f"{'yes' if single_ms < rtb_ms else 'NO'}")


def bench_cli_process(rows: Rows, quick: bool) -> None:
    """Whole-process time of ``fkopt fk 6-sps-cmm --joints ...`` beside ``python -c 'import numpy'``,
    the two commands alternating (best of each), so that their ratio sees the same machine load.

    Both with compiled bytecode cached (a temporary ``PYTHONPYCACHEPREFIX``, one warm-up run
    each), as in any installation, and, for the record, in this process's own environment
    (where ``PYTHONDONTWRITEBYTECODE=1`` makes every start compile fkopt's sources again).
    Such a command imports numpy, typer (with pydantic) and the modules of the mechanism and
    the solver, not pandas or matplotlib."""
    reps = 5 if quick else 15
    numpy_cmd = [sys.executable, "-c", "import numpy"]
    fk_cmd = [sys.executable, "-m", "fkopt.cli", "fk", "6-sps-cmm", "--joints",
              "l1=0.75,l2=0.78,l3=0.8,l4=0.9,l5=0.87,l6=0.85"]
    with tempfile.TemporaryDirectory(prefix="fkopt-pyc-") as pyc:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        env["PYTHONPYCACHEPREFIX"] = pyc
        numpy_s, fk_s = _process_times([numpy_cmd, fk_cmd], reps + 1, env)
    rows.add("kinematics", "python -c 'import numpy' process", numpy_s * 1e3, "ms",
             f"best of {reps + 1} (first one compiles), bytecode cached")
    rows.add("kinematics", "fkopt fk 6-sps-cmm process", fk_s * 1e3, "ms",
             f"best of {reps + 1}, bytecode cached; ratio {fk_s / numpy_s:.2f} x numpy; target <= 2 x: "
             f"{'met' if fk_s <= 2 * numpy_s else 'NOT met'}")
    if os.environ.get("PYTHONDONTWRITEBYTECODE"):
        raw_n, raw_f = _process_times([numpy_cmd, fk_cmd], reps)
        rows.add("kinematics", "fkopt fk 6-sps-cmm process, no bytecode cache", raw_f * 1e3, "ms",
                 f"best of {reps}; PYTHONDONTWRITEBYTECODE is set here: {raw_f / raw_n:.2f} x numpy "
                 f"({raw_n * 1e3:.0f} ms) in the same setting")
