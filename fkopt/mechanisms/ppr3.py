"""Planar 3-PPR parallel mechanism of wu2015 (docs/models.md "wu2015 -- planar 3-PPR").

Wu et al. (2015), forward kinematics of a planar 3-PPR parallel mechanism by an improved ant
colony algorithm. The inverse map is printed:

    d1 = F1x cos(theta) - F1y sin(theta) + x - D1x0,
    d2 = F2x cos(theta) - F2y sin(theta) + x - D2x0,
    d3 = F3x sin(theta) + F3y cos(theta) + y,

but the geometry (F_i, D_i0) is not. fkopt uses docs/models.md's reconstruction, which reproduces the
one printed case (x, y, theta) = (20 mm, 30 mm, 15 deg) -> d = (-14.8355, 65.3984, 70.1170) mm:
F_i = r_F (cos phi_i, sin phi_i) with r_F = 41.5322 mm, phi = (210, 330, 90) deg,
D1x0 = 5.4678 mm, D2x0 = -5.2814 mm. All of them can be overridden (``r_F``, ``phi1..3``,
``D1x0``, ``D2x0``); fkopt keeps the circle parametrisation rather than free F points.

The system is nearly linear and has a closed-form forward solution, :meth:`ThreePPR.fk_exact`:
d1 - d2 fixes theta through A cos(theta) - B sin(theta) = k, then d1 gives x and d3 gives y.
The cosine equation has two roots, so the forward kinematics has two branches. With the default
geometry (F1y = F2y) they are theta and -theta, with the same y and x' = x + r_F sin(theta):
for the printed case both (20, 30, 15) and (30.749, 30, -15) lie inside the workspace and
reproduce the same inputs, so a solver may legitimately return either.
"""
from __future__ import annotations

import numpy as np
from pydantic import Field

from fkopt.mechanisms.base import Geometry, ParallelMechanism


class ThreePPRGeometry(Geometry):
    r_F: float = Field(41.5322, gt=0, description="radius of the circle of platform points F_i (mm)")
    phi1: float = Field(210.0, description="polar angle of F1 on that circle (deg)")
    phi2: float = Field(330.0, description="polar angle of F2 (deg)")
    phi3: float = Field(90.0, description="polar angle of F3 (deg)")
    D1x0: float = Field(5.4678, description="offset of actuator 1 along x (mm)")
    D2x0: float = Field(-5.2814, description="offset of actuator 2 along x (mm)")


class ThreePPR(ParallelMechanism):
    name = "3-ppr"
    blas_free_fitness = True   # elementwise map (module docstring): no BLAS on the fitness path
    paper = "wu2015"
    reconstruction = ("wu2015 prints the inverse map but not F_i or D_i0; docs/models.md's geometry "
                      "(F_i on a circle r_F = 41.5322 mm at 210, 330, 90 deg, D1x0 = 5.4678 mm, "
                      "D2x0 = -5.2814 mm) reproduces the printed case")
    pose_names = ("x", "y", "theta")
    pose_units = ("mm", "mm", "deg")
    joint_names = ("d1", "d2", "d3")
    joint_units = ("mm", "mm", "mm")
    Geometry = ThreePPRGeometry
    # Workspace of wu2015: x, y in [-60, 60] mm, theta in [-24, 24] deg.
    default_bounds = {"x": (-60.0, 60.0), "y": (-60.0, 60.0), "theta": (-24.0, 24.0)}

    @property
    def F(self) -> np.ndarray:
        """Platform points F_i as a (3, 2) array (mm)."""
        g = self.geometry
        phi = np.radians([g.phi1, g.phi2, g.phi3])
        return g.r_F * np.stack([np.cos(phi), np.sin(phi)], axis=-1)

    def ik(self, poses) -> np.ndarray:
        poses = np.asarray(poses, dtype=float)
        x, y, t = poses[..., 0], poses[..., 1], np.radians(poses[..., 2])
        c, s = np.cos(t), np.sin(t)
        F, g = self.F, self.geometry
        d1 = F[0, 0] * c - F[0, 1] * s + x - g.D1x0
        d2 = F[1, 0] * c - F[1, 1] * s + x - g.D2x0
        d3 = F[2, 0] * s + F[2, 1] * c + y
        return np.stack([d1, d2, d3], axis=-1)

    def jacobian(self, poses) -> np.ndarray:
        """d(d_1, d_2, d_3)/d(x, y, theta), shaped (..., 3, 3): mm per mm and mm per degree."""
        poses = np.asarray(poses, dtype=float)
        t = np.radians(poses[..., 2])
        c, s = np.cos(t), np.sin(t)
        F = self.F
        k = np.pi / 180.0
        J = np.zeros(poses.shape[:-1] + (3, 3))
        J[..., 0, 0] = J[..., 1, 0] = J[..., 2, 1] = 1.0
        J[..., 0, 2] = (-F[0, 0] * s - F[0, 1] * c) * k
        J[..., 1, 2] = (-F[1, 0] * s - F[1, 1] * c) * k
        J[..., 2, 2] = (F[2, 0] * c - F[2, 1] * s) * k
        return J

    def fk_exact(self, joints) -> np.ndarray:
        """Both closed-form forward solutions, shaped (..., 2, 3), sorted by theta (ascending).

        theta in [-180, 180) deg; NaN where the inputs admit no pose (|k| > rho). Whether a
        branch lies in the search bounds is for the caller to check (``in_bounds``).
        """
        joints = np.asarray(joints, dtype=float)
        d1, d2, d3 = joints[..., 0], joints[..., 1], joints[..., 2]
        F, g = self.F, self.geometry
        A, B = F[0, 0] - F[1, 0], F[0, 1] - F[1, 1]
        rho, psi = np.hypot(A, B), np.arctan2(B, A)
        # A cos(t) - B sin(t) = rho cos(t + psi) = k
        ratio = (d1 - d2 + g.D1x0 - g.D2x0) / rho
        ratio = np.where(np.abs(ratio) <= 1.0 + 1e-12, np.clip(ratio, -1.0, 1.0), np.nan)
        root = np.arccos(ratio)
        thetas = np.stack([-psi - root, -psi + root], axis=-1)
        thetas = (thetas + np.pi) % (2.0 * np.pi) - np.pi
        thetas = np.sort(thetas, axis=-1)
        c, s = np.cos(thetas), np.sin(thetas)
        x = d1[..., None] - F[0, 0] * c + F[0, 1] * s + g.D1x0
        y = d3[..., None] - F[2, 0] * s - F[2, 1] * c
        return np.stack([x, y, np.degrees(thetas)], axis=-1)
