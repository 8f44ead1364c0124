"""Section ``peers`` of ``fkopt bench`` (``peers=True``): NiaPy ``ArtificialBeeColonyAlgorithm``,
MEALPY ``OriginalABC``, pygmo ``bee_colony`` (if importable) and npEA's GABC on fkopt's own 3-RPS
fitness, called one point at a time, same budget (10 food sources, 600 iterations, limit =
population * dim = 30 as fkopt's ABC default), timed in this process; ratio = peer ms per run /
fkopt's amortised GABC ms per run. A peer whose package is missing or fails is skipped with a
message. Each peer's package is optional: imported inside the function that runs it."""
from __future__ import annotations

import contextlib
import io
import time
import warnings

import numpy as np

from fkopt.tools.bench.measuring import Rows, mao_problem
from fkopt.solve import solve


def _peer_niapy(problem, runs: int):
    from niapy.algorithms.basic import ArtificialBeeColonyAlgorithm
    from niapy.problems import Problem
    from niapy.task import Task

    class FkoptFitness(Problem):
        def __init__(self):
            super().__init__(dimension=problem.dim, lower=problem.bounds[:, 0], upper=problem.bounds[:, 1])

        def _evaluate(self, x):
            return float(problem.fitness(x))

    out = []
    for k in range(runs):
        # NiaPy's population_size counts employed + onlooker bees: 20 -> 10 food sources.
        algo = ArtificialBeeColonyAlgorithm(population_size=20, limit=30, seed=k)
        task = Task(problem=FkoptFitness(), max_iters=600)
        t = time.perf_counter()
        _, best_f = algo.run(task)
        out.append((time.perf_counter() - t, task.evals, float(best_f)))
    return out, "niapy.ArtificialBeeColonyAlgorithm(population_size=20 (10 sources), limit=30), max_iters=600"


def _peer_mealpy(problem, runs: int):
    from mealpy import FloatVar
    from mealpy.swarm_based.ABC import OriginalABC

    def obj(x):
        return float(problem.fitness(x))

    spec = {"obj_func": obj, "bounds": FloatVar(lb=problem.bounds[:, 0].tolist(), ub=problem.bounds[:, 1].tolist()),
            "minmax": "min", "log_to": None}
    out = []
    for k in range(runs):
        model = OriginalABC(epoch=600, pop_size=10, n_limits=30)
        t = time.perf_counter()
        best = model.solve(spec, seed=k)
        out.append((time.perf_counter() - t, model.nfe_counter, float(best.target.fitness)))
    return out, "mealpy OriginalABC(epoch=600, pop_size=10, n_limits=30)"


def pygmo_bee_colony(fitness_one, bounds, runs: int, gen: int = 600, population: int = 10, limit: int = 30,
                     clock=time.perf_counter, first: int = 0):
    """pygmo's C++ ``bee_colony`` on ``fitness_one`` (one point -> float), run ``runs`` times
    (seed k for run k from ``first``): per run (seconds of ``evolve`` by ``clock``, evaluations,
    final fitness)."""
    import pygmo as pg
    lo, hi = np.asarray(bounds)[:, 0].tolist(), np.asarray(bounds)[:, 1].tolist()

    class UDP:
        def fitness(self, x):
            return [float(fitness_one(x))]

        def get_bounds(self):
            return (lo, hi)

    out = []
    for k in range(first, first + runs):
        prob = pg.problem(UDP())
        algo = pg.algorithm(pg.bee_colony(gen=gen, limit=limit, seed=k))
        t = clock()
        pop = algo.evolve(pg.population(prob, population, seed=k))
        out.append((clock() - t, pop.problem.get_fevals(), float(pop.champion_f[0])))
    return out


def _peer_pygmo(problem, runs: int):
    out = pygmo_bee_colony(lambda x: problem.fitness(np.asarray(x)), problem.bounds, runs)
    return out, "pygmo bee_colony(gen=600, limit=30), population 10"


def _peer_npea(problem, runs: int):
    from npea.ABC_ import GABC

    calls = [0]

    def f(x):
        calls[0] += 1
        return float(problem.fitness(np.asarray(x)))

    out = []
    for k in range(runs):
        calls[0] = 0
        t = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()):   # npea prints its parameters
            _, fit, _ = GABC(f, popsize=10, limit=30, C=1.5, lb=problem.bounds[:, 0].tolist(),
                             ub=problem.bounds[:, 1].tolist(), MaxFEs=12_000, seed=k)
        out.append((time.perf_counter() - t, calls[0], float(fit)))
    return out, "npEA GABC(popsize=10, limit=30, C=1.5, MaxFEs=12000) (vectorised moves, per-point fitness)"


def bench_peers(rows: Rows, quick: bool, fkopt_gabc_ms: float | None, messages: list[str]) -> None:
    problem = mao_problem()
    runs = 3 if quick else 10
    # fkopt alone, one run at a time (no batching), for an apples-to-apples single-run figure
    times = []
    for k in range(runs):
        t = time.perf_counter()
        r = solve(problem, "gabc", population=10, iterations=600, runs=1, seed=1, run_ids=[k])
        times.append(time.perf_counter() - t)
    alone_ms = float(np.median(times) * 1e3)
    rows.add("peers", "fkopt gabc, one run alone", alone_ms, "ms/run",
             f"median of {runs} single runs; evals {int(r.evaluations[0])}, final f {float(r.fitness[0]):.3g}")
    peers = [("niapy", _peer_niapy), ("mealpy", _peer_mealpy)]
    try:
        import pygmo  # noqa: F401
        peers.append(("pygmo", _peer_pygmo))
    except Exception:
        messages.append("peer pygmo skipped: not importable")
    peers.append(("npea", _peer_npea))
    for name, fn in peers:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                out, how = fn(problem, runs)
        except ImportError as err:
            messages.append(f"peer {name} skipped: not installed ({err}); pip install 'fkopt[bench]'")
            continue
        except Exception as err:   # a peer's own failure must not stop the benchmark
            messages.append(f"peer {name} skipped: {type(err).__name__}: {err}")
            continue
        t = np.array([o[0] for o in out])
        ev = np.array([o[1] for o in out], dtype=float)
        f = np.array([o[2] for o in out])
        ms = float(np.median(t) * 1e3)
        rows.add("peers", f"{name} per run", ms, "ms/run", f"median of {runs} runs; {how}")
        rows.add("peers", f"{name} evaluations per run", float(ev.mean()), "evals", "")
        rows.add("peers", f"{name} final fitness (median)", float(np.median(f)), "", "")
        if fkopt_gabc_ms:
            rows.add("peers", f"{name} / fkopt gabc amortised", ms / fkopt_gabc_ms, "x",
                     f"fkopt gabc {fkopt_gabc_ms:.3g} ms/run amortised over 30 batched runs")
        rows.add("peers", f"{name} / fkopt gabc one run alone", ms / alone_ms, "x",
                 "same work, no batching: fkopt's per-iteration overhead with 10 points")
