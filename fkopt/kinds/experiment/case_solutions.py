"""Every solution of each case: an experiment's exact-solver entries with ``params: {solutions: all}``.

Such an entry (``inverse`` or ``exact`` on a serial arm, ``forward`` or ``exact`` on a parallel
mechanism; :class:`fkopt.kinematics.as_algorithms.ExactSolver`) is no optimiser: it does not run
``runs`` times, it searches every solution of each case's pose once
(:meth:`~fkopt.kinematics.as_algorithms.ExactSolver.solution_set`: ``fkopt.inverse(arm, pose,
solutions="all")`` or the assembly-mode search), seeded with the case's task seed
(:func:`fkopt.run.solving.task_seed`, the seed an algorithm's runs of that case get), so its sets
are those of the library called with that seed. It is one task of the experiment's plan like an
algorithm (same task id, task file and ``--resume``); its record holds each case's set and the
search's wall time; the merge keeps the sets in :attr:`ExperimentOwn.sets` and
``solutions.csv`` writes them (:func:`fkopt.kinds.experiment.reports.solutions_table`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from fkopt.kinematics.as_algorithms import SolutionSet
from fkopt.progress import tick
from fkopt.run.config_base import AlgorithmSpec
from fkopt.run.result import dataclass_from_json, dataclass_to_json
from fkopt.run.solving import task_seed
from fkopt.solve import make_algorithm


@dataclass
class CaseSet:
    """One entry's solution set of one case (``case`` is the runner's ``Case``)."""

    case: object
    spec: AlgorithmSpec
    seed: int
    found: SolutionSet
    wall_s: float          # the search's wall time (timing.csv; never in solutions.csv)


def wants_every_solution(spec: AlgorithmSpec) -> bool:
    """Is this entry a search of every solution (its algorithm built from its params says so)?"""
    return bool(getattr(make_algorithm(spec.name, spec.params), "every_solution", False))


def search_cases(config, mech, cases: list, a: int, fp: str) -> dict:
    """The task of entry ``a``: every case's set, JSON-able (a task file)."""
    spec = config.algorithms[a]
    solver = make_algorithm(spec.name, spec.params)
    solver.prepare_solution_set(mech)          # compiled code and start tables loaded outside the timed searches
    sets = []
    for i, case in enumerate(cases):
        seed = task_seed(config.seed, case.index, spec.key)
        start = time.perf_counter()
        found = solver.solution_set(mech, case.inputs, seed)
        sets.append({"seed": seed, "found": dataclass_to_json(found), "wall_s": time.perf_counter() - start})
        tick(i + 1, len(cases))
    return {"fingerprint": fp, "algorithm": a, "solver": spec.key, "sets": sets,
            "wall_s": sum(s["wall_s"] for s in sets) / len(cases)}


def set_record_problem(task, rec: dict, config, cases: list) -> str | None:
    """Why ``rec`` (read back by ``--resume``) is not entry ``task``'s finished record: one set
    per case with the case's seed, values (k, n) and per-solution columns of length k, finite
    non-negative times."""
    a = task.payload["algorithm"]
    spec = config.algorithms[a]
    if rec["algorithm"] != a or rec["solver"] != spec.key or isinstance(rec["algorithm"], bool):
        return "its algorithm is not the one its file name names"
    sets = rec["sets"]
    if not isinstance(sets, list) or len(sets) != len(cases):
        return f"sets: not one solution set per case ({len(cases)})"
    for i, (item, case) in enumerate(zip(sets, cases)):
        if item["seed"] != task_seed(config.seed, case.index, spec.key):
            return f"sets[{i}].seed: not this case's seed"
        found = dataclass_from_json(SolutionSet, item["found"])
        k = len(found.values)
        if np.shape(found.values) != (k, len(found.names)) or not isinstance(found.search, dict) \
                or any(np.shape(v) != (k,) for v in found.per_solution.values()):
            return f"sets[{i}].found: not {len(found.names)} values and one entry per column for each solution"
        if not (isinstance(item["wall_s"], (int, float)) and math.isfinite(item["wall_s"]) and item["wall_s"] >= 0):
            return f"sets[{i}].wall_s: not a non-negative finite number"
    return None


def merge_sets(config, cases: list, rec: dict) -> list[CaseSet]:
    """Entry ``rec["algorithm"]``'s sets, one per case."""
    spec = config.algorithms[rec["algorithm"]]
    return [CaseSet(case, spec, int(item["seed"]), dataclass_from_json(SolutionSet, item["found"]),
                    float(item["wall_s"])) for case, item in zip(cases, rec["sets"])]
