"""Other libraries' optimisers as fkopt algorithms: ``scipy:``, ``pymoo:`` and ``niapy:`` names.

An experiment names them like any algorithm, with ``params:`` passed through to the library::

    algorithms:
      - {name: "scipy:differential_evolution", params: {mutation: [0.5, 1.0]}}
      - {name: "pymoo:DE", params: {CR: 0.9}}
      - {name: "niapy:ArtificialBeeColonyAlgorithm", params: {limit: 100}}

* ``scipy:differential_evolution`` and ``scipy:dual_annealing`` need nothing beyond fkopt's
  core install;
* ``pymoo:GA``, ``pymoo:DE``, ``pymoo:PSO`` (also ``ES``, ``G3PCX``, ``NelderMead``,
  ``PatternSearch``) need pymoo, ``niapy:<any class of niapy.algorithms>`` needs NiaPy:
  ``pip install "fkopt[peers]"``.

The adapter (:class:`fkopt.adapters.base.ExternalAlgorithm`) is an :class:`~fkopt.algorithms.Algorithm`
whose ``minimize`` hands the library a counting wrapper of ``problem.fitness`` and returns the
same :class:`~fkopt.algorithms.base.RunRecord` as fkopt's own algorithms, so the results land in
the same CSVs and figures. What the wrapper guarantees for every library, and how evaluations
map onto fkopt's iteration axis, is documented in :mod:`fkopt.adapters.base`.
"""
from __future__ import annotations

from functools import lru_cache

from fkopt.adapters.libraries import ADAPTERS, DISTRIBUTIONS  # noqa: F401  (re-exported)
from fkopt.errors import FkoptError


@lru_cache(maxsize=None)
def adapter_class(library: str, method: str):
    """The :class:`ExternalAlgorithm` subclass running ``library``'s ``method``.

    The library itself is imported here (so a missing optional install fails at validation,
    with the install hint), but no optimiser runs.
    """
    from fkopt.adapters import base      # lazy: its pydantic models: not at every command's start-up (the registry)
    if library not in base.LIBRARY_MODULES:  # pragma: no cover - registry only routes the reserved prefixes here
        raise FkoptError(f"no adapter for '{library}:'")
    target = base.LIBRARY_MODULES[library].resolve(method)   # raises FkoptError for unknown names / missing installs
    return type(f"{library}_{method}", (base.ExternalAlgorithm,),
                {"name": f"{library}:{method}", "library": library, "method": method,
                 "target": target, "per_point": library == "niapy",
                 "__module__": __name__})


__all__ = ["ADAPTERS", "adapter_class"]
