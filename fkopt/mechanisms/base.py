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

pydantic is imported only when a geometry is validated or inspected: a mechanism built without
overrides keeps no model until ``mechanism.geometry`` is first read (then the model of the
defaults is built, as before), and a mechanism whose own code needs only the default values
reads them from its pydantic-free ``geometry_defaults`` (:meth:`Mechanism.geometry_values`).
``fkopt fk`` / ``fkopt ik`` on a preset thus never import pydantic (its import is a large part
of such a process: ``fkopt bench --section kinematics``).
A mechanism module can build its model class on first use with :class:`lazy_model`; the
``Geometry`` base class itself is built on first import of the name.
"""
from __future__ import annotations

from types import SimpleNamespace
from typing import Any, Callable, ClassVar, NamedTuple

import numpy as np

from fkopt.numerics import rotations
from fkopt.errors import FkoptError, did_you_mean
from fkopt.files import MAX_MAGNITUDE, field_path, no_quoted_numbers
from fkopt.files import did_you_mean as closest


def _geometry_base():
    from pydantic import BaseModel, ConfigDict, field_validator

    class Geometry(BaseModel):
        """Base of every mechanism's geometry model (unknown keys are rejected; every number,
        also inside lists, within |v| <= :data:`fkopt.files.MAX_MAGNITUDE`, 1e9 in the
        geometry's units: past it FK and IK overflow to inf instead of failing)."""

        model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)   # "1e400" from YAML is inf
        _numbers = field_validator("*", mode="before")(no_quoted_numbers)          # ra: "450" is text

        @field_validator("*", mode="after", check_fields=False)
        @classmethod
        def _within_magnitude(cls, value):
            def walk(v):
                if isinstance(v, (int, float)) and not isinstance(v, bool) and abs(v) > MAX_MAGNITUDE:
                    raise ValueError(f"{v:g} is past the bound |value| <= {MAX_MAGNITUDE:g}")
                if isinstance(v, (list, tuple)):
                    for x in v:
                        walk(x)
                elif isinstance(v, dict):
                    for x in v.values():
                        walk(x)
            walk(value)
            return value

    Geometry.__module__ = __name__
    return Geometry


def geometry_base() -> type:
    """``Geometry``, the pydantic base of every geometry model, built on first use (so that
    importing a mechanism module does not import pydantic)."""
    cls = globals().get("Geometry")
    if cls is None:
        cls = globals()["Geometry"] = _geometry_base()
    return cls


def __getattr__(name: str):
    # ``from fkopt.mechanisms.base import Geometry`` builds it on first import.
    if name == "Geometry":
        return geometry_base()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class lazy_model:
    """Class attribute holding a geometry model class built by ``build()`` on first access
    (so that importing the mechanism's module does not import pydantic)."""

    def __init__(self, build: Callable[[], type]):
        self.build = build
        self.cls: type | None = None

    def __get__(self, obj, owner=None) -> type:
        if self.cls is None:
            self.cls = self.build()
        return self.cls


def validate_geometry(model: type, geometry: dict[str, Any], where: str, clean=lambda m: m):
    """``model(**geometry)``, or a one-line :class:`FkoptError` naming ``where``, the field and
    the allowed keys (``clean`` edits the message, e.g. drops pydantic's "Value error, ")."""
    from pydantic import ValidationError
    try:
        return model(**geometry)
    except ValidationError as err:
        allowed = did_you_mean("", model.model_fields)
        raise FkoptError(clean(describe_validation_error(err, f"{where} geometry"))
                         + f" (geometry keys: {allowed})") from None


def describe_validation_error(err, where: str) -> str:
    """Collapse a pydantic error into one line: ``where.field: message``."""
    first = err.errors()[0]
    loc = field_path(first["loc"])
    msg = first["msg"].removeprefix("Value error, ")
    return f"{where}.{loc}: {msg}" if loc else f"{where}: {msg}"


def check_bounds(name: str, names, bounds) -> np.ndarray:
    """Search bounds every solver and figure can use: shape (len(names), 2), finite, lower below
    upper, and a finite width (``[-1e308, 1e308]`` overflows to an infinite width); else one line
    naming the variable. The one check of bounds -- presets, overrides, URDF limits, plug-ins."""
    try:
        b = np.asarray(bounds, dtype=float)
    except (TypeError, ValueError):
        raise FkoptError(f"{name} bounds: expected numbers [lower, upper] per variable") from None
    if b.shape != (len(names), 2):
        raise FkoptError(f"{name} bounds: expected shape ({len(names)}, 2) for {', '.join(names)}, got {b.shape}")
    with np.errstate(over="ignore", invalid="ignore"):
        width = b[:, 1] - b[:, 0]
    for n, (lo, hi), w in zip(names, b, width):
        if not (np.isfinite(lo) and np.isfinite(hi)):
            raise FkoptError(f"{name} bounds.{n}: [{lo:g}, {hi:g}] must be finite numbers")
        if not lo < hi:
            raise FkoptError(f"{name} bounds.{n}: lower {lo:g} must be below upper {hi:g}")
        if not np.isfinite(w) or w > 1e150:
            raise FkoptError(f"{name} bounds.{n}: [{lo:g}, {hi:g}] is too wide (width {w:g}); "
                             "bounds must span at most 1e150")
    return b


class Mechanism:
    """Common part of parallel and serial mechanisms."""

    name: ClassVar[str]
    kind: ClassVar[str]
    #: Paper key in docs/models.md this mechanism reproduces (``None`` for general ones).
    paper: ClassVar[str | None] = None
    #: Set when the model is a reconstruction (docs/models.md), with a one-sentence explanation.
    reconstruction: ClassVar[str | None] = None
    #: True when the fitness path (forward/inverse map, no Jacobian) is elementwise numpy, with no
    #: BLAS call (:mod:`fkopt.run.compare`); False for mechanisms fkopt has not read (plug-ins).
    blas_free_fitness: ClassVar[bool] = False
    pose_names: ClassVar[tuple[str, ...]]
    pose_units: ClassVar[tuple[str, ...]]
    joint_names: ClassVar[tuple[str, ...]]
    joint_units: ClassVar[tuple[str, ...]]
    Geometry: ClassVar[type] = lazy_model(lambda: __getattr__("Geometry"))
    #: The default geometry's values without pydantic (``None``: the mechanism reads
    #: ``self.geometry``, which builds the model); must equal ``Geometry().model_dump()``.
    geometry_defaults: ClassVar[dict[str, Any] | None] = None
    #: Default search bounds of the unknowns, name -> (lower, upper).
    default_bounds: ClassVar[dict[str, tuple[float, float]]]

    def __init__(self, bounds: dict[str, Any] | None = None, **geometry: Any):
        if geometry or self.geometry_defaults is None:
            self.geometry = validate_geometry(self.Geometry, geometry, self.name)
        # else: the model of the defaults is built on first access of ``geometry`` (__getattr__)
        self.bounds = self._make_bounds(bounds or {})

    def __getattr__(self, name: str):
        if name == "geometry":                       # defaults, built on first use
            g = self.__dict__["geometry"] = self.Geometry()
            return g
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def geometry_values(self):
        """The geometry's values by attribute: the model when one was built or given, else
        :attr:`geometry_defaults` (no pydantic)."""
        g = self.__dict__.get("geometry")
        if g is None and self.geometry_defaults is not None:
            return SimpleNamespace(**self.geometry_defaults)
        return self.geometry

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
                raise FkoptError(f"{self.name} bounds: unknown variable '{key}'{closest(key, names)}; "
                                 f"allowed: {', '.join(names)}")
            try:
                if any(isinstance(v, str) for v in value):     # "1" in YAML is text, not a number
                    raise TypeError
                lo, hi = (float(v) for v in value)
            except (TypeError, ValueError):
                raise FkoptError(f"{self.name} bounds.{key}: expected [lower, upper], got {value!r}") from None
            bounds[key] = (lo, hi)
        out = np.array([bounds[n] for n in names], dtype=float)
        check_bounds(self.name, names, out)
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
            word = sorted(unknown)[0]
            raise FkoptError(f"{self.name} {what}: unknown variable '{word}'{closest(word, names)}; "
                             f"allowed: {', '.join(names)}")
        if missing:
            raise FkoptError(f"{self.name} {what}: missing {', '.join(missing)} "
                             f"(needs {', '.join(names)})")
        return self._bounded(np.array([float(values[n]) for n in names]), names, what)

    def _bounded(self, values: np.ndarray, names: tuple[str, ...], what: str) -> np.ndarray:
        """``values`` after checking |v| <= :data:`fkopt.files.MAX_MAGNITUDE` (1e9 in the
        mechanism's units; past it a square overflows in FK, IK or a Jacobian): one line naming
        the variable otherwise."""
        big = np.flatnonzero(np.abs(values) > MAX_MAGNITUDE)
        if big.size:
            i = int(big[0])
            raise FkoptError(f"{self.name} {what}: '{names[i]}' = {values[i]:g} is past the bound |value| <= "
                             f"{MAX_MAGNITUDE:g} (in the mechanism's units)")
        return values

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
        return self._bounded(values, names, what)

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


class CompiledFitness(NamedTuple):
    """A parallel mechanism's FK fitness as the compiled swarm iterations take it
    (:mod:`fkopt.algorithms.pso_kernels`, :mod:`fkopt.algorithms.abc_kernels`; offered by
    ``compiled_swarm_fitness()``, e.g. :meth:`fkopt.mechanisms.rps3.ThreeRPS.compiled_swarm_fitness`),
    in three stages so that numpy's own ufunc runs between compiled code and the iterations keep
    the numpy path's bits: an iteration's kernel writes each candidate pose's ufunc arguments
    (``prepare``), the ufunc runs on the buffer as the numpy fitness calls it (``ufunc``), and the
    next kernel reads each candidate's fitness (``value``). A pose is c of a fitness call over
    poses [s0, s0 + sl); ``prepare`` and ``value`` are numba kernels the iterations inline."""

    prepare: Callable   # njit (x0, x1, x2, arg, c, s0, sl, block): the pose's ufunc arguments into arg
    ufunc: Callable     # (arg, out, segments, block): numpy's ufunc on arg into out, per (s0, sl) call
    value: Callable     # njit (out, c, s0, sl, block, x0, x1, x2, j0, j1, j2, params, absolute) -> fitness
    width: int          # ufunc arguments per pose (the buffers hold width * poses values)
    block: int          # poses per block of the numpy fitness
    params: tuple       # the geometry's floats ``value`` reads
    #: ``ufunc`` from compiled code: njit (loop, data, arg, out, s0, sl, block), numpy's own loop of
    #: the ufunc called by address (:mod:`fkopt.numerics.ufunc_loop`), and that (loop, data); None
    #: where numpy's loop cannot be read (then the iterations call ``ufunc`` from Python)
    ufunc_compiled: Callable | None = None
    ufunc_loop: tuple | None = None


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


class FrameArm(SerialMechanism):
    """A serial arm whose closed form is its tip frame: :meth:`frame` gives (p, R), the
    position and rotation as nested tuples of arrays shaped like the batch; the pose is the
    position and the Z-Y-Z Euler angles in degrees (wang7dof's convention). DH tables and URDF
    chains are both such arms."""

    pose_names = ("x", "y", "z", "alpha", "beta", "gamma")

    #: Which unknowns are periodic (continuous joints: any angle is allowed, answers are
    #: wrapped into the bounds); instances may set their own array.
    periodic: np.ndarray | None = None

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    def frame(self, joints):
        raise NotImplementedError

    def frame_jacobian(self, joints):
        """Tip position (..., 3), rotation (..., 3, 3) and geometric frame Jacobian (..., 6, n)
        per public joint unit (rows 0-2 d(position)/dq, rows 3-5 angular velocity in the base
        frame). Every frame arm defines it; solvers use only this interface."""
        raise NotImplementedError

    def frame_jacobian1(self, t):
        """:meth:`frame_jacobian` of one configuration on Python floats in internal units (rad
        for angles, the length unit for lengths; the Jacobian per internal unit)."""
        raise NotImplementedError

    def jacobian(self, joints) -> np.ndarray:
        """The frame Jacobian (..., 6, n) of :meth:`frame_jacobian`."""
        return self.frame_jacobian(joints)[2]

    def kinematic_key(self) -> tuple:
        """Hashable numbers that fix the arm's forward map (caches, e.g. inverse's start table)."""
        raise NotImplementedError

    def periodic_mask(self) -> np.ndarray:
        """Boolean (n,) of periodic unknowns (all False unless the arm says otherwise)."""
        if self.periodic is None:
            return np.zeros(self.dof, dtype=bool)
        return np.asarray(self.periodic, dtype=bool)

    @staticmethod
    def euler_rates(R, omega) -> np.ndarray:
        """Z-Y-Z Euler-angle rates (..., 3, k) of angular velocities omega (..., 3, k) at
        rotations R (..., 3, 3): with w = (w_x, w_y, w_z), alpha' = w_z - cos(beta) gamma',
        beta' = -sin(alpha) w_x + cos(alpha) w_y, gamma' = (cos(alpha) w_x + sin(alpha) w_y) / sin(beta)
        (from w = alpha' e_z + beta' Rz(alpha) e_y + gamma' Rz(alpha) Ry(beta) e_z); infinite at
        sin(beta) = 0, the singularity of the angles themselves."""
        R = np.asarray(R)
        al = np.arctan2(R[..., 1, 2], R[..., 0, 2])[..., None]
        sb = np.hypot(R[..., 2, 0], R[..., 2, 1])[..., None]
        cb = R[..., 2, 2][..., None]
        wx, wy, wz = omega[..., 0, :], omega[..., 1, :], omega[..., 2, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            gd = (np.cos(al) * wx + np.sin(al) * wy) / sb
        bd = -np.sin(al) * wx + np.cos(al) * wy
        return np.stack([wz - cb * gd, bd, gd], axis=-2)

    def fk(self, joints) -> np.ndarray:
        p, R = self.frame(joints)
        alpha, beta, gamma = rotations.zyz_angles(R)
        return np.stack([p[0], p[1], p[2], np.degrees(alpha), np.degrees(beta), np.degrees(gamma)], axis=-1)

    def fk_matrix(self, joints) -> np.ndarray:
        """Homogeneous tip transforms shaped (..., 4, 4)."""
        p, R = self.frame(joints)
        upper = np.concatenate([rotations.to_array(R), np.stack(p, axis=-1)[..., None]], axis=-1)
        last = np.broadcast_to(np.array([0.0, 0.0, 0.0, 1.0]), upper.shape[:-2] + (1, 4))
        return np.concatenate([upper, last], axis=-2)
