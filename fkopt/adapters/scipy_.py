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

from ..errors import FkoptError
from .libraries import ceil_div, refuse_unknown

METHODS = ("differential_evolution", "dual_annealing")
RESERVED = {"func", "bounds", "rng", "seed", "workers", "callback", "vectorized", "maxfun", "args"}


def resolve(method: str):
    if method not in METHODS:
        raise FkoptError(f"unknown scipy adapter 'scipy:{method}'; allowed: "
                         + ", ".join(f"scipy:{m}" for m in METHODS))
    import scipy.optimize
    return getattr(scipy.optimize, method)


def check_params(method: str, target, params: dict) -> None:
    refuse_unknown(f"scipy:{method}", params, inspect.signature(target).parameters, RESERVED)


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
