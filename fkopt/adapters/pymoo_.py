"""pymoo's single-objective algorithms: ``pymoo:GA``, ``pymoo:DE``, ``pymoo:PSO`` (also ``ES``,
``G3PCX``, ``NelderMead``, ``PatternSearch``); optional, ``pip install "fkopt[peers]"``.

The library gets a vectorised ``pymoo.core.problem.Problem`` (whole populations per call) on
fkopt's box, the termination ``("n_eval", budget)`` and the run's integer seed (pymoo 0.6 draws
from its own ``default_rng(seed)``, never numpy's global state). ``pop_size`` is fkopt's
population unless ``params`` give it; every other key of ``params`` goes to the algorithm's
constructor unchanged (``termination``, ``seed`` and ``verbose`` are fkopt's).
"""
from __future__ import annotations

import importlib
import inspect
from functools import lru_cache

import numpy as np

from fkopt.errors import FkoptError
from fkopt.adapters.libraries import ADAPTERS, refuse_unknown, require

RESERVED = {"termination", "seed", "verbose", "save_history", "callback", "display", "output"}


def _table() -> dict[str, str]:
    return ADAPTERS["pymoo"]


def resolve(method: str):
    table = _table()
    if method not in table:
        raise FkoptError(f"unknown pymoo adapter 'pymoo:{method}'; allowed: "
                         + ", ".join(f"pymoo:{m}" for m in table))
    require("pymoo", "pymoo")
    from pymoo.config import Config
    Config.warnings["not_compiled"] = False     # no hint printed into fkopt's output
    module, _, cls = table[method].partition(":")
    return getattr(importlib.import_module(module), cls)


@lru_cache(maxsize=None)
def _accepted(cls) -> frozenset[str]:
    """Keyword names of every ``__init__`` along the MRO (pymoo's base classes swallow unknown
    keywords, so fkopt checks them itself); DE also forwards its ``Variant``'s (F, CR, ...)."""
    names = set()
    for klass in cls.__mro__:
        init = klass.__dict__.get("__init__")
        if init is not None:
            names |= {p for p, v in inspect.signature(init).parameters.items()
                      if v.kind not in (v.VAR_KEYWORD, v.VAR_POSITIONAL)}
    if cls.__name__ == "DE":
        from pymoo.algorithms.soo.nonconvex.de import Variant
        names |= _accepted(Variant)
    return frozenset(names - {"self"})     # cached: asked once per run, inspect is ~1 ms


def check_params(method: str, target, params: dict) -> None:
    refuse_unknown(f"pymoo:{method}", params, _accepted(target), RESERVED)
    size = params.get("pop_size")
    if size is not None and (not isinstance(size, int) or isinstance(size, bool) or size < 1):
        raise FkoptError(f"algorithm 'pymoo:{method}' parameter 'pop_size': {size!r} is not allowed; a whole "
                         "number >= 1")
    small = {**params, "pop_size": min(size, 10)} if size is not None else params
    try:
        target(**_with_pop(target, small, 10))
    except Exception as err:
        raise FkoptError(f"algorithm 'pymoo:{method}' rejected params {params}: {type(err).__name__}: {err}") from None


def library_population(method: str, params: dict, population: int, dim: int) -> int:
    """Points the method holds and evaluates per generation (``pop_size``, default fkopt's)."""
    value = params.get("pop_size", population)
    return int(value) if isinstance(value, int) and not isinstance(value, bool) else population


def _with_pop(cls, params: dict, population: int) -> dict:
    kwargs = dict(params)
    if "pop_size" in _accepted(cls):
        kwargs.setdefault("pop_size", population)
    return kwargs


def run(method, params, counter, problem, population, budget, seed_seq, x0) -> None:
    cls = resolve(method)
    from pymoo.core.problem import Problem
    from pymoo.optimize import minimize

    bounds = np.asarray(problem.bounds, dtype=float)

    class Wrapped(Problem):
        def __init__(self):
            super().__init__(n_var=len(bounds), n_obj=1, xl=bounds[:, 0], xu=bounds[:, 1])

        def _evaluate(self, x, out, *args, **kwargs):
            out["F"] = counter.batch(np.atleast_2d(x))[:, None]

    kwargs = _with_pop(cls, params, population)
    if x0 is not None and "x0" in _accepted(cls) and "x0" not in kwargs:
        kwargs["x0"] = x0
    seed = int(seed_seq.generate_state(1)[0])
    minimize(Wrapped(), cls(**kwargs), termination=("n_eval", budget), seed=seed, verbose=False)
