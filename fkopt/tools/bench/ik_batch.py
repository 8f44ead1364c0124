"""Section ``ik-batch`` of ``fkopt bench``: all ``n`` poses (1000; 200 in quick mode) of each arm
of :mod:`.ik_arms` in one ``fkopt.inverse`` call beside rtb called per pose on the same poses,
alternating call by call (best of 5: one call of 1000 poses takes ~10-15 ms, and best of 2 moved the rate by 15 % between two idle runs; 1 in quick mode); per arm µs per pose of each and their
ratio, IK per second of wall time and per CPU-second; median over arms (target <= 0.5, none
above 1)."""
from __future__ import annotations

import os
import time

import numpy as np

from fkopt.tools.bench.ik_arms import ARMS, QUICK_ARMS, arms as bench_arms, ratio_summary
from fkopt.tools.bench.measuring import load_average
from fkopt.kinematics import solvers as kinematics

#: Issue 38: batched IK on Panda and UR5 at 1e-6: IK/s wall on 2 idle cores, IK per CPU-second
#: (process time, all threads) under any load; IK/s wall on every arm.
BATCH_TARGET = {"wall": 100_000.0, "cpu": 50_000.0, "every_arm_wall": 50_000.0}


def bench_ik_batch(rows, quick: bool, messages: list[str]) -> None:
    sec = "ik-batch"
    n = 200 if quick else 1000
    reps = 1 if quick else 5
    arms = bench_arms(QUICK_ARMS if quick else ARMS, n, messages)
    if not arms:
        return
    ratios = {}
    for a in arms:
        kinematics.inverse(a.m, a.P[:64], tol=a.tol)              # warm: start table, tree, compile
        best_f = best_r = cpu_f = np.inf
        for _ in range(reps):
            t, c = time.perf_counter(), time.process_time()
            res = kinematics.inverse(a.m, a.P, tol=a.tol)
            dt, dc = time.perf_counter() - t, time.process_time() - c
            if dt < best_f:
                best_f, cpu_f = dt, dc
            t = time.perf_counter()
            qr = [a.rtb(k) for k in range(n)]
            best_r = min(best_r, time.perf_counter() - t)
        okf_rows = np.array([a.verified(res.joints[k], k) for k in range(n)])
        okf = int(okf_rows.sum())
        lie = int((np.asarray(res.solved, bool) & ~okf_rows).sum())
        okr = sum(a.verified(qr[k], k) for k in range(n))
        f_us, r_us = best_f / n * 1e6, best_r / n * 1e6
        ratios[a.name] = f_us / r_us
        rows.add(sec, a.name, f_us / r_us, "x rtb",
                 f"{a.m.dof} joints; fkopt {f_us:.0f} µs/pose in one call of {n}, rtb {r_us:.0f} µs/pose "
                 f"(one call per pose); best of {reps}; solved ({a.check.name}) fkopt {okf}/{n}, rtb {okr}/{n}; "
                 f"fkopt reported solved but not: {lie}")
        wall, cpu = n / best_f, n / max(cpu_f, 1e-9)
        load = load_average()
        key = a.name in ("panda", "ur5")
        rows.add(sec, f"{a.name} IK/s wall", wall, "IK/s",
                 f"{n} poses in one call, 1e-6 m / 1e-6 rad, {okf}/{n} verified; load average {load} on "
                 f"{os.cpu_count()} CPUs; target >= {BATCH_TARGET['every_arm_wall']:,.0f} on every arm"
                 + (f", >= {BATCH_TARGET['wall']:,.0f} on Panda and UR5" if key else "") + " (idle cores): "
                 + ("met" if wall >= (BATCH_TARGET["wall"] if key else BATCH_TARGET["every_arm_wall"]) else "NOT met")
                 + ("" if load.split()[0] == "unknown" or float(load.split()[0]) < 0.5 else
                    " (not idle: a wall rate under load understates the idle one)"))
        rows.add(sec, f"{a.name} IK per CPU-second", cpu, "IK/s",
                 f"process time of the same call, all threads; target >= {BATCH_TARGET['cpu']:,.0f}"
                 + (f" (Panda, UR5): {'met' if cpu >= BATCH_TARGET['cpu'] else 'NOT met'}" if key else ""))
    ratio_summary(rows, sec, ratios, 0.5, 1,
                  f"µs per pose, fkopt batched ({n} poses) / rtb per pose; load average {load_average()}")
