"""fkopt: rerunnable swarm-optimisation experiments for robot mechanism kinematics.

Python API::

    import fkopt
    m = fkopt.mechanism("3-rps")
    joints = m.ik([9, 13, 622])                     # closed-form inverse map (vectorised)
    problem = fkopt.fk_problem(m, joints)           # forward kinematics as a minimisation
    result = fkopt.solve(problem, "gabc", population=10, iterations=600, runs=30, seed=1)
    result.x[result.median_run], result.history     # per-run answers and best-so-far curves
    many = fkopt.fk_problem(m, m.ik([[9, 13, 622], [0, 0, 500]]))    # joints (cases, 3)
    fkopt.solve(many, "gabc", runs=30, seed=[1, 2]).case(1)          # pose 2 as if solved alone

    fk = fkopt.forward("6-sps-cmm", legs)           # exact solvers, batched over leading axes:
    ik = fkopt.inverse("7dof-arm", poses)           # .pose / .joints, .residual, .solved, .evaluations
"""
from __future__ import annotations

import sys
import types

from fkopt.errors import FkoptError

#: Public names loaded on first use (PEP 562), so that ``import fkopt`` -- and ``fkopt fk`` --
#: pay only for what they touch: the optimiser layer imports pydantic, the version
#: importlib.metadata.
_LAZY = {"ForwardResult": "kinematics", "InverseResult": "kinematics", "forward": "kinematics",
         "inverse": "kinematics", "InverseSolver": "kinematics", "inverse_solver": "kinematics",
         "InverseOptions": "numerics", "FKProblem": "problems", "IKProblem": "problems",
         "fk_problem": "problems", "ik_problem": "problems", "Result": "solve", "solve": "solve",
         "MECHANISMS": "registry", "ALGORITHMS": "registry", "SOLVERS": "registry",
         "inverse_path": "kinematics.branches", "AllSolutions": "kinematics.branches",
         "PathResult": "kinematics.branches"}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    if name == "__version__":
        from fkopt.files.host import installed_version
        value = installed_version("fkopt") or "0.0.0+unknown"   # None: running from a source tree
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY) | {"__version__"})


class _Package(types.ModuleType):
    """Importing the submodule ``fkopt.solve`` binds it as the package attribute ``solve``
    (the import system does so after running it); the public ``fkopt.solve`` is the function,
    as when it was imported eagerly."""

    def __setattr__(self, name, value):
        if name == "solve" and isinstance(value, types.ModuleType):
            value = value.solve
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


def mechanism(name: str, **geometry):
    """A registered mechanism with optional geometry overrides (and ``bounds={var: [lo, hi]}``)."""
    from fkopt.registry import mechanism_class    # lazy: the registry imports every built-in class: on first use
    return mechanism_class(name)(**geometry)


def algorithm(name: str, **params):
    """A registered algorithm with validated parameters."""
    from fkopt.registry import algorithm_class     # lazy: the same: on first use
    return algorithm_class(name)(**params)


__all__ = ["FkoptError", "FKProblem", "IKProblem", "Result", "algorithm", "fk_problem", "ik_problem",
           "mechanism", "solve", "forward", "inverse", "inverse_path", "AllSolutions", "PathResult", "InverseSolver", "inverse_solver",
           "InverseOptions", "ForwardResult", "InverseResult",
           "MECHANISMS", "ALGORITHMS", "SOLVERS", "__version__"]
