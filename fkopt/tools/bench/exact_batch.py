"""Section ``exact`` of ``fkopt bench``: 6-SPS (CMM) forward kinematics of 1000 random poses solved
exactly by the batched ``lm`` in one call (the poses are the cases of one problem); ms per pose
and success."""
from __future__ import annotations

import time

import numpy as np

import fkopt
from fkopt.tools.bench.measuring import Rows, uniform
from fkopt.problems import fk_problem
from fkopt.solve import solve

EXACT_TARGET_MS = 0.3        # ms per pose wanted for the batched exact 6-SPS solve


def bench_exact(rows: Rows, quick: bool, rng) -> None:
    m = fkopt.mechanism("6-sps-cmm")
    n = 1000
    poses = uniform(m.bounds, (n,), rng)
    legs = m.ik(poses)
    problem = fk_problem(m, legs)          # one problem, n cases
    x0 = m.bounds.mean(axis=1)
    reps = 1 if quick else 3
    times, result = [], None
    for _ in range(reps):
        t = time.perf_counter()
        result = solve(problem, "lm", population=1, iterations=50, runs=1, x0=x0)
        times.append(time.perf_counter() - t)
    x = result.x[:, 0]
    err = np.abs(m.ik(x) - legs).max(axis=-1)
    ok = err < 1e-9
    ms = float(np.median(times)) / n * 1e3
    rows.add("exact", "6-sps-cmm lm per pose", ms, "ms/pose",
             f"{n} random poses as the cases of one batched lm solve (50 it, start = centre of bounds), "
             f"median of {reps}; target < {EXACT_TARGET_MS} ms: {'met' if ms < EXACT_TARGET_MS else 'NOT met'}")
    rows.add("exact", "6-sps-cmm lm success", ok.mean() * 100, "%", "max |ik(x) - legs| < 1e-9")
    found = np.abs(x - poses).max(axis=-1) < 1e-6
    rows.add("exact", "6-sps-cmm lm found the drawn pose", found.mean() * 100, "%",
             "others: another assembly mode with the same legs, or a miss")
    rows.add("exact", "6-sps-cmm lm evaluations per pose", float(np.mean(result.evaluations)), "evals",
             "residual evaluations")
