"""TRAC-IK through ``pytracik`` (Beeson and Ames, Humanoids 2015): KDL's Newton and an SQP solve
run in two threads until either meets ``eps`` or the wall-clock ``timeout`` passes, as its
README runs it.

Settings: solve type ``Speed`` (return the first solution, TRAC-IK's default), ``eps`` = 1e-5 / sqrt(3):
TRAC-IK's eps bounds each component of the twist error (m and rad), so the Euclidean position
error and the rotation angle are within sqrt(3) eps = 1e-5, the board's rung (its default eps of
1e-5 lets answers it accepts fail that rung: 5-14 % of queries on the first board);
timeout = the wrapper's timeout; the start is a random in-limit configuration from the
wrapper's generator (the README's protocol seeds at the middle of the limits; the board's
queries are random poses and every entry starts at random); TRAC-IK's own restarts draw from its
own unseeded RNG and its timeout is wall-clock, so its outcomes vary run to run (compare them by
timing rules).

Inside the timed call only pytracik's call, pinned to the caller's core
(:func:`fkopt.adapters.field.cores.pinned`: its two threads share that core, as every entry of the
clock track runs on one core), and the target's quaternion by Shepperd's method on floats
(:func:`fkopt.numerics.rotations.quaternion_xyzw1`, a few microseconds; the first wrapper's scipy conversion took 50-107 us,
20-35 % of a call).

Quirks worked around: pytracik reads some URDF limits as [0, 0] (the Panda: KDL's URDF parser
misses limits on a root link with an inertia), so the wrapper sets the limits itself from
fkopt's chain; it stores limits as float32, so they are set rounded *inward* to float32 (an
answer at a float32 limit rounded outward would fall outside the URDF limits); the quaternion
argument order is (x, y, z, w) after the position, and the returned vector starts with
the status (> 0: found).
"""
from __future__ import annotations

import math

import numpy as np

from fkopt.errors import FkoptError
from fkopt.adapters.field import FieldIK, arm_urdf
from fkopt.adapters.field.cores import pinned
from fkopt.numerics.rotations import quaternion_xyzw1


class TracIK(FieldIK):
    name = "tracik"
    package = "pytracik"
    EPS = 1e-5 / math.sqrt(3.0)

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        import pytracik

        urdf = arm_urdf(arm)
        self._pt = pytracik
        self._solver = pytracik.TRAC_IK(urdf.base_link, urdf.tip_link, urdf.text, self.timeout, self.EPS, pytracik.Speed)
        if pytracik.get_num_joints(self._solver) != arm.dof:
            raise FkoptError(f"tracik: {urdf.source} {urdf.base_link} -> {urdf.tip_link} has "
                             f"{pytracik.get_num_joints(self._solver)} joints in KDL, {arm.dof} in fkopt")
        lo32 = np.nextafter(self.lo_rad.astype(np.float32), np.float32(np.inf))
        hi32 = np.nextafter(self.hi_rad.astype(np.float32), np.float32(-np.inf))
        pytracik.set_joint_limits(self._solver, lo32.astype(float).tolist(), hi32.astype(float).tolist())
        self.settings.update(urdf=urdf.source, solve_type="Speed", eps=self.EPS, limits="fkopt's, float32 rounded inward",
                             start="uniform in limits (wrapper's generator)", internal_rng="TRAC-IK's own, unseeded",
                             threads="two per call, pinned to the caller's core", quaternion="Shepperd, on floats")

    def solve1(self, T):
        x, y, z, w = quaternion_xyzw1(T.tolist())
        with pinned(whole_process=False):   # per call: only its own two threads
            out = self._pt.ik(self._solver, self.random_start(), T[0, 3], T[1, 3], T[2, 3], x, y, z, w)
        if out[0] <= 0:
            return None, False
        return self.public(out[1:]), True
