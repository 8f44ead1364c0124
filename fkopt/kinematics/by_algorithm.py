"""One pose solved by a named algorithm (a swarm, a hybrid, lm, ...) instead of the exact
solvers, judged exactly as :func:`fkopt.forward` and :func:`fkopt.inverse` judge their answers.

``fkopt fk --algorithm`` and ``fkopt ik --algorithm`` are these calls: the budget
(:data:`fkopt.kinematics.solvers.FORWARD_SWARM`, :data:`~fkopt.kinematics.solvers.INVERSE_SWARM`) and the
verdict (solved = within the tolerances and the bounds) are the library's, not the command's.
"""
from __future__ import annotations

import numpy as np

from fkopt.kinematics.inputs import _mechanism
from fkopt.kinematics.results import FORWARD_TOL, INVERSE_TOL, ForwardResult, InverseResult
from fkopt.kinematics.solvers import FORWARD_SWARM, INVERSE_SWARM
from fkopt.mechanisms.base import ParallelMechanism, SerialMechanism
from fkopt.problems import fk_problem, ik_problem
from fkopt.solve import solve


def forward_by(mechanism, joints, algorithm: str, *, tol: float = FORWARD_TOL, seed: int = 0,
               budget: dict | None = None) -> ForwardResult:
    """FK of one set of joints (m,) by ``algorithm`` (one run, seed ``seed``, ``budget``
    population/iterations, default :data:`~fkopt.kinematics.solvers.FORWARD_SWARM`); solved when
    max |ik(pose) - joints| <= ``tol`` and the pose is inside the bounds."""
    m = _mechanism(mechanism, ParallelMechanism, "forward")
    problem = fk_problem(m, joints)
    res = solve(problem, algorithm, **(budget or FORWARD_SWARM), runs=1, seed=seed)
    x = res.x[0]
    residual = float(np.max(np.abs(problem.residuals(x))))
    evals = int(res.evaluations[0])
    return ForwardResult(mechanism=m.name, names=tuple(m.pose_names), units=tuple(m.pose_units), pose=x,
                         residual=np.asarray(residual), solved=np.asarray(residual <= tol and bool(m.in_bounds(x))),
                         stage=np.asarray(-1), evaluations={"residual": np.asarray(evals),
                                                            "jacobian": np.asarray(0)}, tol=float(tol))


def inverse_by(mechanism, pose, algorithm: str, *, tol: tuple[float, float] = INVERSE_TOL, seed: int = 0,
               budget: dict | None = None) -> InverseResult:
    """IK of one pose (6,) by ``algorithm`` on the geodesic objective (one run, seed ``seed``,
    ``budget`` default :data:`~fkopt.kinematics.solvers.INVERSE_SWARM`); solved when the position error
    (the arm's length unit) and the geodesic rotation error (rad) are within ``tol``."""
    m = _mechanism(mechanism, SerialMechanism, "inverse")
    problem = ik_problem(m, pose, objective="geodesic")
    res = solve(problem, algorithm, **(budget or INVERSE_SWARM), runs=1, seed=seed)
    q = res.x[0]
    perr = float(problem.position_error(q))
    rerr = float(np.radians(problem.rotation_error(q, "geodesic")))
    return InverseResult(mechanism=m.name, names=tuple(m.joint_names), joints=q, position_error=np.asarray(perr),
                         rotation_error=np.asarray(rerr), residual=np.asarray(max(perr / tol[0], rerr / tol[1])),
                         solved=np.asarray(perr <= tol[0] and rerr <= tol[1] and bool(m.in_bounds(q))),
                         restarts=np.asarray(0), evaluations={"residual": np.asarray(int(res.evaluations[0])),
                                                              "jacobian": np.asarray(0)}, tol=tuple(tol))
