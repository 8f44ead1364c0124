"""scipy.optimize's global optimisers (core install): ``scipy:differential_evolution``,
``scipy:dual_annealing``.

* ``differential_evolution`` gets the whole population at once (``vectorized=True``,
  ``updating="deferred"``); its population is ``popsize * dim`` points (scipy's rule), and
  fkopt sets ``popsize = ceil(population / dim)`` unless ``params`` give it. ``maxiter`` is
  set high enough for the budget to end the run (scipy's ``tol`` may end it earlier;
  ``polish``'s L-BFGS-B evaluations are counted like any other).
* ``dual_annealing`` evaluates one point at a time; ``maxfun`` is set to the budget (scipy
  treats it as approximate, fkopt's wrapper makes it exact).

Keys fkopt controls (``func``, ``bounds``, ``rng``/``seed``, ``workers``, ``callback``,
``vectorized``, ``maxfun``) are refused in ``params``; every other keyword of the function
passes through unchanged.
"""
from __future__ import annotations

import inspect

import numpy as np

from fkopt.errors import FkoptError
from fkopt.adapters.libraries import ceil_div, refuse_unknown

METHODS = ("differential_evolution", "dual_annealing")
RESERVED = {"func", "bounds", "rng", "seed", "workers", "callback", "vectorized", "maxfun", "args"}


def resolve(method: str):
    if method not in METHODS:
        raise FkoptError(f"unknown scipy adapter 'scipy:{method}'; allowed: "
                         + ", ".join(f"scipy:{m}" for m in METHODS))
    import scipy.optimize
    return getattr(scipy.optimize, method)


#: Documented ranges of scipy's numeric options, checked before any run (scipy checks some of
#: them only once a run has started, others never: dual_annealing with ``maxiter: -1`` runs
#: forever). name -> (lower, upper, lower open, upper open, whole number); None: unbounded.
RANGES = {
    "differential_evolution": {"maxiter": (1, None, False, False, True), "popsize": (1, None, False, False, True),
                               "recombination": (0, 1, False, False, False), "tol": (0, None, False, False, False),
                               "atol": (0, None, False, False, False)},
    "dual_annealing": {"maxiter": (1, None, False, False, True), "initial_temp": (0.01, 5e4, True, False, False),
                       "restart_temp_ratio": (0, 1, True, True, False), "visit": (1, 3, True, False, False),
                       "accept": (-1e4, -5, False, False, False)},
}


def _check_range(name: str, key: str, value, rule) -> None:
    lo, hi, lo_open, hi_open, whole = rule
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and value == value
    if ok and whole:
        ok = float(value).is_integer()
    if ok and lo is not None:
        ok = value > lo if lo_open else value >= lo
    if ok and hi is not None:
        ok = value < hi if hi_open else value <= hi
    if not ok:
        span = f"{'(' if lo_open else '['}{lo if lo is not None else '-inf'}, {hi if hi is not None else 'inf'}" \
               f"{')' if hi_open or hi is None else ']'}"
        raise FkoptError(f"algorithm '{name}' parameter '{key}': {value!r} is not allowed; "
                         f"{'a whole number ' if whole else 'a number '}in {span}")


def check_params(method: str, target, params: dict) -> None:
    name = f"scipy:{method}"
    refuse_unknown(name, params, inspect.signature(target).parameters, RESERVED)
    for key, rule in RANGES.get(method, {}).items():
        if key in params:
            _check_range(name, key, params[key], rule)


def probe_params(method: str, params: dict) -> dict | None:
    """Parameters for a probe run that lets scipy check the options fkopt does not know
    (:meth:`fkopt.adapters.base.ExternalAlgorithm.probe`); None: no probe (dual_annealing
    checks nothing before it evaluates)."""
    if method != "differential_evolution":
        return None
    small = dict(params)
    if "popsize" in small:
        small["popsize"] = min(int(small["popsize"]), 5)
    return small


def library_population(method: str, params: dict, population: int, dim: int) -> int:
    """Points the method holds and evaluates per generation."""
    if method == "differential_evolution":
        return int(params.get("popsize", max(1, ceil_div(population, dim)))) * dim
    return 1


def _rng_kwargs(fn, seed_seq) -> dict:
    gen = np.random.Generator(np.random.PCG64(seed_seq))
    return {"rng": gen} if "rng" in inspect.signature(fn).parameters else {"seed": gen}


def run(method, params, counter, problem, population, budget, seed_seq, x0) -> None:
    fn = resolve(method)
    bounds = [tuple(b) for b in np.asarray(problem.bounds, dtype=float)]
    dim = len(bounds)
    kwargs = dict(params)
    kwargs.update(_rng_kwargs(fn, seed_seq))
    if x0 is not None and "x0" not in kwargs:
        kwargs["x0"] = np.clip(x0, problem.bounds[:, 0], problem.bounds[:, 1])
    if method == "differential_evolution":
        kwargs.setdefault("popsize", max(1, ceil_div(population, dim)))
        vector = kwargs.get("updating", "deferred") == "deferred"
        if vector:
            kwargs["updating"] = "deferred"
            kwargs["vectorized"] = True
        size = kwargs["popsize"] * dim
        kwargs.setdefault("maxiter", ceil_div(budget, max(size, 1)) + 1)

        def func(x):
            x = np.asarray(x, dtype=float)
            if x.ndim == 1:                       # polishing and x0 evaluate single points
                return counter.point(x)
            return counter.batch(x.T)             # vectorized: x is (dim, S)
        fn(func, bounds, **kwargs)
    else:
        kwargs["maxfun"] = budget
        fn(counter.point, bounds, **kwargs)
