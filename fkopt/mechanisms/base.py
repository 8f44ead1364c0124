"""Base classes of all mechanisms.

A mechanism knows its geometry, its pose and joint variables with their units, the search
bounds of the unknowns, and its closed-form map, vectorised over any leading batch shape:

* a :class:`ParallelMechanism` maps poses to actuator inputs, ``ik(poses[..., n]) -> joints[..., m]``
  (forward kinematics is the hard direction and is solved numerically);
* a :class:`SerialMechanism` maps joints to the end-effector pose, ``fk(joints[..., n]) -> pose[..., 6]``
  (inverse kinematics is the hard direction).

Angles are in degrees at every public interface; lengths in the unit of the source paper
(mm, or m for liu2008). Geometry is a pydantic model per mechanism, so overrides from Python or
YAML are validated with clear messages.
"""
from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationError

from ..errors import FkoptError, did_you_mean


class Geometry(BaseModel):
    """Base of every mechanism's geometry model (unknown keys are rejected)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)   # "1e400" from YAML is inf


def describe_validation_error(err: ValidationError, where: str) -> str:
    """Collapse a pydantic error into one line: ``where.field: message``."""
    first = err.errors()[0]
    loc = ".".join(str(p) for p in first["loc"])
    msg = first["msg"]
    return f"{where}.{loc}: {msg}" if loc else f"{where}: {msg}"


class Mechanism:
    """Common part of parallel and serial mechanisms."""

    name: ClassVar[str]
    kind: ClassVar[str]
    #: Paper key in docs/models.md this mechanism reproduces (``None`` for general ones).
    paper: ClassVar[str | None] = None
    #: Set when the model is a reconstruction (docs/models.md), with a one-sentence explanation.
    reconstruction: ClassVar[str | None] = None
    pose_names: ClassVar[tuple[str, ...]]
    pose_units: ClassVar[tuple[str, ...]]
    joint_names: ClassVar[tuple[str, ...]]
    joint_units: ClassVar[tuple[str, ...]]
    Geometry: ClassVar[type[Geometry]] = Geometry
    #: Default search bounds of the unknowns, name -> (lower, upper).
    default_bounds: ClassVar[dict[str, tuple[float, float]]]

    def __init__(self, bounds: dict[str, Any] | None = None, **geometry: Any):
        try:
            self.geometry = self.Geometry(**geometry)
        except ValidationError as err:
            allowed = did_you_mean("", self.Geometry.model_fields)
            raise FkoptError(describe_validation_error(err, f"{self.name} geometry")
                             + f" (geometry keys: {allowed})") from None
        self.bounds = self._make_bounds(bounds or {})

    # -- variables ---------------------------------------------------------------------------
    @property
    def unknown_names(self) -> tuple[str, ...]:
        """Names of the variables a solver searches (pose for parallel, joints for serial)."""
        raise NotImplementedError

    @property
    def unknown_units(self) -> tuple[str, ...]:
        raise NotImplementedError

    def _make_bounds(self, overrides: dict[str, Any]) -> np.ndarray:
        names = self.unknown_names
        bounds = dict(self.default_bounds)
        for key, value in overrides.items():
            if key not in names:
                raise FkoptError(f"{self.name} bounds: unknown variable '{key}'; "
                                 f"allowed: {', '.join(names)}")
            try:
                lo, hi = (float(v) for v in value)
            except (TypeError, ValueError):
                raise FkoptError(f"{self.name} bounds.{key}: expected [lower, upper], got {value!r}") from None
            bounds[key] = (lo, hi)
        out = np.array([bounds[n] for n in names], dtype=float)
        for n, (lo, hi) in zip(names, out):
            if not lo < hi:
                raise FkoptError(f"{self.name} bounds.{n}: lower {lo:g} must be below upper {hi:g}")
        return out

    def in_bounds(self, x, tol: float = 1e-9) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        return np.all((x >= lo - tol) & (x <= hi + tol), axis=-1)

    def vector(self, values: dict[str, float], names: tuple[str, ...], what: str) -> np.ndarray:
        """Turn ``{"alpha": 9, ...}`` into an array ordered like ``names`` (all keys required)."""
        unknown = set(values) - set(names)
        missing = [n for n in names if n not in values]
        if unknown:
            raise FkoptError(f"{self.name} {what}: unknown variable '{sorted(unknown)[0]}'; "
                             f"allowed: {', '.join(names)}")
        if missing:
            raise FkoptError(f"{self.name} {what}: missing {', '.join(missing)} "
                             f"(needs {', '.join(names)})")
        return np.array([float(values[n]) for n in names])

    def as_values(self, values, names: tuple[str, ...], what: str) -> np.ndarray:
        """Measured joints or a target pose, given by name (dict) or in order (sequence), as a
        finite float vector of ``len(names)`` values; anything else is a one-line error."""
        if isinstance(values, dict):
            values = self.vector(values, names, what)
        values = np.asarray(values, dtype=float)
        if values.shape != (len(names),):
            raise FkoptError(f"{self.name} {what}: expected {len(names)} values "
                             f"({', '.join(names)}), got shape {values.shape}")
        if not np.all(np.isfinite(values)):
            raise FkoptError(f"{self.name} {what}: values must be finite, got {values.tolist()}")
        return values

    def angle_mask(self, units: tuple[str, ...]) -> np.ndarray:
        return np.array([u == "deg" for u in units])

    def describe(self) -> dict[str, Any]:
        return {
            "name": self.name, "kind": self.kind, "paper": self.paper,
            "reconstruction": self.reconstruction,
            "pose": dict(zip(self.pose_names, self.pose_units)),
            "joints": dict(zip(self.joint_names, self.joint_units)),
            "bounds": {n: list(b) for n, b in zip(self.unknown_names, self.bounds.tolist())},
            "geometry": self.geometry.model_dump(),
        }


class ParallelMechanism(Mechanism):
    """Closed form is the inverse map pose -> actuator inputs; FK is solved numerically."""

    kind = "parallel"

    @property
    def unknown_names(self):
        return self.pose_names

    @property
    def unknown_units(self):
        return self.pose_units

    def ik(self, poses) -> np.ndarray:
        """Actuator inputs for poses shaped (..., len(pose_names)) -> (..., len(joint_names))."""
        raise NotImplementedError

    # Mechanisms with an analytic Jacobian define ``jacobian(poses) -> (..., m, n)``:
    # d(actuator inputs)/d(pose) in the public units (per degree for angles).

    def ik_jacobian(self, poses) -> tuple[np.ndarray, np.ndarray]:
        """``(ik(poses), jacobian(poses))``; mechanisms may compute both in one pass."""
        return self.ik(poses), self.jacobian(poses)


class SerialMechanism(Mechanism):
    """Closed form is the forward map joints -> pose; IK is solved numerically."""

    kind = "serial"

    @property
    def unknown_names(self):
        return self.joint_names

    @property
    def unknown_units(self):
        return self.joint_units

    def fk(self, joints) -> np.ndarray:
        """End-effector pose for joints shaped (..., len(joint_names)) -> (..., len(pose_names))."""
        raise NotImplementedError
