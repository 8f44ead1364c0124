"""The libraries behind the ``scipy:``, ``pymoo:`` and ``niapy:`` adapters: names, distributions,
optional imports. Shared by :mod:`fkopt.adapters` and the per-library modules (no import loops)."""
from __future__ import annotations

from importlib import import_module

from fkopt.errors import FkoptError
from fkopt.files.host import installed_version

#: Names listed by ``fkopt list`` (niapy accepts any algorithm class of niapy.algorithms).
ADAPTERS: dict[str, dict[str, str]] = {
    "scipy": {"differential_evolution": "scipy.optimize:differential_evolution",
              "dual_annealing": "scipy.optimize:dual_annealing"},
    "pymoo": {"GA": "pymoo.algorithms.soo.nonconvex.ga:GA",
              "DE": "pymoo.algorithms.soo.nonconvex.de:DE",
              "PSO": "pymoo.algorithms.soo.nonconvex.pso:PSO",
              "ES": "pymoo.algorithms.soo.nonconvex.es:ES",
              "G3PCX": "pymoo.algorithms.soo.nonconvex.g3pcx:G3PCX",
              "NelderMead": "pymoo.algorithms.soo.nonconvex.nelder:NelderMead",
              "PatternSearch": "pymoo.algorithms.soo.nonconvex.pattern:PatternSearch"},
    "niapy": {"<ClassName>": "niapy.algorithms.{basic,modified,other}:<ClassName>"},
}

#: pip distribution of each library (for versions and install hints).
DISTRIBUTIONS = {"scipy": "scipy", "pymoo": "pymoo", "niapy": "niapy"}


def ceil_div(a: int, b: int) -> int:
    return -(-int(a) // int(b))


def library_version(library: str) -> str:
    return installed_version(DISTRIBUTIONS[library]) or "not installed"


def require(library: str, module: str):
    """Import an optional library or fail with the install hint."""
    try:
        return import_module(module)
    except ImportError as err:
        raise FkoptError(f"'{library}:' algorithms need {library} ({err.name or module} is not installed): "
                         f'pip install "fkopt[peers]"') from None


def refuse_unknown(name: str, params: dict, accepted, reserved) -> None:
    """One line for a ``params:`` key that the library does not take, or that fkopt sets itself
    (budget, seed, processes): the same check for every adapter."""
    allowed = sorted(set(accepted) - set(reserved))
    for key in params:
        if key in reserved or key not in allowed:
            what = (f"parameter '{key}' is set by fkopt (budget, seed, processes)" if key in reserved
                    else f"has no parameter '{key}'")
            raise FkoptError(f"algorithm '{name}' {what}; parameters: evaluations, workers, " + ", ".join(allowed))
