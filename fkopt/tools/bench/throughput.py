"""Section ``throughput`` of ``fkopt bench``: batched fitness evaluations per second at a batch of
10,000 points (shape (1, 10000, dim)) for every registered mechanism (parallel: ``fk_problem``,
serial: ``ik_problem``), and the cost of one single-point call (µs). Best of several calls."""
from __future__ import annotations

import fkopt
from fkopt.tools.bench.measuring import Rows, best_call_time, single_call_time, uniform
from fkopt.problems import fk_problem, ik_problem
from fkopt.registry import MECHANISMS

THROUGHPUT_TARGET = 3e6      # evaluations/s wanted for 6-sps-cmm at batch 1e4


def bench_throughput(rows: Rows, quick: bool, rng) -> None:
    min_time = 0.1 if quick else 0.5
    for name in MECHANISMS:
        m = fkopt.mechanism(name)
        x = uniform(m.bounds, (1, 10_000), rng)
        if m.kind == "parallel":
            problem = fk_problem(m, m.ik(x[0, 0]))
            how = "fk_problem(m, m.ik(pose0))"
        else:
            problem = ik_problem(m, m.fk(x[0, 0]))
            how = "ik_problem(m, m.fk(q0))"
        t = best_call_time(lambda: problem.fitness(x), min_time)
        rate = x.shape[1] / t
        note = how
        if name == "6-sps-cmm":
            note += f"; target >= {THROUGHPUT_TARGET / 1e6:g} M/s: {'met' if rate >= THROUGHPUT_TARGET else 'NOT met'}"
        rows.add("throughput", f"{name} batch 1e4", rate, "evals/s", note)
        x1 = x[0, 0].copy()
        t1 = single_call_time(lambda: problem.fitness(x1), min_time / 2)
        rows.add("throughput", f"{name} single point", t1 * 1e6, "µs/call", "fitness(x) with x shaped (dim,)")
