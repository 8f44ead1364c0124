"""A planar five-bar (2-RRR... the RR-RR closed chain): fkopt's ParallelMechanism protocol.

Two actuated revolute joints sit on the base at A1 = (-d/2, 0) and A2 = (d/2, 0); each drives a
proximal link of length ``l1`` whose end joins a distal link of length ``l2``; the two distal
links meet at the end-effector P = (x, y). The closed-form map is the inverse one, P -> the
actuator angles (theta1, theta2):

    theta_i = atan2(y - A_iy, x - A_ix) + s_i * acos((l1^2 + r_i^2 - l2^2) / (2 l1 r_i)),

with r_i = |P - A_i| and the working mode s = (+1, -1) ("elbows out"). Forward kinematics --
P from the two angles -- is what fkopt solves numerically. Poses outside the reachable annulus
l2 - l1 <= r_i <= l1 + l2 get the angle at the nearest reachable radius (the acos argument is
clipped), so the fitness stays finite and grows away from the workspace.
"""
from __future__ import annotations

import numpy as np
from pydantic import Field

from fkopt.mechanisms.base import Geometry, ParallelMechanism


class FiveBarGeometry(Geometry):
    d: float = Field(100.0, gt=0, description="distance between the two base joints (mm)")
    l1: float = Field(100.0, gt=0, description="proximal link length (mm)")
    l2: float = Field(150.0, gt=0, description="distal link length (mm)")


class FiveBar(ParallelMechanism):
    """Planar five-bar: pose (x, y) in mm, actuator angles theta1, theta2 in degrees."""

    name = "five-bar"
    pose_names = ("x", "y")
    pose_units = ("mm", "mm")
    joint_names = ("theta1", "theta2")
    joint_units = ("deg", "deg")
    Geometry = FiveBarGeometry
    default_bounds = {"x": (-80.0, 80.0), "y": (80.0, 200.0)}

    def ik(self, poses) -> np.ndarray:
        g = self.geometry
        p = np.asarray(poses, dtype=float)
        x, y = p[..., 0], p[..., 1]
        out = []
        for ax, s in ((-g.d / 2, 1.0), (g.d / 2, -1.0)):
            dx, dy = x - ax, y
            r = np.hypot(dx, dy)
            c = np.clip((g.l1 ** 2 + r ** 2 - g.l2 ** 2) / (2 * g.l1 * np.maximum(r, 1e-12)), -1.0, 1.0)
            out.append(np.degrees(np.arctan2(dy, dx) + s * np.arccos(c)))
        return np.stack(out, axis=-1)
