"""A scalable family of spatial serial chains: seeded standard-DH tables of n revolute joints.

``fkopt.mechanism("dh-chain", joints=12, seed=0)`` is a :class:`fkopt.mechanisms.dh_arm.DHArm`
whose table is drawn from the stream ``PCG64(SeedSequence([seed, joints]))`` (one chain per
(joints, seed), whatever else runs), so that a benchmark can show how a solver's cost grows with
the number of joints, as COCO's plots over dimension do (kinbench v3 holds n = 3 ... 30). Per
joint i, in this order:

* twist ``alpha_i = s * U(30, 90)`` deg with a random sign s: never near 0 or 180, so no two
  consecutive axes are (nearly) parallel and every joint adds a direction of motion (a generic,
  non-degenerate spatial chain, not a planar one);
* raw lengths ``a_i, d_i ~ U(0.2, 1)``, then all scaled so the reach bound ``sum sqrt(a_i^2 +
  d_i^2)`` is :data:`REACH` mm for every n: the workspace keeps its size as n grows, so position
  errors in mm compare across the family;
* ``theta_offset_i ~ U(-180, 180)`` deg (the zero configuration is not a special pose);
* joint limits (-170, 170) deg (real arms' ranges; the boundary pose set has a boundary to use).

The pose is DHArm's: (x, y, z) in mm and the Z-Y-Z Euler angles in degrees; unknowns q1..qn in
degrees. Chains of n < 6 joints reach a 3-D family of poses only; their targets are FK of joints
inside the limits, so every target is reachable.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from fkopt.mechanisms.base import geometry_base, lazy_model
from fkopt.mechanisms.dh_arm import DHArm

#: Reach bound of every member (mm): sum over the links of sqrt(a^2 + d^2).
REACH = 1000.0
TWIST_RANGE = (30.0, 90.0)      # |alpha| in degrees
LENGTH_RANGE = (0.2, 1.0)       # raw a, d before scaling to REACH
LIMIT = 170.0                   # joint limits (-LIMIT, LIMIT) deg
MAX_JOINTS = 100


@lru_cache(maxsize=256)
def chain_table(joints: int, seed: int) -> dict:
    """The DH table (a, alpha, d, theta_offset, limits) of member (joints, seed) (module docstring)."""
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([int(seed), int(joints)])))
    u = rng.random((joints, 5))
    sign = np.where(u[:, 0] < 0.5, -1.0, 1.0)
    alpha = sign * (TWIST_RANGE[0] + u[:, 1] * (TWIST_RANGE[1] - TWIST_RANGE[0]))
    a = LENGTH_RANGE[0] + u[:, 2] * (LENGTH_RANGE[1] - LENGTH_RANGE[0])
    d = LENGTH_RANGE[0] + u[:, 3] * (LENGTH_RANGE[1] - LENGTH_RANGE[0])
    scale = REACH / float(np.hypot(a, d).sum())
    offset = -180.0 + 360.0 * u[:, 4]
    return {"a": tuple(float(v) for v in a * scale), "alpha": tuple(float(v) for v in alpha),
            "d": tuple(float(v) for v in d * scale), "theta_offset": tuple(float(v) for v in offset),
            "limits": tuple((-LIMIT, LIMIT) for _ in range(joints))}


def _chain_geometry():
    from pydantic import Field

    class DHChainGeometry(geometry_base()):
        joints: int = Field(6, ge=1, le=MAX_JOINTS, description="number of revolute joints n")
        seed: int = Field(0, ge=0, le=2**63 - 1, description="seed of the DH table's stream")

        # the table DHArm reads, drawn from (joints, seed)
        @property
        def a(self):
            return chain_table(self.joints, self.seed)["a"]

        @property
        def alpha(self):
            return chain_table(self.joints, self.seed)["alpha"]

        @property
        def d(self):
            return chain_table(self.joints, self.seed)["d"]

        @property
        def theta_offset(self):
            return chain_table(self.joints, self.seed)["theta_offset"]

        @property
        def limits(self):
            return chain_table(self.joints, self.seed)["limits"]

    DHChainGeometry.__module__ = __name__
    return DHChainGeometry


class DHChain(DHArm):
    """Seeded spatial DH chain of ``joints`` revolute joints (module docstring); lengths in mm, angles in deg."""

    name = "dh-chain"
    Geometry = lazy_model(_chain_geometry)
    geometry_defaults = None          # the table is drawn from (joints, seed): build the model
