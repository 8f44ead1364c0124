"""Problems: a mechanism paired with what was measured, as a bounded minimisation.

A problem exposes ``dim``, ``bounds`` (dim, 2), ``variable_names``, ``residuals(x[..., dim])``
and ``fitness(x[..., dim]) -> [...]``, all vectorised over any leading batch shape, and knows
nothing of algorithms. Algorithms see only this interface.
"""
from __future__ import annotations

from typing import Literal

import numpy as np

from .errors import FkoptError
from .mechanisms.base import Mechanism, ParallelMechanism
from .rotations import wrap_degrees

#: Objectives built from residuals r: "squared" = sum r_i^2 (mao2017 eq. 12, wu2015, chang2024),
#: "absolute" = sum |r_i| (liu2008 as printed).
OBJECTIVES = ("squared", "absolute")


class Problem:
    """Bounded minimisation of ``fitness`` over ``dim`` variables."""

    variable_names: tuple[str, ...]
    variable_units: tuple[str, ...]
    bounds: np.ndarray

    @property
    def dim(self) -> int:
        return len(self.variable_names)

    def fitness(self, x) -> np.ndarray:
        raise NotImplementedError

    def residuals(self, x) -> np.ndarray:
        raise NotImplementedError


class FKProblem(Problem):
    """Forward kinematics of a parallel mechanism: find the pose whose inverse map gives ``joints``.

    Residuals are ``ik(x) - joints`` (angle-valued joints wrapped to [-180, 180) degrees);
    fitness is their sum of squares (default) or of absolute values.
    """

    def __init__(self, mechanism: Mechanism, joints, *, objective: Literal["squared", "absolute"] = "squared",
                 bounds=None):
        if not isinstance(mechanism, ParallelMechanism):
            raise FkoptError(f"fk_problem needs a parallel mechanism; '{mechanism.name}' is {mechanism.kind} "
                             "(use ik_problem for a serial arm)")
        if isinstance(joints, dict):
            joints = mechanism.vector(joints, mechanism.joint_names, "joints")
        joints = np.asarray(joints, dtype=float)
        if joints.shape != (len(mechanism.joint_names),):
            raise FkoptError(f"{mechanism.name} joints: expected {len(mechanism.joint_names)} values "
                             f"({', '.join(mechanism.joint_names)}), got shape {joints.shape}")
        if not np.all(np.isfinite(joints)):
            raise FkoptError(f"{mechanism.name} joints: values must be finite, got {joints.tolist()}")
        if objective not in OBJECTIVES:
            raise FkoptError(f"objective '{objective}' unknown; allowed: {', '.join(OBJECTIVES)}")
        self.mechanism = mechanism
        self.joints = joints
        self.objective = objective
        self.variable_names = mechanism.pose_names
        self.variable_units = mechanism.pose_units
        self.bounds = mechanism.bounds if bounds is None else np.asarray(bounds, dtype=float)
        self._angle = mechanism.angle_mask(mechanism.joint_units)

    def residuals(self, x) -> np.ndarray:
        r = self.mechanism.ik(x) - self.joints
        if self._angle.any():
            r = np.where(self._angle, wrap_degrees(r), r)
        return r

    def fitness(self, x) -> np.ndarray:
        r = self.residuals(x)
        if self.objective == "absolute":
            return np.abs(r).sum(axis=-1)
        return (r * r).sum(axis=-1)


def fk_problem(mechanism: Mechanism, joints, **kwargs) -> FKProblem:
    """Pair a parallel mechanism with measured joint values (dict by name or array)."""
    return FKProblem(mechanism, joints, **kwargs)
