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

from importlib.metadata import PackageNotFoundError, version as _version

from .errors import FkoptError
from .kinematics import ForwardResult, InverseResult, forward, inverse
from .problems import FKProblem, IKProblem, fk_problem, ik_problem
from .registry import ALGORITHMS, MECHANISMS, algorithm_class, mechanism_class
from .solve import Result, solve

try:
    __version__ = _version("fkopt")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0+unknown"


def mechanism(name: str, **geometry):
    """A registered mechanism with optional geometry overrides (and ``bounds={var: [lo, hi]}``)."""
    return mechanism_class(name)(**geometry)


def algorithm(name: str, **params):
    """A registered algorithm with validated parameters."""
    return algorithm_class(name)(**params)


__all__ = ["FkoptError", "FKProblem", "IKProblem", "Result", "algorithm", "fk_problem", "ik_problem",
           "mechanism", "solve", "forward", "inverse", "ForwardResult", "InverseResult",
           "MECHANISMS", "ALGORITHMS", "__version__"]
