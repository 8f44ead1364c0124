"""Study files: the YAML schema of a workspace study, validated with pydantic.

A *study* solves many poses of one mechanism with several algorithms (algorithms x poses x
runs) and reports statistics over all (pose, run) pairs. A YAML file is a study when its top
level says ``kind: study``; any other file is an experiment (:mod:`fkopt.kinds.experiment.config`).
The explicit key (rather than a folder convention) lets ``fkopt reproduce`` and ``fkopt check``
dispatch on the file itself, wherever it lives::

    kind: study
    name: 3rps_workspace            # results folder OUT/<paper>/<name>/ (paper: studies)
    title: "3-RPS: uniform workspace poses"
    mechanism: {name: 3-rps}
    poses: {uniform: 200, seed: 7}  # or grid / waypoints / circle, see below
    algorithms:
      - name: gabc
      - name: lm
        start: centre               # local methods: a pose {alpha: 0, ...} or "centre"
        population: 1
    population: 10
    iterations: 600
    runs: 5
    seed: 2024
    threshold: 1.0e-10              # success rate, evaluations to target, ECDF are against it
    stop_at_threshold: true
    chunk: 20                       # poses per task (the unit of parallel work and of resume)
    mode: independent               # or: tracking

Pose sets (``poses:``), in the space of the mechanism's unknowns -- the pose of a parallel
mechanism; the joints of a serial arm, whose targets are then ``fk(joints)`` (always reachable):

* ``{uniform: N, seed: S}`` -- N points uniform in the bounds, drawn exactly like an
  experiment's ``cases: {random: N, seed: S}``;
* ``{grid: {alpha: [-20, 20, 9], beta: [-20, 20, 9]}, fixed: {z: 550}}`` -- a full grid
  (``[lower, upper, points]`` per variable, the first variable varying slowest) with the other
  variables fixed; a grid over exactly two variables also gets a heat map (``heatmap.png``);
* ``{waypoints: [{...}, {...}, ...], points: 50}`` -- a polyline through the waypoints,
  ``points`` poses equally spaced in the normalised coordinates (each variable divided by its
  box width), both ends included; a line is two waypoints;
* ``{circle: {centre: {...}, radius: 0.05, plane: [x, y]}, points: 40}`` -- ``points`` poses on
  a closed circle (the first not repeated) in the plane of two variables around ``centre``;
  ``radius`` may be ``[r1, r2]`` for an ellipse (e.g. mm and degrees);
* (tracking only) a list of waypoint and circle sets: several independent trajectories, of any
  lengths, numbered 1, 2, ... in ``tracking.csv``; their poses are indexed one after another.

Modes:

* ``independent`` -- every pose is solved on its own, cold, by every algorithm for ``runs``
  seeded runs. A task is (pose chunk, algorithm); pose i of the task uses the seed
  ``task_seed(seed, i, label)`` of :mod:`fkopt.kinds.experiment.runner`, so the numbers do not
  depend on ``chunk``, on the executor, or on which tasks ran first.
* ``tracking`` -- the poses are a trajectory (or several) solved in order, the way a controller
  does: each step warm-starts from the previous step's solution of the same run (local methods
  ``nr``/``lm``: ``x0`` = that solution; swarms and hybrids: their search box shrunk to
  ``tracking.radius`` x the box width around it). The first step starts from ``start`` (or the
  centre of the bounds) for local methods and from the full box for swarms. ``warm_start: false``
  on an algorithm solves every step cold instead (a baseline). A task is (all trajectories,
  algorithm): step t of every trajectory that has one is one solve (trajectories x runs rows),
  the pose with index i in the pose set using the seed ``task_seed(seed, i, label)``, so a
  trajectory's numbers do not depend on the others. Time per step (amortised over the
  trajectories) goes to ``tracking_timing.csv`` (never into the deterministic files).
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Literal

from pydantic import Field, ValidationError, field_validator, model_validator

from fkopt.errors import FkoptError
from fkopt.run.config_base import MAX_CASES, MAX_RUNS, NOT_NUMERIC, AlgorithmSpec, RunConfig, Seed, Strict
from fkopt.files import error_line, load_mapping

KIND = "study"
#: Trajectories of one tracking study (they are solved together, step by step).
MAX_TRAJECTORIES = 1000


class StudyAlgorithmSpec(AlgorithmSpec):
    #: Start point of local methods: a pose, or "centre" (centre of the bounds).
    start: dict[str, float] | Literal["centre"] | None = None
    #: Tracking mode only: start each step from the previous step's solution (default) or cold.
    warm_start: bool = True


class UniformPoses(Strict):
    uniform: int = Field(ge=1, le=MAX_CASES, description="number of poses uniform in the bounds")
    seed: int = Seed()


class GridPoses(Strict):
    grid: dict[str, tuple[float, float, int]] = Field(min_length=1)
    fixed: dict[str, float] = Field(default_factory=dict)

    @field_validator("grid")
    @classmethod
    def _points(cls, grid):
        for name, (lo, hi, n) in grid.items():
            if not 1 <= n <= MAX_CASES:
                raise ValueError(f"grid.{name}: needs 1 to {MAX_CASES} points, got {n}")
            if n > 1 and not lo < hi:
                raise ValueError(f"grid.{name}: lower {lo:g} must be below upper {hi:g}")
        total = 1
        for _, _, n in grid.values():
            total *= n
        if total > MAX_CASES:
            raise ValueError(f"the grid has {total} points, more than the {MAX_CASES} allowed")
        return grid


class WaypointPoses(Strict):
    waypoints: list[dict[str, float]] = Field(min_length=2)
    points: int = Field(ge=2, le=MAX_CASES, description="poses along the polyline, both ends included")


class CircleSpec(Strict):
    centre: dict[str, float]
    radius: float | tuple[float, float]
    plane: tuple[str, str]

    @field_validator("plane")
    @classmethod
    def _two(cls, plane):
        if plane[0] == plane[1]:
            raise ValueError(f"the two plane variables must differ, got {list(plane)}")
        return plane


class CirclePoses(Strict):
    circle: CircleSpec
    points: int = Field(ge=3, le=MAX_CASES, description="poses on the closed circle")


PoseSet = UniformPoses | GridPoses | WaypointPoses | CirclePoses


class TrackingSpec(Strict):
    #: Half width of a swarm's warm-start box around the previous solution, as a fraction of
    #: each variable's box width (local methods start at the previous solution itself).
    radius: float = Field(0.05, gt=0, le=1)


class StudyConfig(RunConfig):
    """A :class:`~fkopt.kinds.experiment.config.RunConfig` whose targets come from a pose set, plus the
    study's own settings (chunks, tracking, statistics)."""

    kind: Literal["study"]
    paper: str = "studies"
    #: A pose set; in tracking mode also a list of trajectories, solved together step by step.
    poses: PoseSet | list[WaypointPoses | CirclePoses] = Field(union_mode="left_to_right")
    algorithms: list[StudyAlgorithmSpec] = Field(min_length=1)
    runs: int = Field(5, ge=1, le=MAX_RUNS)
    threshold: float = Field(1e-10, gt=0)
    chunk: int = Field(20, ge=1, description="poses per task (independent mode)")
    mode: Literal["independent", "tracking"] = "independent"
    tracking: TrackingSpec = Field(default_factory=TrackingSpec)
    #: Significance level of the pairwise Wilcoxon rank-sum tests (after Holm's correction).
    alpha: float = Field(0.05, gt=0, lt=1)

    @model_validator(mode="after")
    def _mode(self):
        if self.mode == "tracking" and isinstance(self.poses, (UniformPoses, GridPoses)):
            raise ValueError("mode tracking needs a trajectory: poses.waypoints or poses.circle "
                             "(uniform and grid poses have no order)")
        if isinstance(self.poses, list):
            if self.mode != "tracking":
                raise ValueError("poses: a list of trajectories needs mode: tracking (otherwise give one pose set)")
            if not 1 <= len(self.poses) <= MAX_TRAJECTORIES:
                raise ValueError(f"poses: 1 to {MAX_TRAJECTORIES} trajectories, got {len(self.poses)}")
            if sum(p.points for p in self.poses) > MAX_CASES:
                raise ValueError(f"poses: the trajectories have more than {MAX_CASES} points in all")
        return self

    def fingerprint(self) -> str:
        """Hash of everything that changes the numbers (a resumed study must match it)."""
        data = self.model_dump(mode="json", exclude=set(NOT_NUMERIC))
        data["algorithms"] = [{k: v for k, v in a.items() if k != "printed"} for a in data["algorithms"]]
        text = json.dumps(data, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def _pose_set_error(data: dict) -> str | None:
    """A clear message for a ``poses:`` mapping that names no (or several) pose set kinds."""
    poses = data.get("poses")
    if isinstance(poses, list):       # tracking: trajectories
        for j, item in enumerate(poses):
            kinds = [k for k in ("waypoints", "circle") if isinstance(item, dict) and k in item]
            if len(kinds) != 1:
                return (f"poses[{j}]: a trajectory needs exactly one of waypoints, circle"
                        + (f" (got {', '.join(kinds)})" if kinds else ""))
        return None
    if not isinstance(poses, dict):
        return None
    kinds = [k for k in ("uniform", "grid", "waypoints", "circle") if k in poses]
    if len(kinds) != 1:
        return ("poses: needs exactly one of uniform, grid, waypoints, circle"
                + (f" (got {', '.join(kinds)})" if kinds else ""))
    return None


def study_from_dict(data: dict, where: str = "study") -> StudyConfig:
    """Validate a study mapping; errors are one line naming ``where`` and the field."""
    if data.get("kind") != KIND:
        raise FkoptError(f"{where}: kind: expected '{KIND}', got {data.get('kind')!r}")
    msg = _pose_set_error(data)
    if msg:
        raise FkoptError(f"{where}: {msg}")
    try:
        return StudyConfig(**data)
    except ValidationError as err:
        raise FkoptError(f"{where}: {_study_error(err, data)}") from None


POSE_BRANCHES = {"poses": {"uniform": "UniformPoses", "grid": "GridPoses", "waypoints": "WaypointPoses",
                            "circle": "CirclePoses"}}


def _study_error(err: ValidationError, data: dict) -> str:
    """One line; a union of pose sets reports the branch the user meant (by its key)."""
    return error_line(err, POSE_BRANCHES, data, model=StudyConfig)


def load_study(path: str | Path) -> StudyConfig:
    """Read and validate a study file (``kind: study``)."""
    return study_from_dict(load_mapping(path, "study fields"), str(path))
