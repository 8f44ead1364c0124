"""``fkopt bench``: measure fkopt's speed on this machine (and, optionally, peers' speed).

Sections of the table (and of ``bench.csv``: columns section, item, value, unit, note):

1. ``throughput`` -- batched fitness evaluations per second at a batch of 10,000 points
   (shape (1, 10000, dim)) for every registered mechanism (parallel: ``fk_problem``, serial:
   ``ik_problem``), and the cost of one single-point call (µs). Best of several calls.
2. ``mao2017`` -- the whole Tab. 3 experiment (ACO, ABC, GABC; 30 runs x 600 iterations x
   population 10 on the 3-RPS case alpha=9, beta=13, z=622): wall time, amortised ms per run,
   evaluations per run, beside the paper's MATLAB times. Best of 3 repetitions (1 in quick mode).
3. ``peers`` (``peers=True``) -- NiaPy ``ArtificialBeeColonyAlgorithm`` and MEALPY
   ``OriginalABC`` on fkopt's own 3-RPS fitness, called one point at a time, same budget
   (10 food sources, 600 iterations, limit = population * dim = 30 as fkopt's ABC default),
   timed in this process; ratio = peer ms per run / fkopt's amortised GABC ms per run. Skipped
   with a message when a package is missing or fails. pygmo ``bee_colony`` only if importable.
3b. ``adapters`` (``peers=True`` or named) -- ``scipy:differential_evolution``, ``pymoo:DE`` and
   ``niapy:DifferentialEvolution`` through fkopt's adapters beside fkopt's gabc, abc and
   examples/plugin's DE, on kinbench's problems and settings (population 20, 2000 x dimension,
   stop below 1e-10), alternating in one process: ms per solve, µs per evaluation, ratios to
   scipy's DE (:func:`bench_adapters`). Solvers whose library is missing are skipped.
4. ``exact`` -- 6-SPS (CMM) forward kinematics of 1000 random poses solved exactly by the
   batched ``lm`` in one call (the poses are the cases of one problem); ms per pose and success.
4b. ``kinematics`` -- the exact solvers' targets side by side: 6-sps-cmm ``fkopt.forward`` on one
   pose beside a plain numpy Newton with the analytic Jacobian, batched over 10,000 poses,
   solved-and-verified rate; Dietmaier's 40 solutions (5 seeds); 6-sps-cmm ``all_solutions`` on
   poses anywhere in the box and near its bounds (bounded angles: the padded start box); 7dof-arm ``fkopt.inverse`` on
   1000 reachable poses batched and one at a time, beside roboticstoolbox-python's ``ik_LM``
   (run in the Python named by ``FKOPT_RTB_PYTHON``, or /work/venv-rtb, when installed); the
   whole ``fkopt fk`` process beside ``python -c "import numpy"``.
4c. ``ik-one-pose`` and ``ik-batch`` -- ``fkopt.inverse`` on 14 arms of example-robot-data and the
   wang7dof DH arm beside roboticstoolbox's ETS ``ik_LM`` at 1e-6 m and 1e-6 rad, one pose per
   call alternating query by query, and 1000 poses in one fkopt call beside rtb per pose; every
   answer verified by an independent FK (pinocchio's; rtb's DHRobot for the DH arm); ratios per
   arm and their median (:mod:`fkopt.bench.ik`).
4d. ``cases`` -- N cases x 30 runs solved together (N = 1, 10, 100; GABC, 3-RPS, population 10,
   600 iterations): wall time and ns per evaluation, beside the same GABC as a plain C loop
   (``fkopt/bench/ref/gabc_3rps.c``, compiled with the system's C compiler into a temporary
   folder and run on the same 100 cases; the row is skipped with a message when there is no
   compiler), the ratio and whether the target (<= 2x the compiled loop) is met; and the chunk
   size (rows per chunk) that :data:`fkopt.solve.CHUNK_POINTS` was chosen from.
4f. ``swarms`` -- GABC, ABC and PSO on 3-RPS at 1 case and 100 cases x 30 runs beside the same
   algorithm as the C loop of ``fkopt/bench/ref/gabc_3rps.c``, alternating: ns per evaluation and
   the ratio (issue 29's targets: <= 3 at 1 case, <= 1.5 at 100 cases), for the default path (the
   iterations compiled, the numpy path's bits) and ``FKOPT_NUMERICS=numpy``; and pygmo's C++
   ``bee_colony`` with a numba-compiled fitness beside fkopt's batched ABC (population 10, 600
   iterations, 30 runs), the ratio per run (target >= 10; the row needs pygmo and numba).
5. ``scaling`` -- GABC on the 3-RPS case with population 10..1000 (30 runs) and runs 1..1000
   (population 10): wall time and ns per evaluation; plotted into ``scaling.png``.

Timings are wall-clock on whatever else the machine is doing; tests never assert them.
"""
from __future__ import annotations

import os
import platform
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.problems import fk_problem, ik_problem
from fkopt.registry import MECHANISMS

#: mao2017 Tab. 3: mean time per run (ms) in MATLAB on an i7-4510U.
PAPER_MS = {"aco": 250.6, "abc": 362.4, "gabc": 361.3}
MAO_POSE = (9.0, 13.0, 622.0)
THROUGHPUT_TARGET = 3e6      # evaluations/s wanted for 6-sps-cmm at batch 1e4
EXACT_TARGET_MS = 0.3        # ms per pose wanted for the batched exact 6-SPS solve


# -- helpers ---------------------------------------------------------------------------------
class _Rows:
    def __init__(self):
        self.rows: list[dict] = []

    def add(self, section, item, value, unit, note=""):
        self.rows.append(dict(section=section, item=item, value=float(value), unit=unit, note=note))


def _best_call_time(fn, min_time: float, min_calls: int = 5) -> float:
    """Smallest wall time of one ``fn()`` call over at least ``min_calls`` calls / ``min_time`` s."""
    fn()   # warm-up
    best, spent, n = np.inf, 0.0, 0
    while n < min_calls or spent < min_time:
        t = time.perf_counter()
        fn()
        dt = time.perf_counter() - t
        best, spent, n = min(best, dt), spent + dt, n + 1
    return best


def _single_call_time(fn, min_time: float) -> float:
    """Mean wall time of one cheap call, from loops of 200 calls (best loop)."""
    fn()
    best, spent = np.inf, 0.0
    while spent < min_time or best == np.inf:
        t = time.perf_counter()
        for _ in range(200):
            fn()
        dt = time.perf_counter() - t
        best, spent = min(best, dt / 200), spent + dt
    return best


def _uniform(bounds: np.ndarray, shape, rng) -> np.ndarray:
    lo, hi = bounds[:, 0], bounds[:, 1]
    return lo + rng.random((*shape, len(lo))) * (hi - lo)


def mao_problem():
    from fkopt import mechanism
    m = mechanism("3-rps")
    return fk_problem(m, m.ik(np.array(MAO_POSE)))


# -- 1. throughput ---------------------------------------------------------------------------
def bench_throughput(rows: _Rows, quick: bool, rng) -> None:
    from fkopt import mechanism
    min_time = 0.1 if quick else 0.5
    for name in MECHANISMS:
        m = mechanism(name)
        x = _uniform(m.bounds, (1, 10_000), rng)
        if m.kind == "parallel":
            problem = fk_problem(m, m.ik(x[0, 0]))
            how = "fk_problem(m, m.ik(pose0))"
        else:
            problem = ik_problem(m, m.fk(x[0, 0]))
            how = "ik_problem(m, m.fk(q0))"
        t = _best_call_time(lambda: problem.fitness(x), min_time)
        rate = x.shape[1] / t
        note = how
        if name == "6-sps-cmm":
            note += f"; target >= {THROUGHPUT_TARGET / 1e6:g} M/s: {'met' if rate >= THROUGHPUT_TARGET else 'NOT met'}"
        rows.add("throughput", f"{name} batch 1e4", rate, "evals/s", note)
        x1 = x[0, 0].copy()
        t1 = _single_call_time(lambda: problem.fitness(x1), min_time / 2)
        rows.add("throughput", f"{name} single point", t1 * 1e6, "µs/call", "fitness(x) with x shaped (dim,)")


# -- 2. the mao2017 Tab. 3 experiment ----------------------------------------------------------
def bench_mao2017(rows: _Rows, quick: bool) -> dict[str, float]:
    from fkopt.solve import solve
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


# -- 3. peers --------------------------------------------------------------------------------
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


def _pygmo_bee_colony(fitness_one, bounds, runs: int, gen: int = 600, population: int = 10, limit: int = 30,
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
    out = _pygmo_bee_colony(lambda x: problem.fitness(np.asarray(x)), problem.bounds, runs)
    return out, "pygmo bee_colony(gen=600, limit=30), population 10"


def _peer_npea(problem, runs: int):
    import contextlib
    import io

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


def bench_peers(rows: _Rows, quick: bool, fkopt_gabc_ms: float | None, messages: list[str]) -> None:
    from fkopt.solve import solve
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


# -- 3b. library adapters side by side ---------------------------------------------------------
#: kinbench's problems as the suites define them (name, mechanism, geometry, objective); the
#: quick run uses the first three (the libraries subset's).
ADAPTER_PROBLEMS = (("mao2017-3rps", "3-rps", {"ra": 274, "rb": 158}, None),
                    ("wu2015-3ppr", "3-ppr", {}, None),
                    ("chang2024-3rpupc", "3-rpupc-ups", {"R": 120, "c": 60}, None),
                    ("liu2008-6sps", "6-sps-cmm", {"Rb": 0.5, "Rp": 0.225, "tb": 30, "tp": 30, "ls": 0.180},
                     "absolute"),
                    ("wang2020-7dof", "7dof-arm", {}, None))
#: (label, algorithm, params) timed by section ``adapters``; scipy's DE is the reference.
ADAPTER_SOLVERS = (("scipy:DE", "scipy:differential_evolution", {"polish": False, "tol": 0}),
                   ("pymoo:DE", "pymoo:DE", {}),
                   ("niapy:DE", "niapy:DifferentialEvolution", {}),
                   ("gabc", "gabc", {}),
                   ("abc", "abc", {}),
                   ("de (plug-in)", "fkopt_example.de:DE", {}))


def _adapter_problems(quick: bool):
    """(name, problem with a case axis, dimension) of the kinbench problems, on uniform poses
    drawn from a fixed stream (the same for every solver)."""
    from fkopt import mechanism
    rng = np.random.default_rng(2026)
    poses = 2 if quick else 4
    out = []
    for name, mech, geometry, objective in ADAPTER_PROBLEMS[:3 if quick else None]:
        m = mechanism(mech, **geometry)
        x = _uniform(m.bounds, (poses,), rng)
        kw = {"objective": objective} if objective else {}
        out.append((name, fk_problem(m, m.ik(x), **kw) if m.kind == "parallel" else ik_problem(m, m.fk(x), **kw),
                    len(m.bounds)))
    return out


def bench_adapters(rows: _Rows, quick: bool, messages: list[str]) -> None:
    """scipy's, pymoo's and NiaPy's DE through fkopt's adapters, beside fkopt's own gabc, abc and
    examples/plugin's DE, on kinbench's problems with kinbench's settings (population 20, budget
    2000 x dimension, stop below 1e-10), in this process, alternating solvers within each
    repetition (best of 2; 1 in quick mode). Per problem and solver: ms per solve (one pose x
    run), evaluations per solve, µs per evaluation, and the ratios to scipy's DE; per solver, the
    same over all problems (total time / total solves)."""
    import math
    import sys
    from fkopt.errors import FkoptError
    from fkopt.solve import make_algorithm, solve
    plugin = Path(__file__).resolve().parents[1] / "examples" / "plugin"
    if plugin.is_dir() and str(plugin) not in sys.path:
        sys.path.append(str(plugin))
    solvers = []
    for label, name, params in ADAPTER_SOLVERS:
        try:
            make_algorithm(name, params or None)
        except (FkoptError, ImportError) as err:
            messages.append(f"adapters: {label} skipped: {str(err).splitlines()[0]}")
            continue
        solvers.append((label, name, params))
    runs, reps = 2, (1 if quick else 2)
    problems = _adapter_problems(quick)
    best: dict[tuple[str, str], float] = {}
    evals: dict[tuple[str, str], float] = {}
    for rep in range(reps):
        for pname, problem, dim in problems:
            iterations = math.ceil(2000 * dim / 20)
            order = solvers[rep % len(solvers):] + solvers[:rep % len(solvers)]   # alternate who goes first
            for label, name, params in order:
                seeds = [1000 + i for i in range(problem.cases)]
                t = time.perf_counter()
                res = solve(problem, name, population=20, iterations=iterations, runs=runs, seed=seeds,
                            target=1e-10, stop_at_target=True, params=params or None)
                dt = (time.perf_counter() - t) / (problem.cases * runs)
                key = (pname, label)
                best[key] = min(best.get(key, np.inf), dt)
                evals[key] = float(np.mean(res.evaluations))
    labels = [s[0] for s in solvers]
    ref = "scipy:DE"
    for pname, problem, dim in problems:
        for label in labels:
            ms, ev = best[(pname, label)] * 1e3, evals[(pname, label)]
            us = ms * 1e3 / ev
            note = f"{ev:.0f} evals/solve, {us:.1f} µs/eval"
            if ref in labels and label != ref:
                ref_ms, ref_ev = best[(pname, ref)] * 1e3, evals[(pname, ref)]
                note += f"; x{ms / ref_ms:.2f} scipy's ms/solve, x{us / (ref_ms * 1e3 / ref_ev):.2f} its µs/eval"
            rows.add("adapters", f"{pname} (n={dim}) {label}", ms, "ms/solve", note)
    for label in labels:
        ms = float(np.mean([best[(p, label)] for p, _, _ in problems])) * 1e3
        ev = float(np.mean([evals[(p, label)] for p, _, _ in problems]))
        note = f"mean over {len(problems)} problems x {problems[0][1].cases} poses x {runs} runs; " \
               f"{ev:.0f} evals/solve, {ms * 1e3 / ev:.1f} µs/eval; best of {reps}"
        if ref in labels and label != ref:
            ref_ms = float(np.mean([best[(p, ref)] for p, _, _ in problems])) * 1e3
            note += f"; x{ms / ref_ms:.2f} scipy's DE"
        rows.add("adapters", f"all problems {label}", ms, "ms/solve", note)


# -- 4. exact solves of many 6-SPS poses at once ----------------------------------------------
def bench_exact(rows: _Rows, quick: bool, rng) -> None:
    from fkopt import mechanism
    from fkopt.solve import solve
    m = mechanism("6-sps-cmm")
    n = 1000
    poses = _uniform(m.bounds, (n,), rng)
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


# -- 4b. exact kinematics (fkopt.forward / fkopt.inverse) -------------------------------------
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
    import shutil
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
    import subprocess
    best = [np.inf] * len(cmds)
    for _ in range(reps):
        for i, cmd in enumerate(cmds):
            t = time.perf_counter()
            subprocess.run(cmd, capture_output=True, check=False, env=env)
            best[i] = min(best[i], time.perf_counter() - t)
    return best


def bench_kinematics(rows: _Rows, quick: bool, rng, messages: list[str]) -> None:
    """Targets of the exact solvers (issue 12), measured side by side in this process."""
    import json
    import subprocess
    import sys
    from fkopt import mechanism
    from fkopt.kinematics import solvers as kinematics
    from fkopt.kinematics.assembly_modes import all_solutions
    from fkopt.mechanisms.sps6 import DIETMAIER_LEGS
    sec = "kinematics"
    m = mechanism("6-sps-cmm")
    # one pose in-process: fkopt.forward vs a plain numpy Newton with the analytic Jacobian
    n1 = 30 if quick else 200
    poses = _uniform(m.bounds, (n1,), rng)
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
    poses = _uniform(m.bounds, (nb,), rng)
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
    d6 = mechanism("6-sps")
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
    arm = mechanism("7dof-arm")
    ni = 200 if quick else 1000
    Q = _uniform(arm.bounds, (ni,), rng)
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
    from fkopt.numerics.rotations import to_array
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


def bench_cli_process(rows: _Rows, quick: bool) -> None:
    """Whole-process time of ``fkopt fk 6-sps-cmm --joints ...`` beside ``python -c 'import numpy'``,
    the two commands alternating (best of each), so that their ratio sees the same machine load.

    Both with compiled bytecode cached (a temporary ``PYTHONPYCACHEPREFIX``, one warm-up run
    each), as in any installation, and, for the record, in this process's own environment
    (where ``PYTHONDONTWRITEBYTECODE=1`` makes every start compile fkopt's sources again).
    Such a command imports numpy, typer (with pydantic) and the modules of the mechanism and
    the solver, not pandas or matplotlib."""
    import sys
    import tempfile
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


#: The compiled reference of section ``cases``: the same GABC on the same 3-RPS fitness as a plain
#: C loop (one run after the other), compiled with the system's C compiler when the bench runs.
REFERENCE_C = Path(__file__).parent / "ref" / "gabc_3rps.c"
#: Compiler flags tried in order (the first that compiles is used).
REFERENCE_FLAGS = (("-O3", "-march=native"), ("-O2",))


def compile_reference(folder: Path) -> tuple[Path, str] | str:
    """Compile :data:`REFERENCE_C` into ``folder``: (executable, compiler command), or a message
    saying why not (no compiler: ``$CC``, ``gcc``, ``cc`` or ``clang`` on the PATH; errors)."""
    import shutil
    import subprocess
    cc = os.environ.get("CC") or next((c for c in ("gcc", "cc", "clang") if shutil.which(c)), None)
    if cc is None or shutil.which(cc.split()[0]) is None:
        return "no C compiler ($CC, gcc, cc or clang) on the PATH"
    exe = folder / "gabc_3rps"
    err = ""
    for flags in REFERENCE_FLAGS:
        cmd = [*cc.split(), *flags, "-o", str(exe), str(REFERENCE_C), "-lm"]
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        except (OSError, subprocess.SubprocessError) as e:
            return f"{cc} failed to run: {e}"
        if p.returncode == 0:
            return exe, " ".join([cc, *flags])
        err = (p.stderr.strip().splitlines() or ["(no message)"])[-1]
    return f"{cc} could not compile {REFERENCE_C.name}: {err}"


def run_reference(exe: Path, joints: np.ndarray, iterations: int, population: int, runs: int,
                  seed: int = 1, algorithm: str = "gabc") -> dict[str, float]:
    """Solve every row of ``joints`` (cases, 3) ``runs`` times with the compiled loop of
    ``algorithm`` (gabc, abc or pso): evaluations, seconds and cpu_seconds (of the solves, wall
    and CPU time, timed inside the program), median and largest final fitness."""
    import subprocess
    data = "\n".join(" ".join(repr(float(v)) for v in row) for row in np.atleast_2d(joints)) + "\n"
    p = subprocess.run([str(exe), str(iterations), str(population), str(runs), str(seed), algorithm], input=data,
                       capture_output=True, text=True, timeout=1800, check=True)
    evals, seconds, median, worst, cpu = p.stdout.split()
    return {"evaluations": float(evals), "seconds": float(seconds), "median": float(median),
            "worst": float(worst), "cpu_seconds": float(cpu)}


def bench_cases(rows: _Rows, quick: bool, rng, messages: list[str] | None = None) -> None:
    """N cases x 30 runs solved together (GABC, 3-RPS, population 10, 600 iterations), beside the
    compiled loop of :data:`REFERENCE_C` on the 100 cases in the same run.

    The N = 100 solve is run twice and the compiled loop three times, interleaved, and the best
    time of each is kept (this machine is shared; the best is the least disturbed, and the
    extra run of the reference only makes the target stricter). The compiled loop's final
    fitness is reported beside fkopt's so that a broken loop would show."""
    import tempfile
    from fkopt import mechanism
    from fkopt.solve import CHUNK_POINTS, solve
    m = mechanism("3-rps")
    iterations = 100 if quick else 600
    poses = _uniform(m.bounds, (100,), rng)
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


# -- 5. scaling ------------------------------------------------------------------------------
#: Section ``swarms``: issue 38's targets, fkopt / C loop per evaluation at 1 case and 100 cases
#: (issue 29's were 3 and 1.5).
SWARM_TARGETS = {1: 1.5, 100: 1.2}


def _load_average() -> str:
    """The load average (1, 5, 15 min) for a note: a shared machine's measurements say it beside them."""
    try:
        return "load " + "/".join(f"{v:.1f}" for v in os.getloadavg())
    except (AttributeError, OSError):     # pragma: no cover - not on every platform
        return "load unknown"


def bench_swarms(rows: _Rows, quick: bool, rng, messages: list[str]) -> None:
    """GABC, ABC and PSO on 3-RPS (population 10, 600 iterations; 100 in quick mode; 30 runs) at
    1 case and at 100 cases, beside the same algorithm as the plain C loop of
    :data:`REFERENCE_C` on the same cases; alternating fkopt solve on the default path, on
    ``FKOPT_NUMERICS=numpy`` and the C run, in CPU time (this process's, and the C program's own:
    what a shared machine disturbs least; both on one core), best of 5 at 1 case and of 2 at 100
    (1 in quick mode), the load average in every note. Rows: the ratio fkopt / C per evaluation,
    against :data:`SWARM_TARGETS`, for the default path (with numba: the whole iteration compiled
    around numpy's np.tan, :func:`fkopt.algorithms.abc_kernels.abc_iteration`, ``pso_iteration``;
    the numpy path's bits, checked here run for run) and the numpy path. Skipped with a message
    when there is no C compiler."""
    import tempfile
    from fkopt import mechanism
    from fkopt.solve import solve
    from fkopt.numerics import path as numerics_path
    m = mechanism("3-rps")
    iterations = 100 if quick else 600
    joints = m.ik(_uniform(m.bounds, (100,), rng))
    try:
        with numerics_path.forced("compiled"):
            fast = numerics_path.compiled() is not None
            if fast:                   # numba's import and the kernels' cache load before any timing
                solve(fk_problem(m, joints[:1]), "pso", population=10, iterations=2, runs=2, seed=1)
                solve(fk_problem(m, joints[:1]), "abc", population=10, iterations=2, runs=2, seed=1)
    except Exception:                  # numba missing or broken: the numpy path's rows only
        fast = False
    with tempfile.TemporaryDirectory() as tmp:
        built = compile_reference(Path(tmp))
        if isinstance(built, str):
            messages.append(f"swarms: section skipped: {built}")
            return
        for alg in ("gabc", "abc", "pso"):
            for n in SWARM_TARGETS:
                problem = fk_problem(m, joints[:n])
                f_ns, k_ns, c_ns = np.inf, np.inf, np.inf
                reps = 1 if quick else (5 if n == 1 else 2)
                load = _load_average()
                for _ in range(reps):              # numpy path, default path, C loop
                    with numerics_path.forced("numpy"):
                        t = time.process_time()
                        res = solve(problem, alg, population=10, iterations=iterations, runs=30, seed=1)
                        f_ns = min(f_ns, (time.process_time() - t) / float(res.evaluations.sum()) * 1e9)
                    if fast:
                        with numerics_path.forced("auto"):
                            t = time.process_time()
                            rk = solve(problem, alg, population=10, iterations=iterations, runs=30, seed=1)
                            k_ns = min(k_ns, (time.process_time() - t) / float(rk.evaluations.sum()) * 1e9)
                    ref = run_reference(built[0], joints[:n], iterations, 10, 30, algorithm=alg)
                    c_ns = min(c_ns, ref["cpu_seconds"] / ref["evaluations"] * 1e9)
                target = SWARM_TARGETS[n]
                label = f"{alg} {n} case{'s' if n > 1 else ''} x 30 runs"
                common = (f"C loop {c_ns:.0f} ns/eval ({built[1]}); CPU time, {iterations} it, population 10; best of "
                          f"{reps}; {load} -> {_load_average()}; median final fitness C {ref['median']:.2g}")
                if fast:
                    same = all(np.array_equal(getattr(res, k), getattr(rk, k)) for k in ("x", "fitness", "history"))
                    rows.add("swarms", label, k_ns / c_ns, "x C loop",
                             f"default path (compiled: the whole iteration and its evaluation log, numpy's np.tan); "
                             f"fkopt {k_ns:.0f} ns/eval, {common}, fkopt {float(np.median(rk.fitness)):.2g}; "
                             f"runs {'bit-identical to' if same else 'DIFFERENT from'} FKOPT_NUMERICS=numpy; "
                             f"target <= {target:g}: {'met' if k_ns <= target * c_ns else 'NOT met'}")
                rows.add("swarms", label + ", FKOPT_NUMERICS=numpy", f_ns / c_ns, "x C loop",
                         f"numpy path{'' if fast else ' (the default here: no numba)'}; fkopt {f_ns:.0f} ns/eval, "
                         f"{common}, fkopt {float(np.median(res.fitness)):.2g}; target <= {target:g}: "
                         f"{'met' if f_ns <= target * c_ns else 'NOT met'}")


#: Issue 29: pygmo's bee_colony with a compiled fitness at least this many times fkopt's batched
#: ABC's time per run (population 10, 600 iterations, 30 runs).
PYGMO_TARGET = 10.0


def bench_pygmo_abc(rows: _Rows, quick: bool, messages: list[str]) -> None:
    """pygmo's C++ ``bee_colony`` (gen 600, limit 30 = fkopt's default SN * dim, population 10)
    on mao2017's 3-RPS case with the fitness compiled by numba (the 3-RPS point of
    :func:`fkopt.mechanisms.rps3_kernels.point_fitness`, called once per point as pygmo asks), beside
    fkopt's ABC solving the 30 runs in one batch (``FKOPT_NUMERICS=numpy`` and the compiled default path);
    alternating (fkopt's two paths, then a third of pygmo's runs, three times), in CPU time, best of
    3 for fkopt, pygmo's median run; ratio pygmo / fkopt per run against
    :data:`PYGMO_TARGET`. Quick mode: 100 iterations, 10 pygmo runs. Skipped with a message
    without pygmo or numba."""
    try:
        import pygmo  # noqa: F401
        from fkopt.mechanisms import rps3_kernels
    except Exception as err:                        # pragma: no cover - depends on the machine
        messages.append(f"swarms: pygmo bee_colony row skipped: {err}; pip install 'fkopt[bench,fast]'")
        return
    from fkopt import mechanism
    from fkopt.numerics import path as numerics_path
    from fkopt.solve import solve
    m = mechanism("3-rps")
    problem = mao_problem()
    j0, j1, j2 = (float(v) for v in problem.joints)
    ra, rb = float(m.geometry.ra), float(m.geometry.rb)
    point = rps3_kernels.point_fitness

    def fitness_one(x):                             # numba-compiled; one call per point
        return point(x[0], x[1], x[2], j0, j1, j2, ra, rb, False)
    iterations = 100 if quick else 600
    peer_runs = 10 if quick else 30
    fitness_one(problem.bounds.mean(axis=1))        # compile / load numba's cache before timing
    solve(problem, "abc", population=10, iterations=2, runs=2, seed=1)   # and the compiled ABC's
    best = {"numpy": np.inf, "compiled": np.inf}
    fk = {}
    peer = []
    reps = 3
    load = _load_average()
    for rep in range(reps):                         # fkopt's two paths and a third of pygmo's runs, in turn
        for mode in ("numpy", "compiled"):
            with numerics_path.forced(mode):
                t = time.process_time()
                res = solve(problem, "abc", population=10, iterations=iterations, runs=30, seed=1)
                per_run = (time.process_time() - t) / 30
            if per_run < best[mode]:
                best[mode], fk[mode] = per_run, res
        share = peer_runs // reps + (rep < peer_runs % reps)
        peer += _pygmo_bee_colony(fitness_one, problem.bounds, share, gen=iterations, clock=time.process_time,
                                  first=len(peer))
    p_run = float(np.median([r[0] for r in peer]))
    p_evals = float(np.median([r[1] for r in peer]))
    p_fit = float(np.median([r[2] for r in peer]))
    for mode, label in (("numpy", "FKOPT_NUMERICS=numpy"), ("compiled", "default path (compiled)")):
        ratio = p_run / best[mode]
        res = fk[mode]
        rows.add("swarms", f"pygmo bee_colony (numba fitness) / fkopt abc per run, {label}", ratio, "x",
                 f"pygmo {p_run * 1e3:.2f} ms/run (median of {peer_runs}, {p_evals:.0f} evaluations, median final "
                 f"fitness {p_fit:.2g}); fkopt {best[mode] * 1e3:.3f} ms/run (30 runs in one batch, best of {reps}, "
                 f"{float(res.evaluations.mean()):.0f} evaluations, median final fitness "
                 f"{float(np.median(res.fitness)):.2g}); CPU time, alternating; {load} -> {_load_average()}; "
                 f"{iterations} it, population 10, limit 30; "
                 f"target >= {PYGMO_TARGET:g}: {'met' if ratio >= PYGMO_TARGET else 'NOT met'}")


def bench_scaling(rows: _Rows, quick: bool) -> dict[str, list[tuple[int, float, float]]]:
    from fkopt.solve import solve
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
    from matplotlib.figure import Figure
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


# -- entry point -----------------------------------------------------------------------------
def machine() -> dict[str, str]:
    cpu = platform.processor() or "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"cpus": str(os.cpu_count()), "cpu": cpu, "numpy": np.__version__,
            "python": platform.python_version()}


def _fmt(v: float) -> str:
    if v == 0 or not np.isfinite(v):
        return f"{v:g}"
    if abs(v) >= 1e5 or abs(v) < 1e-3:
        return f"{v:.3e}"
    return f"{v:.4g}"


SECTIONS = ("throughput", "mao2017", "peers", "adapters", "exact", "kinematics", "ik-one-pose", "ik-batch",
            "cases", "swarms", "fksgp", "scaling")


def run(quick: bool = False, peers: bool = False, out="bench", sections=None) -> pd.DataFrame:
    """Run the benchmark; print a table, write ``out/bench.csv`` and ``out/scaling.png``.

    ``sections``: names from :data:`SECTIONS` to run (default all; ``peers`` also needs
    ``peers=True`` or its name here). ``scaling.png`` is written only with the scaling section."""
    want = set(sections or SECTIONS)
    from rich.console import Console
    from rich.table import Table

    console = Console()
    if not console.is_terminal:   # files and pipes: wide enough for the notes
        console = Console(width=200)
    from fkopt.files import inside
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for name in ("bench.csv", "scaling.png"):     # no write through a link, checked before measuring
        inside(out, out / name)
    rng = np.random.default_rng(20240601)
    rows = _Rows()
    messages: list[str] = []
    start = time.perf_counter()

    spent: dict[str, float] = {}                       # seconds per section, printed at the end

    def timed(name, fn, *args):
        from fkopt.bench.ik import load_average
        before = load_average()
        t = time.perf_counter()
        got = fn(*args)
        spent[name] = spent.get(name, 0.0) + time.perf_counter() - t
        after = load_average()
        try:
            value = float(after.split()[0])
        except ValueError:                           # pragma: no cover - no load average here
            value = float("nan")
        rows.add(name, "load average", value, "", f"1/5/15-min load average before the section {before}, after "
                 f"{after} ({os.cpu_count()} CPUs): timings here are wall clock on a shared machine; read the ratios")
        return got

    if "throughput" in want:
        timed("throughput", bench_throughput, rows, quick, rng)
    per_run = timed("mao2017", bench_mao2017, rows, quick) if ("mao2017" in want or "peers" in want) else {}
    if peers and "peers" in want:
        timed("peers", bench_peers, rows, quick, per_run.get("gabc"), messages)
    if (peers or sections) and "adapters" in want:       # opt-in, as peers: needs pymoo/NiaPy
        timed("adapters", bench_adapters, rows, quick, messages)
    if "exact" in want:
        timed("exact", bench_exact, rows, quick, rng)
    if "kinematics" in want:
        timed("kinematics", bench_kinematics, rows, quick, np.random.default_rng(12), messages)
        timed("kinematics", bench_cli_process, rows, quick)
    if "ik-one-pose" in want:
        from fkopt.bench.ik import bench_ik_one_pose
        timed("ik-one-pose", bench_ik_one_pose, rows, quick, messages)
    if "ik-batch" in want:
        from fkopt.bench.ik import bench_ik_batch
        timed("ik-batch", bench_ik_batch, rows, quick, messages)
    if "cases" in want:
        timed("cases", bench_cases, rows, quick, rng, messages)
    if "swarms" in want:
        timed("swarms", bench_swarms, rows, quick, np.random.default_rng(29), messages)
        timed("swarms", bench_pygmo_abc, rows, quick, messages)
    if "fksgp" in want:                                  # skipped with a message without the vendored fkSGP
        from fkopt.bench.fksgp import bench_fksgp
        timed("fksgp", bench_fksgp, rows, quick, messages)
    if "scaling" in want:
        curves = timed("scaling", bench_scaling, rows, quick)
        plot_scaling(curves, out / "scaling.png", 50 if quick else 200)

    df = pd.DataFrame(rows.rows, columns=["section", "item", "value", "unit", "note"])
    df.to_csv(out / "bench.csv", index=False)

    info = machine()
    table = Table(title=f"fkopt bench{' (quick)' if quick else ''}: {info['cpus']} CPUs, {info['cpu']}, "
                        f"numpy {info['numpy']}")
    for col in ("section", "item", "value", "unit", "note"):
        table.add_column(col, justify="right" if col == "value" else "left")
    for r in rows.rows:
        table.add_row(r["section"], r["item"], _fmt(r["value"]), r["unit"], r["note"])
    console.print(table)
    for msg in messages:
        console.print(msg)
    wrote = f"{out / 'bench.csv'}" + (f" and {out / 'scaling.png'}" if "scaling" in want else "")
    per = ", ".join(f"{k} {v:.1f}" for k, v in spent.items())
    console.print(f"total {time.perf_counter() - start:.1f} s ({per}); wrote {wrote}")
    return df
