"""fkopt's exact solvers, one package (floor 2 of docs/design.md):

* :mod:`.solvers` -- :func:`forward` (FK of parallel mechanisms) and :func:`inverse` /
  :class:`InverseSolver` (IK of serial arms), batched;
* :mod:`.assembly_modes` -- :func:`all_solutions`: every real assembly mode of a parallel mechanism;
* :mod:`.as_algorithms` -- the exact solvers as algorithms (``forward``, ``inverse``, ``exact``) for
  suites and experiments;
* :mod:`.by_algorithm` -- one pose solved by a named algorithm, judged as the exact solvers judge.
"""
from fkopt.kinematics.solvers import (FORWARD_TOL, INVERSE_TOL, ForwardResult, InverseResult, InverseSolver,
                                      forward, inverse, inverse_solver)

__all__ = ["FORWARD_TOL", "INVERSE_TOL", "ForwardResult", "InverseResult", "InverseSolver", "forward", "inverse",
           "inverse_solver"]
