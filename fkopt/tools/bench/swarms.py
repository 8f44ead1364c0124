"""Section ``swarms`` of ``fkopt bench``: GABC, ABC and PSO on 3-RPS at 1 case and 100 cases x 30
runs beside the same algorithm as the C loop of :mod:`fkopt.tools.bench.c_reference`, alternating, in
CPU time: the ratio per evaluation (issue 38's targets: :data:`SWARM_TARGETS`), for the
default path (the iterations compiled, the numpy path's bits) and ``FKOPT_NUMERICS=numpy``; and
pygmo's C++ ``bee_colony`` with a numba-compiled fitness beside fkopt's batched ABC (population
10, 600 iterations, 30 runs), the ratio per run (target >= 10; the row needs pygmo and numba,
imported inside :func:`bench_pygmo_abc` as optional packages)."""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

import fkopt
from fkopt.tools.bench.c_reference import compile_reference, run_reference
from fkopt.tools.bench.measuring import Rows, load_average, mao_problem, uniform
from fkopt.tools.bench.peer_abc import pygmo_bee_colony
from fkopt.numerics import path as numerics_path
from fkopt.problems import fk_problem
from fkopt.solve import make_algorithm, solve

#: Section ``swarms``: issue 38's targets, fkopt / C loop per evaluation at 1 case and 100 cases
#: (issue 29's were 3 and 1.5).
SWARM_TARGETS = {1: 1.5, 100: 1.2}


def bench_swarms(rows: Rows, quick: bool, rng, messages: list[str]) -> None:
    """GABC, ABC and PSO on 3-RPS (population 10, 600 iterations; 100 in quick mode; 30 runs) at
    1 case and at 100 cases, beside the same algorithm as the plain C loop of
    :data:`fkopt.tools.bench.c_reference.REFERENCE_C` on the same cases; alternating fkopt solve on the
    default path, on ``FKOPT_NUMERICS=numpy`` and the C run, in CPU time (this process's, and the C program's own:
    what a shared machine disturbs least; both on one core), best of 5 at 1 case and of 2 at 100
    (1 in quick mode), the load average in every note. Rows: the ratio fkopt / C per evaluation,
    against :data:`SWARM_TARGETS`, for the default path (with numba: ABC and GABC run many
    iterations per compiled call, numpy's own np.tan loop called from compiled code,
    :func:`fkopt.algorithms.abc_kernels.abc_iterations`; PSO one compiled iteration per call around
    np.tan, ``pso_iteration``; the numpy path's bits, checked here run for run) and the numpy path.
    Both sides count the same evaluations (initial colony, 2 SN per iteration, one per scout; PSO
    the swarm per iteration) and draw the same number of PCG64 values; fkopt's time is its whole
    ``solve`` (set-up, evaluation log, records), the C loop's its solves only. Skipped with a
    message when there is no C compiler."""
    m = fkopt.mechanism("3-rps")
    iterations = 100 if quick else 600
    joints = m.ik(uniform(m.bounds, (100,), rng))
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
                load = f"load {load_average()}"
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
                          f"{reps}; {load} -> {load_average()}; median final fitness C {ref['median']:.2g}")
                if fast:
                    with numerics_path.forced("auto"):
                        several = make_algorithm(alg).compiled_advance(problem) is not None
                    same = all(np.array_equal(getattr(res, k), getattr(rk, k)) for k in ("x", "fitness", "history"))
                    rows.add("swarms", label, k_ns / c_ns, "x C loop",
                             f"default path (compiled, numpy's np.tan: "
                             f"{'many iterations per call' if several else 'one iteration per call'}); "
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


def bench_pygmo_abc(rows: Rows, quick: bool, messages: list[str]) -> None:
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
        from fkopt.mechanisms import rps3_kernels      # lazy: its kernels import numba, which may not load
    except Exception as err:                        # pragma: no cover - depends on the machine
        messages.append(f"swarms: pygmo bee_colony row skipped: {err}; pip install 'fkopt[bench,fast]'")
        return
    m = fkopt.mechanism("3-rps")
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
    load = f"load {load_average()}"
    for rep in range(reps):                         # fkopt's two paths and a third of pygmo's runs, in turn
        for mode in ("numpy", "compiled"):
            with numerics_path.forced(mode):
                t = time.process_time()
                res = solve(problem, "abc", population=10, iterations=iterations, runs=30, seed=1)
                per_run = (time.process_time() - t) / 30
            if per_run < best[mode]:
                best[mode], fk[mode] = per_run, res
        share = peer_runs // reps + (rep < peer_runs % reps)
        peer += pygmo_bee_colony(fitness_one, problem.bounds, share, gen=iterations, clock=time.process_time,
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
                 f"{float(np.median(res.fitness)):.2g}); CPU time, alternating; {load} -> {load_average()}; "
                 f"{iterations} it, population 10, limit 30; "
                 f"target >= {PYGMO_TARGET:g}: {'met' if ratio >= PYGMO_TARGET else 'NOT met'}")

