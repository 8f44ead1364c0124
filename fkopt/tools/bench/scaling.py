"""Section ``scaling`` of ``fkopt bench``: GABC on the 3-RPS case with population 10..1000 (30
runs) and runs 1..1000 (population 10): wall time and ns per evaluation; plotted into
``scaling.png`` (:func:`plot_scaling`)."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fkopt.tools.bench.measuring import Rows, mao_problem
from fkopt.solve import solve


def bench_scaling(rows: Rows, quick: bool) -> dict[str, list[tuple[int, float, float]]]:
    problem = mao_problem()
    iterations = 50 if quick else 200
    pops = (10, 100, 1000) if quick else (10, 30, 100, 300, 1000)
    runs_list = (1, 100, 1000) if quick else (1, 10, 100, 1000)
    curves: dict[str, list[tuple[int, float, float]]] = {"population": [], "runs": []}
    for label, cases in (("population", [(p, 30) for p in pops]), ("runs", [(10, r) for r in runs_list])):
        for pop, runs in cases:
            t = time.perf_counter()
            res = solve(problem, "gabc", population=pop, iterations=iterations, runs=runs, seed=1)
            dt = time.perf_counter() - t
            ns = dt / float(res.evaluations.sum()) * 1e9
            curves[label].append((pop if label == "population" else runs, dt, ns))
            item = f"gabc pop {pop}, {runs} runs"
            rows.add("scaling", item + " time", dt, "s", f"{iterations} iterations")
            rows.add("scaling", item + " per evaluation", ns, "ns/eval", "")
    return curves


def plot_scaling(curves, path: Path, iterations: int):
    """Two panels (growing population, growing runs), each with two y-axes told apart by marker,
    line style and label as well as colour: cost per evaluation (left, circles, solid) and wall
    time (right, squares, dashed). Returns the figure."""
    fig = Figure(figsize=(10, 4.2))
    for ax, key, xlabel, title in zip(fig.subplots(1, 2), ("population", "runs"),
                                      ("population (30 runs)", "runs (population 10)"),
                                      ("growing the population", "growing the number of runs")):
        pts = np.array(curves[key], dtype=float)
        if not len(pts):
            continue
        cost, = ax.loglog(pts[:, 0], pts[:, 2], "o-", color="C0", label="ns per evaluation (left axis)")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("ns per evaluation  (● solid)", color="C0")
        ax2 = ax.twinx()
        wall, = ax2.loglog(pts[:, 0], pts[:, 1], "s--", color="C1", label="wall time, s (right axis)")
        ax2.set_ylabel("wall time, s  (■ dashed)", color="C1")
        ax.set_title(f"{title}: gabc on 3-RPS, {iterations} iterations", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(handles=[cost, wall], loc="upper center", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return fig
