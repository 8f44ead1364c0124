"""The field's entries of kinbench's ``all-solutions`` and ``paths`` tracks
(:mod:`fkopt.kinbench.solution_sets`, :mod:`fkopt.kinbench.paths`): the board's wrappers (EAIK,
roboticstoolbox's ``ik_LM``, TRAC-IK) called as their users call them today for every solution
of a pose and for a path.

**All solutions** (``solutions(T) -> (k, dof)``, every answer the entry gives for one tip frame,
public units):

* ``eaik-all`` -- EAIK's exact (not least-squares) solutions inside the limits
  (:meth:`fkopt.adapters.field.eaik.EAIK.solutions`), one analytic call;
* ``rtb-ik_LM-restarts`` and ``tracik-restarts`` -- the board's one-answer call (a random
  in-limit start from the wrapper's generator, the board's settings) repeated until the time
  budget has passed, every answer the package accepted kept: "restart from another q0", what the
  numeric libraries answer when asked for every solution. The budget is the track's (fkopt's
  median time per pose on the arm, measured first in the same job): the same time, not the same
  number of calls. TRAC-IK's own timeout is the budget, so its last call may end after it.

**Paths** (``path(T (w, 4, 4), start (dof,)) -> (w, dof)``): each waypoint's call seeded with
the previous answer, as MoveIt's Cartesian paths call KDL or TRAC-IK: rtb's ``ik_LM`` with ``q0`` =
the previous answer (when that search fails rtb's further searches start from its own random
starts, ``slimit`` as on the board); TRAC-IK with the previous answer as its seed and the track's
timeout (MoveIt's default ``kinematics_solver_timeout``, 5 ms). A waypoint without an answer
keeps the previous joints (MoveIt stops the path there; the track fails the path either way).

TRAC-IK's eps on both tracks: the board's rule (docs/kinbench.md, "Outside entries": the track's
tolerance / sqrt(3) per twist component, so that the Euclidean position error and the rotation
angle are within it) at these tracks' tolerance of 1e-6 m / 1e-6 rad: 1e-6 / sqrt(3).

**Locked joints** (a 7-joint arm on the all-solutions track, one joint locked in every entry):
the outside entries read the 6-joint chain left, :func:`locked_arm` (the URDF written from fkopt's
chain with that joint made fixed at its value, checked against the arm's FK).
"""
from __future__ import annotations

import math
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from fkopt.adapters.field.cores import pinned
from fkopt.adapters.field.eaik import EAIK
from fkopt.adapters.field.rtb import RtbLM
from fkopt.adapters.field.tracik import TracIK
from fkopt.errors import FkoptError
from fkopt.mechanisms.urdf import URDFArm
from fkopt.mechanisms.urdf_writer import chain_urdf
from fkopt.numerics import rotations
from fkopt.numerics.rotations import quaternion_xyzw1

#: The tracks' tolerance (m, rad): TRAC-IK's eps follows from it by the board's rule.
TRACK_TOL = 1e-6


def locked_arm(arm, fixed: dict[str, float]):
    """The arm ``arm`` with the joints of ``fixed`` ({name: public value}) locked: a URDF arm of
    the remaining joints, read from the URDF written from fkopt's chain
    (:func:`fkopt.mechanisms.urdf_writer.chain_urdf`) with each locked joint made fixed, its
    rotation at the value folded into the joint's origin; refused with one line when its FK
    differs from ``arm``'s (1e-9) at a configuration inside the limits."""
    from scipy.spatial.transform import Rotation

    w = chain_urdf(arm)
    root = ET.fromstring(w.text)
    index = {}
    for name, value in fixed.items():
        if name not in arm.unknown_names or arm.unknown_units[arm.unknown_names.index(name)] != "deg":
            raise FkoptError(f"{arm.name}: cannot lock '{name}' (allowed: its revolute joints "
                             f"{', '.join(n for n, u in zip(arm.unknown_names, arm.unknown_units) if u == 'deg')})")
        k = arm.unknown_names.index(name)
        index[k] = float(value)
        j = root.find(f"joint[@name='{w.joint_names[k]}']")
        o, axis = j.find("origin"), j.find("axis")
        R = Rotation.from_euler("xyz", [float(v) for v in o.get("rpy").split()]).as_matrix() \
            @ rotations.rz1(float(axis.get("xyz").split()[2]) * math.radians(float(value)))
        o.set("rpy", " ".join(repr(float(a)) for a in rotations.zyx_angles1(R)))
        j.set("type", "fixed")
        j.remove(axis)
        if j.find("limit") is not None:
            j.remove(j.find("limit"))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "locked.urdf"
        path.write_text(ET.tostring(root, encoding="unicode"), encoding="utf-8")
        six = URDFArm(file=str(path), base=w.base_link, tip=w.tip_link)
    q = arm.bounds[:, 0] + 0.37 * (arm.bounds[:, 1] - arm.bounds[:, 0])
    for k, v in index.items():
        q[k] = v
    free = [k for k in range(arm.dof) if k not in index]
    gap = float(np.abs(six.fk_matrix(q[free][None]) - arm.fk_matrix(q[None])).max())
    if not gap <= 1e-9:
        raise FkoptError(f"{arm.name}: the chain with {', '.join(fixed)} locked differs from the arm's FK by {gap:.2g}")
    return six


class _Locking:
    """Mixin: an entry built on ``arm`` with ``fixed`` joints reads :func:`locked_arm`'s chain."""

    def __init__(self, arm, *, timeout, rng, fixed=None):
        super().__init__(locked_arm(arm, fixed) if fixed else arm, timeout=timeout, rng=rng)
        if fixed:
            self.settings["locked"] = {k: float(v) for k, v in fixed.items()}


class EAIKAll(_Locking, EAIK):
    name = "eaik-all"

    def solutions(self, T) -> np.ndarray:
        s = super().solutions(T)
        return s.joints[~s.least_squares & s.in_limits]


def _until(budget: float, call) -> list:
    """Every answer of ``call()`` (joints or None) until ``budget`` seconds have passed (at least one call)."""
    out, end = [], time.perf_counter() + budget
    while True:
        q = call()
        if q is not None:
            out.append(q)
        if time.perf_counter() >= end:
            return out


class RtbLMRestarts(_Locking, RtbLM):
    name = "rtb-ik_LM-restarts"

    def __init__(self, arm, *, timeout, rng, fixed=None):
        super().__init__(arm, timeout=timeout, rng=rng, fixed=fixed)
        self.settings.update(restarts="the board's call from a random in-limit start, repeated until the budget "
                             "(timeout_s) has passed; every answer rtb accepted kept", wall_clock_limit=True)

    def solutions(self, T) -> np.ndarray:
        def one():
            q, ok = self.solve1(T)
            return q if ok else None
        return np.array(_until(self.timeout, one)).reshape(-1, self.arm.dof)


class TracIKRestarts(_Locking, TracIK):
    name = "tracik-restarts"
    EPS = TRACK_TOL / math.sqrt(3.0)

    def __init__(self, arm, *, timeout, rng, fixed=None):
        super().__init__(arm, timeout=timeout, rng=rng, fixed=fixed)
        self.settings.update(restarts="the board's call from a random in-limit start (TRAC-IK's timeout: the "
                             "budget), repeated until the budget has passed; every answer it accepted kept")

    def solutions(self, T) -> np.ndarray:
        def one():
            q, ok = self.solve1(T)
            return q if ok else None
        return np.array(_until(self.timeout, one)).reshape(-1, self.arm.dof)


class RtbLMSeeded(RtbLM):
    name = "rtb-ik_LM-seeded"

    def __init__(self, arm, *, timeout, rng, fixed=None):
        super().__init__(arm, timeout=timeout, rng=rng)
        self.settings.update(q0="the previous waypoint's answer (the path's start for the first)")

    def path(self, T: np.ndarray, start: np.ndarray) -> np.ndarray:
        q = np.asarray(start, float) * self.arm._to_si
        out = np.empty((len(T), self.arm.dof))
        for k, t in enumerate(T):
            sol = self._call(t, q0=q, ilimit=self.ILIMIT, slimit=self.SLIMIT, tol=self.TOL, joint_limits=True)
            if sol.success:
                q = np.asarray(sol.q, dtype=float)
            out[k] = self.public(q)
        return out


class TracIKSeeded(TracIK):
    name = "tracik-seeded"
    EPS = TRACK_TOL / math.sqrt(3.0)

    def __init__(self, arm, *, timeout, rng, fixed=None):
        super().__init__(arm, timeout=timeout, rng=rng)
        self.settings.update(start="the previous waypoint's answer (the path's start for the first)")

    def path(self, T: np.ndarray, start: np.ndarray) -> np.ndarray:
        q = (np.asarray(start, float) * self.arm._to_si).tolist()
        out = np.empty((len(T), self.arm.dof))
        with pinned(whole_process=False):    # as TracIK.solve1: its own two threads on the caller's core
            for k, t in enumerate(T):
                x, y, z, w = quaternion_xyzw1(t.tolist())
                got = self._pt.ik(self._solver, q, t[0, 3], t[1, 3], t[2, 3], x, y, z, w)
                if got[0] > 0:
                    q = list(got[1:])
                out[k] = self.public(q)
        return out
