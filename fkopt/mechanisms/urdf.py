"""Serial arms read from URDF files: ``fkopt.mechanism("urdf", file="arm.urdf", base="link0", tip="tool")``.

The chain is the joints from link ``base`` (default: the root link) to link ``tip``
(default: the only leaf link; name it when the tree branches). Each joint applies its fixed
``origin`` (xyz, rpy as URDF defines them: R = Rz(yaw) Ry(pitch) Rx(roll)) and then its motion
about/along its unit ``axis``: revolute and continuous joints rotate (unknowns in degrees),
prismatic joints translate (unknowns in metres), fixed joints only carry their origin.
Lengths stay in metres, as URDF has them; the pose is (x, y, z) of the tip frame's origin
in the base frame plus the Z-Y-Z Euler angles (degrees) of :class:`fkopt.mechanisms.dh_arm.DHArm`,
so :class:`fkopt.problems.IKProblem` treats both alike.

Bounds: revolute and prismatic joints take ``<limit lower upper>`` from the file; continuous
joints (no limits) default to [-180, 180] deg, and any joint's bounds can be overridden by the
config's ``mechanism.bounds`` as for every mechanism. In an experiment file, a relative
``geometry.file`` is relative to the config file's folder (see
:func:`fkopt.experiment.runner.build_mechanism`); from Python, to the working directory.
Without ``file`` the mechanism is wang7dof's arm written as URDF (``mechanisms/data/wang7dof.urdf``),
which gives the same poses as ``7dof-arm`` with lengths in metres instead of millimetres.

Parsing uses yourdfpy (meshes are not loaded); FK is vectorised over any batch shape and
written elementwise like the DH arm, so batching never changes the numbers. No analytic
Jacobian here: solvers that need one use their finite-difference fallback.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from pydantic import Field, ValidationError

from ..errors import FkoptError, did_you_mean
from .base import FrameArm, Geometry, describe_validation_error

DEFAULT_FILE = Path(__file__).resolve().parent / "data" / "wang7dof.urdf"
#: Bounds of continuous joints unless the config gives them (deg).
CONTINUOUS_BOUNDS = (-180.0, 180.0)
MOVING = ("revolute", "continuous", "prismatic")


class URDFGeometry(Geometry):
    file: str = Field(str(DEFAULT_FILE), description="URDF file (relative: to the config's folder)")
    base: str | None = Field(None, description="first link of the chain (default: the root link)")
    tip: str | None = Field(None, description="last link of the chain (default: the only leaf link)")


#: Largest URDF file read (bytes): a robot description with meshes referenced, not inlined, is
#: kilobytes; a parsed tree takes ~35 times its file size in memory.
MAX_URDF_BYTES = 4 << 20


def _load(path: Path):
    """Parse with yourdfpy; every failure is one line naming the file."""
    if not path.is_file():
        raise FkoptError(f"urdf geometry.file: {path} does not exist")
    size = path.stat().st_size
    if size > MAX_URDF_BYTES:
        raise FkoptError(f"urdf {path}: {size} bytes, larger than the {MAX_URDF_BYTES} bytes accepted for "
                         "a URDF file")
    try:
        import yourdfpy
    except ImportError:
        raise FkoptError("the 'urdf' mechanism needs yourdfpy: pip install yourdfpy") from None
    from lxml import etree   # a dependency of yourdfpy
    try:   # strict XML first: yourdfpy would log the error and retry with a recovering parser
        etree.parse(str(path), etree.XMLParser(remove_blank_text=True))
    except etree.XMLSyntaxError as err:
        raise FkoptError(f"urdf {path}: malformed URDF ({err})") from None
    try:
        robot = yourdfpy.URDF.load(str(path), build_scene_graph=False, build_collision_scene_graph=False,
                                   load_meshes=False, load_collision_meshes=False)
    except Exception as err:
        msg = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise FkoptError(f"urdf {path}: malformed URDF ({msg})") from None
    if robot is None or not getattr(robot, "robot", None) or not robot.link_map:
        raise FkoptError(f"urdf {path}: malformed URDF (no <robot> with links)")
    return robot


def _chain(robot, path: Path, base: str | None, tip: str | None) -> list:
    links = robot.link_map
    by_child = {j.child: j for j in robot.joint_map.values()}
    parents = {j.parent for j in robot.joint_map.values()}
    for role, name in (("base", base), ("tip", tip)):
        if name is not None and name not in links:
            raise FkoptError(f"urdf {path}: unknown link '{name}' (geometry.{role}); links: "
                             f"{did_you_mean(name, links)}")
    if base is None:
        roots = [n for n in links if n not in by_child]
        if len(roots) != 1:
            raise FkoptError(f"urdf {path}: {len(roots)} root links, name geometry.base; links: "
                             f"{did_you_mean('', links)}")
        base = roots[0]
    if tip is None:
        leaves = [n for n in links if n not in parents]
        if len(leaves) != 1:
            raise FkoptError(f"urdf {path}: the tree has {len(leaves)} leaf links ({', '.join(sorted(leaves))}); "
                             "name geometry.tip")
        tip = leaves[0]
    chain, link = [], tip
    while link != base:
        joint = by_child.get(link)
        if joint is None:
            raise FkoptError(f"urdf {path}: link '{tip}' is not below link '{base}' (no chain between them)")
        chain.append(joint)
        link = joint.parent
        if len(chain) > len(robot.joint_map):
            raise FkoptError(f"urdf {path}: the joints form a loop")
    chain.reverse()
    for j in chain:
        if j.type not in (*MOVING, "fixed"):
            raise FkoptError(f"urdf {path}: joint '{j.name}' has type '{j.type}'; the chain may hold "
                             "revolute, continuous, prismatic and fixed joints")
    if not any(j.type in MOVING for j in chain):
        raise FkoptError(f"urdf {path}: no moving joint between '{base}' and '{tip}'")
    return chain


class URDFArm(FrameArm):
    """Serial arm from a URDF chain (module docstring). Lengths in m, angles in deg."""

    name = "urdf"
    pose_units = ("m", "m", "m", "deg", "deg", "deg")
    Geometry = URDFGeometry
    #: Geometry keys holding file paths (relative ones are resolved against the config's folder).
    file_fields = ("file",)
    # Class-level values describe the default file (wang7dof); each instance sets its own.
    joint_names = tuple(f"q{i + 1}" for i in range(7))
    joint_units = ("deg",) * 7
    default_bounds = {"q1": CONTINUOUS_BOUNDS, "q2": (-90.0, 30.0), "q3": (-90.0, 120.0), "q4": (-90.0, 90.0),
                      "q5": (-90.0, 90.0), "q6": (-90.0, 90.0), "q7": (-30.0, 90.0)}

    def __init__(self, bounds: dict[str, Any] | None = None, **geometry: Any):
        try:
            g = self.Geometry(**geometry)
        except ValidationError as err:
            raise FkoptError(describe_validation_error(err, f"{self.name} geometry")
                             + f" (geometry keys: {did_you_mean('', self.Geometry.model_fields)})") from None
        path = Path(g.file)
        robot = _load(path)
        chain = _chain(robot, path, g.base, g.tip)
        names, units, limits, steps = [], [], {}, []
        for j in chain:
            origin = np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=float)
            axis = np.array([1.0, 0.0, 0.0]) if j.axis is None else np.asarray(j.axis, dtype=float)
            for what, value in (("origin", origin), ("axis", axis)):
                if not np.all(np.isfinite(value)):
                    raise FkoptError(f"urdf {path}: joint '{j.name}' {what} holds a value that is not a finite "
                                     "number (NaN or inf)")
            if j.type in MOVING:
                norm = float(np.linalg.norm(axis))
                if not norm > 0:
                    raise FkoptError(f"urdf {path}: joint '{j.name}' has a zero axis")
                axis = axis / norm
                names.append(j.name)
                prismatic = j.type == "prismatic"
                units.append("m" if prismatic else "deg")
                lim = j.limit
                if j.type == "continuous" or lim is None or lim.lower is None or lim.upper is None:
                    if j.type != "continuous":
                        raise FkoptError(f"urdf {path}: joint '{j.name}' ({j.type}) needs <limit lower upper>")
                    limits[j.name] = CONTINUOUS_BOUNDS
                else:
                    lo, hi = float(lim.lower), float(lim.upper)
                    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
                        raise FkoptError(f"urdf {path}: joint '{j.name}' <limit lower=\"{lim.lower}\" "
                                         f"upper=\"{lim.upper}\">: finite numbers, lower below upper, are "
                                         "needed (a joint without limits is type=\"continuous\")")
                    limits[j.name] = (lo, hi) if prismatic else (round(float(np.degrees(lo)), 9),
                                                                 round(float(np.degrees(hi)), 9))
            steps.append((j.type, origin[:3, :3].copy(), origin[:3, 3].copy(), axis))
        if len(set(names)) != len(names):
            raise FkoptError(f"urdf {path}: joint names repeat along the chain")
        self.joint_names = tuple(names)
        self.joint_units = tuple(units)
        self.default_bounds = limits
        super().__init__(bounds, **geometry)
        self.path = path
        self.base_link = chain[0].parent
        self.tip_link = chain[-1].child
        self._steps = steps
        strokes = [max(abs(lo), abs(hi)) for unit, (lo, hi) in zip(self.joint_units, self.bounds) if unit == "m"]
        self._reach = float(sum(np.linalg.norm(p) for _, _, p, _ in steps) + sum(strokes))

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    @property
    def reach(self) -> float:
        """Upper bound of the tip's distance from the base origin (sum of origin offsets + strokes)."""
        return self._reach

    def frame(self, joints):
        """Tip frame as (p, R) -- p = (px, py, pz) in m, R a :data:`rotations.Matrix` -- computed
        elementwise over the batch shape of ``joints`` (..., dof)."""
        joints = np.asarray(joints, dtype=float)
        if joints.shape[-1:] != (self.dof,):
            raise FkoptError(f"{self.name} joints: expected {self.dof} values "
                             f"({', '.join(self.joint_names)}), got shape {joints.shape}")
        shape = joints.shape[:-1]
        zero = np.zeros(shape)
        R = tuple(tuple(zero + (1.0 if r == c else 0.0) for c in range(3)) for r in range(3))
        p = (zero.copy(), zero.copy(), zero.copy())
        k = 0
        for kind, Ro, po, axis in self._steps:
            # fixed origin: p += R po, R = R Ro
            p = tuple(p[r] + R[r][0] * po[0] + R[r][1] * po[1] + R[r][2] * po[2] for r in range(3))
            R = tuple(tuple(R[r][0] * Ro[0][c] + R[r][1] * Ro[1][c] + R[r][2] * Ro[2][c] for c in range(3))
                      for r in range(3))
            if kind == "fixed":
                continue
            q = joints[..., k]
            k += 1
            if kind == "prismatic":
                d = (axis[0] * q, axis[1] * q, axis[2] * q)
                p = tuple(p[r] + R[r][0] * d[0] + R[r][1] * d[1] + R[r][2] * d[2] for r in range(3))
                continue
            t = np.radians(q)
            c, s = np.cos(t), np.sin(t)
            v = 1.0 - c
            x, y, z = axis
            # Rodrigues: Rot(axis, t) = c I + s [axis]x + (1 - c) axis axis^T
            M = ((c + x * x * v, x * y * v - z * s, x * z * v + y * s),
                 (y * x * v + z * s, c + y * y * v, y * z * v - x * s),
                 (z * x * v - y * s, z * y * v + x * s, c + z * z * v))
            R = tuple(tuple(R[r][0] * M[0][cc] + R[r][1] * M[1][cc] + R[r][2] * M[2][cc] for cc in range(3))
                      for r in range(3))
        return p, R

    def describe(self) -> dict[str, Any]:
        out = super().describe()
        out["chain"] = {"file": str(self.path), "base": self.base_link, "tip": self.tip_link}
        return out
