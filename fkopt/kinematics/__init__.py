"""fkopt's exact solvers, one package (floor 2 of docs/design.md):

* :mod:`.solvers` -- :func:`forward` (FK of parallel mechanisms) and :func:`inverse` /
  :class:`InverseSolver` (IK of serial arms), batched;
* :mod:`.assembly_modes` -- :func:`all_solutions`: every real assembly mode of a parallel mechanism;
* :mod:`.as_algorithms` -- the exact solvers as algorithms (``forward``, ``inverse``, ``exact``) for
  suites and experiments;
* :mod:`.by_algorithm` -- one pose solved by a named algorithm, judged as the exact solvers judge;
* :mod:`.branches` -- every solution of a pose (``inverse(..., solutions="all")``) and IK along a
  path on one branch (:func:`inverse_path`).
"""
from fkopt.errors import FkoptError
from fkopt.kinematics import solvers as _solvers
from fkopt.kinematics.branches import AllSolutions, PathResult, inverse_all, inverse_path
from fkopt.kinematics.solvers import (FORWARD_TOL, INVERSE_TOL, ForwardResult, InverseResult, InverseSolver,
                                      forward, inverse_solver)


def inverse(arm, poses, *, solutions: str = "one", **options):
    """``fkopt.inverse``: one answer per pose, :func:`fkopt.kinematics.solvers.inverse` (its
    keywords and docstring); ``solutions="all"``: every solution of each pose instead
    (:mod:`fkopt.kinematics.branches`: an :class:`AllSolutions` per pose, a list for a batch),
    taking ``tol`` (default 1e-9 m, 1e-9 rad there), ``mask``, ``seed``, ``orientation_scale`` and
    the keywords of :func:`fkopt.kinematics.branches.all_solutions` (``fixed``, ``spread``,
    ``copies``, ``patience``, ...). The dispatch lives here so that the two modules do not import
    each other (branches uses the one-answer solver's helpers)."""
    if solutions == "one":
        return _solvers.inverse(arm, poses, **options)
    if solutions != "all":
        raise FkoptError(f"inverse solutions: expected 'one' or 'all', got {solutions!r}")
    return inverse_all(arm, poses, **options)

__all__ = ["FORWARD_TOL", "INVERSE_TOL", "ForwardResult", "InverseResult", "InverseSolver", "forward", "inverse",
           "inverse_solver", "inverse_path", "AllSolutions", "PathResult"]
