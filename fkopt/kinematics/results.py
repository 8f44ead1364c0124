"""What ``fkopt.forward`` and ``fkopt.inverse`` return: :class:`ForwardResult` and
:class:`InverseResult` (shaped like the input's leading axes; see :mod:`fkopt.kinematics.solvers`)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


#: Default forward tolerance: max |ik(pose) - joints| in the joint units.
FORWARD_TOL = 1e-9

#: Default inverse tolerances: (position in the arm's length unit, orientation in radians).
INVERSE_TOL = (1e-6, 1e-6)


@dataclass
class ForwardResult:
    """Poses found by :func:`forward`, shaped like the input's leading axes.

    ``pose`` (..., n) in the mechanism's pose units (NaN-free: the best point found when not
    solved); ``residual`` (...) max |ik(pose) - joints| in joint units; ``solved`` (...) bool;
    ``stage`` (...) 0 local Newton, 1 deterministic restarts, 2 global search, -1 not solved;
    ``evaluations`` {"residual": (...), "jacobian": (...)} per row (see the module docstring).
    """

    mechanism: str
    names: tuple[str, ...]
    units: tuple[str, ...]
    pose: np.ndarray
    residual: np.ndarray
    solved: np.ndarray
    stage: np.ndarray
    evaluations: dict[str, np.ndarray] = field(default_factory=dict)
    tol: float = FORWARD_TOL

    def as_dict(self, index=()) -> dict:
        """One row (``index`` into the leading axes) as plain Python values."""
        return {"pose": dict(zip(self.names, map(float, self.pose[index]))),
                "residual": float(self.residual[index]), "solved": bool(self.solved[index]),
                "stage": int(self.stage[index]),
                "evaluations": {k: int(v[index]) for k, v in self.evaluations.items()}}


@dataclass
class InverseResult:
    """Joints found by :func:`inverse`, shaped like the input's leading axes.

    ``joints`` (..., n) degrees, always inside the limits; ``position_error`` (...) in the arm's
    length unit and ``rotation_error`` (...) geodesic, radians, of fk(joints) against the target;
    ``residual`` (...) max of the two errors measured in their tolerances' units
    (max(position_error / tol[0], rotation_error / tol[1]) <= 1 means solved);
    ``solved`` (...) bool; ``restarts`` (...) random restarts used;
    ``evaluations`` {"residual": (...), "jacobian": (...)} per row.
    """

    mechanism: str
    names: tuple[str, ...]
    joints: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    residual: np.ndarray
    solved: np.ndarray
    restarts: np.ndarray
    evaluations: dict[str, np.ndarray] = field(default_factory=dict)
    tol: tuple[float, float] = INVERSE_TOL

    def as_dict(self, index=()) -> dict:
        return {"joints": dict(zip(self.names, map(float, self.joints[index]))),
                "position_error": float(self.position_error[index]),
                "rotation_error_rad": float(self.rotation_error[index]),
                "solved": bool(self.solved[index]), "restarts": int(self.restarts[index]),
                "evaluations": {k: int(v[index]) for k, v in self.evaluations.items()}}
