"""3-RPS parallel manipulator of mao2017 (SPEC.md "mao2017 -- 3-RPS").

Mao, Xie, Wu, Yuan (2017), "Forward kinematics optimization of 3-RPS parallel manipulator
based on global-best artificial bee colony algorithm", eqs. (1)-(10).

Pose (alpha, beta, z): rotations about X and Y in degrees and the platform height in mm. The
revolute axes are perpendicular to the legs, which forces the parasitic motions (eq. 6)

    gamma = atan( sin(alpha) sin(beta) / (cos(alpha) + cos(beta)) ),
    x_e   = (r_b / 2) (cos(gamma) cos(beta) - sin(gamma) sin(beta) sin(alpha) - cos(gamma) cos(alpha)),
    y_e   = -r_b sin(gamma) cos(beta),

and the leg lengths are d_i = |R B_i + (x_e, y_e, z) - A_i| (eq. 10) with
R = Rz(gamma) Ry(beta) Rx(alpha) (eq. 2), A_i = r_a (cos phi_i, sin phi_i, 0),
B_i = r_b (cos phi_i, sin phi_i, 0), phi_i = 2 pi (i - 1) / 3 (eq. 3).
"""
from __future__ import annotations

import numpy as np
from pydantic import Field

from .. import rotations
from .base import Geometry, ParallelMechanism


class ThreeRPSGeometry(Geometry):
    ra: float = Field(274.0, gt=0, description="base joint circle radius r_a (mm)")
    rb: float = Field(158.0, gt=0, description="platform joint circle radius r_b (mm)")


class ThreeRPS(ParallelMechanism):
    name = "3-rps"
    paper = "mao2017"
    pose_names = ("alpha", "beta", "z")
    pose_units = ("deg", "deg", "mm")
    joint_names = ("d1", "d2", "d3")
    joint_units = ("mm", "mm", "mm")
    Geometry = ThreeRPSGeometry
    # Workspace of mao2017 Sec. 3: alpha, beta in [-20, 20] deg, z in [400, 700] mm.
    default_bounds = {"alpha": (-20.0, 20.0), "beta": (-20.0, 20.0), "z": (400.0, 700.0)}

    def parasitic(self, poses):
        """(gamma [deg], x_e [mm], y_e [mm]) forced by the R-joint constraint (eq. 6)."""
        poses = np.asarray(poses, dtype=float)
        a, b = np.radians(poses[..., 0]), np.radians(poses[..., 1])
        g, xe, ye = self._parasitic(a, b)
        return np.degrees(g), xe, ye

    def _parasitic(self, a, b):
        rb = self.geometry.rb
        sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
        # arctan (not arctan2) as printed; cos a + cos b > 0 throughout |a|, |b| < 90 deg.
        g = np.arctan(sa * sb / (ca + cb))
        sg, cg = np.sin(g), np.cos(g)
        xe = 0.5 * rb * (cg * cb - sg * sb * sa - cg * ca)
        ye = -rb * sg * cb
        return g, xe, ye

    def ik(self, poses) -> np.ndarray:
        poses = np.asarray(poses, dtype=float)
        a, b, z = np.radians(poses[..., 0]), np.radians(poses[..., 1]), poses[..., 2]
        g, xe, ye = self._parasitic(a, b)
        R = rotations.zyx(a, b, g)
        ra, rb = self.geometry.ra, self.geometry.rb
        legs = []
        for i in range(3):
            phi = 2.0 * np.pi * i / 3.0
            c, s = np.cos(phi), np.sin(phi)
            # R @ (rb c, rb s, 0) uses only the first two columns of R.
            dx = rb * (R[0][0] * c + R[0][1] * s) + xe - ra * c
            dy = rb * (R[1][0] * c + R[1][1] * s) + ye - ra * s
            dz = rb * (R[2][0] * c + R[2][1] * s) + z
            legs.append(np.sqrt(dx * dx + dy * dy + dz * dz))
        return np.stack(legs, axis=-1)
