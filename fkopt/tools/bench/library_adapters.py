"""Section ``adapters`` of ``fkopt bench`` (``peers=True`` or named): ``scipy:differential_evolution``,
``pymoo:DE`` and ``niapy:DifferentialEvolution`` through fkopt's adapters beside fkopt's gabc, abc
and examples/plugin's DE, on kinbench's problems and settings (population 20, 2000 x dimension,
stop below 1e-10), alternating in one process: ms per solve, µs per evaluation, ratios to scipy's
DE (:func:`bench_adapters`). Solvers whose library is missing are skipped."""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

import fkopt
from fkopt.tools.bench.measuring import Rows, uniform
from fkopt.errors import FkoptError
from fkopt.problems import fk_problem, ik_problem
from fkopt.solve import make_algorithm, solve


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
    rng = np.random.default_rng(2026)
    poses = 2 if quick else 4
    out = []
    for name, mech, geometry, objective in ADAPTER_PROBLEMS[:3 if quick else None]:
        m = fkopt.mechanism(mech, **geometry)
        x = uniform(m.bounds, (poses,), rng)
        kw = {"objective": objective} if objective else {}
        out.append((name, fk_problem(m, m.ik(x), **kw) if m.kind == "parallel" else ik_problem(m, m.fk(x), **kw),
                    len(m.bounds)))
    return out


def bench_adapters(rows: Rows, quick: bool, messages: list[str]) -> None:
    """scipy's, pymoo's and NiaPy's DE through fkopt's adapters, beside fkopt's own gabc, abc and
    examples/plugin's DE, on kinbench's problems with kinbench's settings (population 20, budget
    2000 x dimension, stop below 1e-10), in this process, alternating solvers within each
    repetition (best of 2; 1 in quick mode). Per problem and solver: ms per solve (one pose x
    run), evaluations per solve, µs per evaluation, and the ratios to scipy's DE; per solver, the
    same over all problems (total time / total solves)."""
    plugin = Path(__file__).resolve().parents[3] / "examples" / "plugin"     # the source tree's examples/
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
