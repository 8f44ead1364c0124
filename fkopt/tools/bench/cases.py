"""Section ``cases`` of ``fkopt bench``: N cases x 30 runs solved together (N = 1, 10, 100; GABC,
3-RPS, population 10, 600 iterations): wall time and ns per evaluation, beside the same GABC as a
plain C loop (:mod:`fkopt.tools.bench.c_reference`, run on the same 100 cases; the row is skipped with
a message when there is no compiler), the ratio and whether the target (<= 2x the compiled loop)
is met; and the chunk size (rows per chunk) that :data:`fkopt.solve.CHUNK_POINTS` was chosen from."""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

import fkopt
from fkopt.tools.bench.c_reference import REFERENCE_C, compile_reference, run_reference
from fkopt.tools.bench.measuring import Rows, uniform
from fkopt.problems import fk_problem
from fkopt.solve import CHUNK_POINTS, solve


def bench_cases(rows: Rows, quick: bool, rng, messages: list[str] | None = None) -> None:
    """N cases x 30 runs solved together (GABC, 3-RPS, population 10, 600 iterations), beside the
    compiled loop of :data:`REFERENCE_C` on the 100 cases in the same run.

    The N = 100 solve is run twice and the compiled loop three times, interleaved, and the best
    time of each is kept (this machine is shared; the best is the least disturbed, and the
    extra run of the reference only makes the target stricter). The compiled loop's final
    fitness is reported beside fkopt's so that a broken loop would show."""
    m = fkopt.mechanism("3-rps")
    iterations = 100 if quick else 600
    poses = uniform(m.bounds, (100,), rng)
    joints = m.ik(poses)
    with tempfile.TemporaryDirectory() as tmp:
        built = compile_reference(Path(tmp))
        if isinstance(built, str):
            (messages if messages is not None else []).append(
                f"cases: compiled reference row skipped: {built}")
        ref = None
        best = {}
        # numba's import and the compiled swarm kernels' cache load (or first compile) before any timing
        solve(fk_problem(m, joints[:1]), "gabc", population=10, iterations=2, runs=2, seed=1)
        for rep in range(2):
            for n in ((1, 10, 100) if rep == 0 else (100,)):
                problem = fk_problem(m, joints[:n])
                t, cpu = time.perf_counter(), time.process_time()
                res = solve(problem, "gabc", population=10, iterations=iterations, runs=30, seed=1)
                dt, dcpu = time.perf_counter() - t, time.process_time() - cpu
                if n not in best or dt < best[n][0]:
                    best[n] = (dt, dcpu, float(res.evaluations.sum()), float(np.median(res.fitness)))
            for _ in range(0 if isinstance(built, str) else 2 - rep):   # 3 runs in all: 2, then 1
                out = run_reference(built[0], joints, iterations, 10, 30)
                if ref is None or out["seconds"] < ref["seconds"]:
                    ref = out
    c_ns = None if ref is None else ref["seconds"] / ref["evaluations"] * 1e9
    for n in (1, 10, 100):
        dt, dcpu, evals, med = best[n]
        ns = dt / evals * 1e9
        note = (f"{n * 30} rows, {iterations} it, chunks of {CHUNK_POINTS // 10} rows; CPU time "
                f"{dcpu / evals * 1e9:.0f} ns/eval (less sensitive to a busy machine)")
        if n == 100:
            note += f"; best of 2; median final fitness {med:.2g}"
            if c_ns is not None:
                note += (f"; compiled loop {c_ns:.0f} ns/eval in this run, target <= {2 * c_ns:.0f}: "
                         f"{'met' if ns <= 2 * c_ns else 'NOT met'} (x{ns / c_ns:.2f})")
        rows.add("cases", f"gabc {n} cases x 30 runs time", dt, "s", f"{iterations} iterations")
        rows.add("cases", f"gabc {n} cases x 30 runs per evaluation", ns, "ns/eval", note)
    if ref is not None:
        sane = ref["median"] <= max(1e-6, 100.0 * best[100][3])
        rows.add("cases", "compiled C loop, 100 cases x 30 runs per evaluation", c_ns, "ns/eval",
                 f"{REFERENCE_C.name} ({built[1]}), one run after the other, best of 3; "
                 f"{ref['evaluations'] / 3000:.0f} evaluations per run; median final fitness "
                 f"{ref['median']:.2g} (fkopt {best[100][3]:.2g}): {'sane' if sane else 'NOT SANE'}")
        rows.add("cases", "fkopt / compiled loop at 100 cases x 30 runs", best[100][0] / best[100][2] * 1e9 / c_ns,
                 "x", f"target <= 2: {'met' if best[100][0] / best[100][2] * 1e9 <= 2 * c_ns else 'NOT met'}")
    if quick:
        return
    problem = fk_problem(m, joints)
    for chunk in (300, 1000, 3000):    # what CHUNK_POINTS was chosen from (same numbers each time)
        t = time.perf_counter()
        res = solve(problem, "gabc", population=10, iterations=200, runs=30, seed=1, chunk_rows=chunk)
        ns = (time.perf_counter() - t) / float(res.evaluations.sum()) * 1e9
        rows.add("cases", f"gabc 100 cases x 30 runs, {chunk} rows per chunk", ns, "ns/eval", "200 iterations")
