"""3RPUPc-UPS parallel mechanism of chang2024 (docs/models.md "chang2024 -- 3RPUPc-UPS").

Chang et al. (2024), forward kinematics of a 3RPUPc-UPS parallel mechanism solved by P-ABC.
The paper's kinematic equations were lost in text extraction: the model below is the
reconstruction of docs/models.md, which reproduces the paper's one printed case
(alpha, beta, gamma, z) = (25 deg, 34 deg, 23 deg, 360 mm) -> (l1, l2, l3, delta) =
(332.048, 390.904, 402.294 mm, -14.4389 deg) within the printed rounding.

Pose (alpha, beta, gamma, z): degrees and mm. Base joints on a circle of radius R:
B1 = (-R, 0, 0), B2 = (0, -R, 0), B3 = (R, 0, 0), B4 = (0, R, 0); platform centre Q = (0, 0, z),
platform circle radius c; orientation R_p = Rx(-alpha) Ry(-beta) Rz(gamma) (standard active
rotations; the paper writes Rx(alpha) Ry(beta) Rz(gamma) in its own sign convention).

* Legs 1-3 (RPUPc): the U joint C_i slides on the platform circle (annular prismatic joint) and
  stays in its leg's vertical plane (legs 1, 3 in Y = 0, leg 2 in X = 0). With n the platform
  normal (third column of R_p), u = unit(e_y x n) oriented towards +X and v = unit(n x e_x)
  oriented towards -Y: C1 = Q - c u, C3 = Q + c u, C2 = Q + c v; l_i = |C_i - B_i| (mm).
* Leg 4 (UPS): S joint C4 = Q + R_p (0, c, 0); input angle delta = atan2(dX, -dY) of C4 - B4 (deg).

Default search bounds are not printed in the paper; fkopt uses angles in [-45, 45] deg and
z in [300, 420] mm (docs/models.md's suggestion), which contains the printed case.
"""
from __future__ import annotations

import numpy as np
from pydantic import Field

from fkopt.mechanisms.base import Geometry, ParallelMechanism


class RPUPcUPSGeometry(Geometry):
    R: float = Field(120.0, gt=0, description="base circle radius R (mm)")
    c: float = Field(60.0, gt=0, description="platform circle radius c (mm)")


class ThreeRPUPcUPS(ParallelMechanism):
    name = "3-rpupc-ups"
    blas_free_fitness = True   # elementwise map (module docstring): no BLAS on the fitness path
    paper = "chang2024"
    reconstruction = ("chang2024's kinematic equations were lost in extraction; docs/models.md's model "
                      "(annular-prismatic U joints kept in the legs' vertical planes, delta = "
                      "atan2(dX, -dY) of leg 4) reproduces the printed case within its rounding")
    pose_names = ("alpha", "beta", "gamma", "z")
    pose_units = ("deg", "deg", "deg", "mm")
    joint_names = ("l1", "l2", "l3", "delta")
    joint_units = ("mm", "mm", "mm", "deg")
    Geometry = RPUPcUPSGeometry
    # Not printed in chang2024: docs/models.md suggests angles +-45 deg, z 300-420 mm.
    default_bounds = {"alpha": (-45.0, 45.0), "beta": (-45.0, 45.0), "gamma": (-45.0, 45.0),
                      "z": (300.0, 420.0)}

    def ik(self, poses) -> np.ndarray:
        poses = np.asarray(poses, dtype=float)
        a, b, g = (np.radians(poses[..., i]) for i in range(3))
        z = poses[..., 3]
        sa, ca, sb, cb, sg, cg = np.sin(a), np.cos(a), np.sin(b), np.cos(b), np.sin(g), np.cos(g)
        R, c = self.geometry.R, self.geometry.c
        # R_p = Rx(-a) Ry(-b) Rz(g): normal n = R_p e_z and second column R_p e_y, written out.
        nx, ny, nz = -sb, sa * cb, ca * cb
        # (its z component does not enter delta, which is measured in the horizontal plane)
        ex, ey = -sg * cb, ca * cg - sa * sb * sg
        # u = unit(e_y x n) = unit(n_z, 0, -n_x), oriented towards +X
        hu = np.hypot(nz, nx) * np.where(nz < 0, -1.0, 1.0)
        ux, uz = nz / hu, -nx / hu
        # v = unit(n x e_x) = unit(0, n_z, -n_y), oriented towards -Y
        hv = np.hypot(nz, ny) * np.where(nz > 0, -1.0, 1.0)
        vy, vz = nz / hv, -ny / hv
        # leg 1: C1 = Q - c u, B1 = (-R, 0, 0); leg 3: C3 = Q + c u, B3 = (R, 0, 0)
        l1 = np.sqrt((R - c * ux) ** 2 + (z - c * uz) ** 2)
        l3 = np.sqrt((c * ux - R) ** 2 + (z + c * uz) ** 2)
        # leg 2: C2 = Q + c v, B2 = (0, -R, 0)
        l2 = np.sqrt((c * vy + R) ** 2 + (z + c * vz) ** 2)
        # leg 4: C4 = Q + c (second column of R_p), B4 = (0, R, 0)
        dx, dy = c * ex, c * ey - R
        delta = np.degrees(np.arctan2(dx, -dy))
        return np.stack([l1, l2, l3, delta], axis=-1)

    def jacobian(self, poses) -> np.ndarray:
        """d(l1, l2, l3, delta)/d(alpha, beta, gamma, z), shaped (..., 4, 4), public units
        (mm per degree, mm per mm, degree per degree) -- the derivative of the reconstruction
        above, written out: n' from R_p, the unit vectors u, v by the quotient rule
        (d(n_z/h) = n_x (n_x dn_z - n_z dn_x) / h^3 with h = hypot(n_z, n_x)), the legs by
        dl = (C - B) . dC / l, delta by d atan2(dX, -dY)."""
        poses = np.asarray(poses, dtype=float)
        a, b, g = (np.radians(poses[..., i]) for i in range(3))
        z = poses[..., 3]
        sa, ca, sb, cb, sg, cg = np.sin(a), np.cos(a), np.sin(b), np.cos(b), np.sin(g), np.cos(g)
        R, c = self.geometry.R, self.geometry.c
        zero = np.zeros_like(a)
        nx, ny, nz = -sb, sa * cb, ca * cb
        # derivatives of n with respect to (alpha, beta, gamma), radians
        dnx = (zero, -cb, zero)
        dny = (ca * cb, -sa * sb, zero)
        dnz = (-sa * cb, -ca * sb, zero)
        su = np.where(nz < 0, -1.0, 1.0)
        hu = np.hypot(nz, nx)
        ux, uz = su * nz / hu, -su * nx / hu
        sv = np.where(nz > 0, -1.0, 1.0)
        hv = np.hypot(nz, ny)
        vy, vz = sv * nz / hv, -sv * ny / hv
        l1 = np.sqrt((R - c * ux) ** 2 + (z - c * uz) ** 2)
        l3 = np.sqrt((c * ux - R) ** 2 + (z + c * uz) ** 2)
        l2 = np.sqrt((c * vy + R) ** 2 + (z + c * vz) ** 2)
        ex, ey = -sg * cb, ca * cg - sa * sb * sg
        dex = (zero, sg * sb, -cg * cb)
        dey = (-sa * cg - ca * sb * sg, -sa * cb * sg, -ca * sg - sa * sb * cg)
        DX, DY = c * ex, c * ey - R
        q = DX * DX + DY * DY
        J = np.empty(poses.shape[:-1] + (4, 4))
        k = np.pi / 180.0
        hu3, hv3 = hu ** 3, hv ** 3
        for j in range(3):
            dux = su * nx * (nx * dnz[j] - nz * dnx[j]) / hu3
            duz = -su * nz * (nz * dnx[j] - nx * dnz[j]) / hu3
            dvy = sv * ny * (ny * dnz[j] - nz * dny[j]) / hv3
            dvz = -sv * nz * (nz * dny[j] - ny * dnz[j]) / hv3
            J[..., 0, j] = k * c * (-(R - c * ux) * dux - (z - c * uz) * duz) / l1
            J[..., 2, j] = k * c * ((c * ux - R) * dux + (z + c * uz) * duz) / l3
            J[..., 1, j] = k * c * ((c * vy + R) * dvy + (z + c * vz) * dvz) / l2
            J[..., 3, j] = c * (-DY * dex[j] + DX * dey[j]) / q
        J[..., 0, 3] = (z - c * uz) / l1
        J[..., 1, 3] = (z + c * vz) / l2
        J[..., 2, 3] = (z + c * uz) / l3
        J[..., 3, 3] = 0.0
        return J
