"""NiaPy's algorithms by class name: ``niapy:ArtificialBeeColonyAlgorithm``, ``niapy:ParticleSwarmAlgorithm``,
... any class of ``niapy.algorithms.basic``, ``.modified`` or ``.other``; optional,
``pip install "fkopt[peers]"``.

NiaPy evaluates one point at a time (``Problem._evaluate(x)``), so a run costs a Python call
per evaluation. fkopt runs the runs of a solve in lockstep threads
(:func:`fkopt.adapters.base.run_lockstep`): the points the runs ask for at the same time are
evaluated in one batched fitness call, and each run gets exactly the value it would get alone
(``workers: N`` runs them in N processes instead, one point per call). The task gets
``max_evals = budget`` (NiaPy returns ``inf`` without evaluating past it; fkopt's wrapper ends
the run there). ``population_size`` is fkopt's population unless ``params`` give it; ``seed`` is
fkopt's; every other key must be a parameter of the class's ``set_parameters`` (NiaPy itself
ignores unknown keywords, fkopt refuses them).
"""
from __future__ import annotations

import importlib
import inspect

import numpy as np

from fkopt.errors import FkoptError
from fkopt.adapters.libraries import refuse_unknown, require

MODULES = ("niapy.algorithms.basic", "niapy.algorithms.modified", "niapy.algorithms.other")
RESERVED = {"seed", "callbacks", "individual_type", "initialization_function"}


def resolve(method: str):
    require("niapy", "niapy")
    from niapy.algorithms import Algorithm
    names = set()
    for mod in MODULES:
        m = importlib.import_module(mod)
        names |= set(getattr(m, "__all__", ()))
        obj = getattr(m, method, None)
        if method in getattr(m, "__all__", ()) and isinstance(obj, type) and issubclass(obj, Algorithm):
            return obj
    raise FkoptError(f"unknown NiaPy algorithm 'niapy:{method}'; allowed: niapy:" + ", niapy:".join(sorted(names)))


def _accepted(cls) -> set[str]:
    names = set()
    for fn in (cls.set_parameters, cls.__init__):
        names |= {p for p, v in inspect.signature(fn).parameters.items()
                  if v.kind not in (v.VAR_KEYWORD, v.VAR_POSITIONAL)}
    return names - {"self"}


def check_params(method: str, target, params: dict) -> None:
    refuse_unknown(f"niapy:{method}", params, _accepted(target), RESERVED)


def library_population(method: str, params: dict, population: int, dim: int) -> int:
    """Points the method holds (``population_size``, default fkopt's population)."""
    value = params.get("population_size", population)
    return int(value) if isinstance(value, int) and not isinstance(value, bool) else population


def run(method, params, counter, problem, population, budget, seed_seq, x0) -> None:
    cls = resolve(method)
    from niapy.problems import Problem
    from niapy.task import Task

    bounds = np.asarray(problem.bounds, dtype=float)

    class Wrapped(Problem):
        def __init__(self):
            super().__init__(dimension=len(bounds), lower=bounds[:, 0], upper=bounds[:, 1])

        def _evaluate(self, x):
            return counter.point(x)

    kwargs = dict(params)
    kwargs.setdefault("population_size", population)
    algo = cls(seed=int(seed_seq.generate_state(1)[0]), **kwargs)
    algo.run(Task(problem=Wrapped(), max_evals=budget))
    if algo.exception is not None:    # NiaPy keeps exceptions raised outside the main process/thread
        raise algo.exception
