"""Pose sets of a study: uniform, grid, polyline through waypoints, circle.

Points live in the space of the mechanism's unknowns (:attr:`Mechanism.unknown_names`): the
pose of a parallel mechanism, the joints of a serial arm. What a solver must reproduce (its
``inputs``) and what its answer is compared with (``targets``, a pose) follow as in an
experiment: joints = ik(pose) for a parallel mechanism, pose = fk(joints) for a serial arm.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fkopt.errors import FkoptError
from fkopt.kinds.study.config import CirclePoses, GridPoses, StudyConfig, UniformPoses, WaypointPoses


@dataclass
class PoseSet:
    names: tuple[str, ...]          # unknown names (columns of ``points``)
    points: np.ndarray              # (n, dim) in the space of the unknowns
    inputs: np.ndarray              # (n, n_inputs) what each problem must reproduce
    targets: np.ndarray             # (n, n_pose) the true answer in the compared space (pose)
    grid_axes: tuple[str, str] | None = None   # the two varying variables of a 2-D grid
    #: (start, stop) of each trajectory in ``points`` (tracking); one segment for any other set.
    segments: tuple[tuple[int, int], ...] = ()

    def __post_init__(self):
        if not self.segments:
            self.segments = ((0, len(self.points)),)

    @property
    def trajectory(self) -> np.ndarray:
        """(n,) index of the trajectory each pose belongs to (all 0 but in multi-trajectory tracking)."""
        return np.repeat(np.arange(len(self.segments)), [b - a for a, b in self.segments])

    @property
    def step(self) -> np.ndarray:
        """(n,) position of each pose along its trajectory."""
        return np.concatenate([np.arange(b - a) for a, b in self.segments])

    def __len__(self) -> int:
        return len(self.points)

    def label(self, i: int) -> str:
        return f"pose-{i + 1}"


def _vector(mech, values: dict, where: str) -> np.ndarray:
    return mech.vector(values, mech.unknown_names, where)


def _check_bounds(mech, pts: np.ndarray, where: str) -> None:
    lo, hi = mech.bounds[:, 0], mech.bounds[:, 1]
    bad = (pts < lo - 1e-9) | (pts > hi + 1e-9)
    if bad.any():
        i, j = (int(v) for v in np.argwhere(bad)[0])
        name = mech.unknown_names[j]
        raise FkoptError(f"{where}: point {i + 1} has {name}={pts[i, j]:g} outside the workspace bounds "
                         f"[{lo[j]:g}, {hi[j]:g}] (widen mechanism.bounds.{name} or move the poses)")


def uniform_points(mech, spec: UniformPoses) -> np.ndarray:
    """Same draw as an experiment's ``cases: {random: N, seed: S}``."""
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(spec.seed)))
    u = rng.random((spec.uniform, len(mech.unknown_names)))
    return mech.bounds[:, 0] + u * (mech.bounds[:, 1] - mech.bounds[:, 0])


def grid_points(mech, spec: GridPoses) -> tuple[np.ndarray, tuple[str, str] | None]:
    names = mech.unknown_names
    for key in list(spec.grid) + list(spec.fixed):
        if key not in names:
            raise FkoptError(f"poses: unknown variable '{key}'; allowed: {', '.join(names)}")
    both = set(spec.grid) & set(spec.fixed)
    if both:
        raise FkoptError(f"poses: '{sorted(both)[0]}' is both in grid and fixed")
    missing = [n for n in names if n not in spec.grid and n not in spec.fixed]
    if missing:
        raise FkoptError(f"poses.fixed: missing {', '.join(missing)} (every variable not in the grid "
                         f"needs a value)")
    axes = [np.linspace(lo, hi, int(n)) for lo, hi, n in spec.grid.values()]
    mesh = np.meshgrid(*axes, indexing="ij")
    cols = {name: m.ravel() for name, m in zip(spec.grid, mesh)}
    count = mesh[0].size
    pts = np.column_stack([cols[n] if n in cols else np.full(count, float(spec.fixed[n])) for n in names])
    varying = [n for n, (lo, hi, k) in spec.grid.items() if k > 1]
    return pts, (tuple(varying) if len(varying) == 2 else None)


def waypoint_points(mech, spec: WaypointPoses) -> np.ndarray:
    way = np.array([_vector(mech, w, f"poses.waypoints[{i}]") for i, w in enumerate(spec.waypoints)])
    width = mech.bounds[:, 1] - mech.bounds[:, 0]
    seg = np.sqrt((((way[1:] - way[:-1]) / width) ** 2).sum(axis=1))
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] == 0:
        raise FkoptError("poses.waypoints: all waypoints are the same pose")
    t = np.linspace(0.0, s[-1], spec.points)
    return np.column_stack([np.interp(t, s, way[:, j]) for j in range(way.shape[1])])


def circle_points(mech, spec: CirclePoses) -> np.ndarray:
    c = spec.circle
    centre = _vector(mech, c.centre, "poses.circle.centre")
    names = mech.unknown_names
    for p in c.plane:
        if p not in names:
            raise FkoptError(f"poses.circle.plane: unknown variable '{p}'; allowed: {', '.join(names)}")
    r1, r2 = (c.radius, c.radius) if isinstance(c.radius, (int, float)) else c.radius
    theta = 2.0 * np.pi * np.arange(spec.points) / spec.points
    pts = np.repeat(centre[None, :], spec.points, axis=0)
    pts[:, names.index(c.plane[0])] += r1 * np.cos(theta)
    pts[:, names.index(c.plane[1])] += r2 * np.sin(theta)
    return pts


def _points(mech, spec, where: str) -> tuple[np.ndarray, tuple[str, str] | None]:
    if isinstance(spec, UniformPoses):
        return uniform_points(mech, spec), None
    if isinstance(spec, GridPoses):
        return grid_points(mech, spec)
    if isinstance(spec, WaypointPoses):
        return waypoint_points(mech, spec), None
    if isinstance(spec, CirclePoses):
        return circle_points(mech, spec), None
    raise FkoptError(f"{where}: unsupported pose set {type(spec).__name__}")  # pragma: no cover


def build_poses(config: StudyConfig, mech) -> PoseSet:
    """The study's poses; a list of trajectories (tracking) is concatenated, with its segments."""
    specs = config.poses if isinstance(config.poses, list) else [config.poses]
    parts, axes, segments = [], None, []
    for j, spec in enumerate(specs):
        where = f"poses[{j}]" if isinstance(config.poses, list) else "poses"
        try:
            pts, axes = _points(mech, spec, where)
        except FkoptError as err:     # the point builders name "poses"; a list names the item
            raise FkoptError(str(err).replace("poses", where, 1)) from None
        segments.append((sum(len(p) for p in parts), sum(len(p) for p in parts) + len(pts)))
        parts.append(pts)
    pts = np.concatenate(parts)
    _check_bounds(mech, pts, "poses")
    if mech.kind == "serial":
        targets = mech.fk(pts)
        inputs = targets
    else:
        targets = pts
        inputs = mech.ik(pts)
    if not np.all(np.isfinite(inputs)):
        i = int(np.flatnonzero(~np.isfinite(inputs).all(axis=1))[0])
        raise FkoptError(f"poses: point {i + 1} ({', '.join(f'{n}={v:g}' for n, v in zip(mech.unknown_names, pts[i]))}) "
                         f"has no finite {'inverse' if mech.kind != 'serial' else 'forward'} map")
    return PoseSet(tuple(mech.unknown_names), pts, np.asarray(inputs, float), np.asarray(targets, float), axes,
                   tuple(segments))
