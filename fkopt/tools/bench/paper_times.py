"""Section ``mao2017`` of ``fkopt bench``: the whole Tab. 3 experiment of mao2017 (ACO, ABC, GABC;
30 runs x 600 iterations x population 10 on the 3-RPS case alpha=9, beta=13, z=622): wall time,
amortised ms per run, evaluations per run, beside the paper's MATLAB times. Best of 3
repetitions (1 in quick mode)."""
from __future__ import annotations

import time

import numpy as np

from fkopt.tools.bench.measuring import PAPER_MS, Rows, mao_problem
from fkopt.solve import solve


def bench_mao2017(rows: Rows, quick: bool) -> dict[str, float]:
    problem = mao_problem()
    reps = 1 if quick else 3
    per_run: dict[str, float] = {}
    for algo in ("aco", "abc", "gabc"):
        best, result = np.inf, None
        for _ in range(reps):
            t = time.perf_counter()
            result = solve(problem, algo, population=10, iterations=600, runs=30, seed=1)
            best = min(best, time.perf_counter() - t)
        ms = best / 30 * 1e3
        per_run[algo] = ms
        rep = f"best of {reps}" if reps > 1 else "1 repetition"
        rows.add("mao2017", f"{algo} 30 runs total", best, "s", f"30 runs x 600 it x pop 10, {rep}")
        rows.add("mao2017", f"{algo} per run (amortised)", ms, "ms/run",
                 f"paper (MATLAB, i7-4510U) {PAPER_MS[algo]} ms/run: x{PAPER_MS[algo] / ms:.0f} faster")
        rows.add("mao2017", f"{algo} evaluations per run", float(np.mean(result.evaluations)), "evals",
                 f"mean final fitness {float(np.mean(result.fitness)):.3g}")
    return per_run
