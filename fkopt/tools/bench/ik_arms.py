"""The arms of ``fkopt bench --section ik-one-pose`` (:mod:`.ik_one_pose`) and ``--section ik-batch``
(:mod:`.ik_batch`), where ``fkopt.inverse`` runs on real arms
beside roboticstoolbox's ETS ``ik_LM`` (C++), the answers of both verified by an FK independent of
fkopt's: pinocchio's for the URDF arms, roboticstoolbox's ``DHRobot`` for the DH arm.

Arms (:data:`ARMS`): chains of :data:`fkopt.mechanisms.urdf.EXAMPLE_ROBOTS` in example-robot-data
(Panda, UR3, UR5, UR10, Kinova j2s6s200, xArm7, Unitree Z1, Baxter's two arms, PR2's left arm,
Romeo's left arm, TIAGo's arm, Talos's left arm, Unitree G1's left arm; 6 and 7 joints) and the
wang7dof arm (:data:`DH_ARM`): fkopt's DH model ``7dof-arm`` in mm, checked by rtb's ``DHRobot`` of
the paper's DH table (:data:`fkopt.mechanisms.dh_arm.WANG7DOF`, standard DH, in m), rtb's ETS read
from ``mechanisms/data/wang7dof.urdf`` (its q1 is continuous there: answers wrapped into
[-180, 180) deg before the limits are checked). An arm whose rtb ETS disagrees with the check's FK
when read (iCub's arm: rtb misreads its URDF) or whose check disagrees with fkopt's FK is left out
with a message.

Per arm ``n`` poses: joints uniform inside the limits (generator seeded per arm), target frame =
the independent FK of those joints (not fkopt's, not rtb's ETS). Tolerance 1e-6 m and 1e-6 rad for
both: fkopt gets ``tol=(1e-6, 1e-6)`` in the arm's length unit (1e-3 mm for the DH arm); rtb stops
at E = 1/2 |e|^2 < tol (e = position error, rotation vector) and gets tol = 1/2 (1e-6)^2, which
implies both (and is no looser). rtb: ``ilimit=30``, ``slimit=100`` (its defaults),
``joint_limits=True``, first start q0 uniform in the limits from a seeded generator. An answer
counts as solved only when the independent FK of it (continuous joints wrapped) is within both
tolerances of the target and it is inside the limits; neither library's own verdict is counted
(``ik-batch`` also reports how many of fkopt's answers it called solved but were not).

Timings are wall-clock on whatever else the machine is doing: read the ratios, not the times.
Skipped with a message when roboticstoolbox-python or pinocchio is missing; without
example-robot-data only the DH arm is measured.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

import fkopt
from fkopt.adapters.field import ArmURDF
from fkopt.adapters.field.rtb import chain_ets
from fkopt.mechanisms import urdf
from fkopt.mechanisms.dh_arm import WANG7DOF

ARMS = ("panda", "ur3", "ur5", "ur10", "kinova", "xarm7", "z1", "baxter-left", "baxter-right", "pr2-left",
        "romeo-left", "tiago", "talos-left", "g1-left", "icub-left", "wang7dof")
#: Quick mode: a subset (6 and 7 joints, the slowest arms of the last measurement included).
QUICK_ARMS = ("panda", "ur5", "ur10", "kinova", "xarm7", "romeo-left", "wang7dof")
#: The DH arm: fkopt's ``7dof-arm`` (mm), checked by rtb's DHRobot of the paper's table.
DH_ARM = "wang7dof"
TOL = (1e-6, 1e-6)                # m, rad
RTB_TOL = 0.5 * TOL[0] ** 2       # E = 1/2 |e|^2 < tol  =>  |e| < 1e-6, both errors below their tolerances


class PinocchioFK:
    """Frame of the tip in the base of an arm's URDF chain by pinocchio's own reader and FK
    (Carpentier et al., SII 2019): the independent check of every answer here. Continuous joints
    are pinocchio's (cos, sin) pairs; joints outside the chain stay at pinocchio's neutral."""

    name = "pinocchio FK"

    def __init__(self, arm):
        import pinocchio as pin
        self.pin = pin
        self.model = pin.buildModelFromUrdf(str(arm.path))
        self.data = self.model.createData()
        self.base = self.model.getFrameId(arm.base_link, pin.FrameType.BODY)
        self.tip = self.model.getFrameId(arm.tip_link, pin.FrameType.BODY)
        js = [self.model.joints[self.model.getJointId(n)] for n in arm.joint_names]
        self.idx = [(j.idx_q, j.nq) for j in js]
        self.x0 = self.pin.neutral(self.model)

    def frame(self, q_rad) -> np.ndarray:
        """4x4 tip-in-base frame at chain joints ``q_rad`` (n,), SI units."""
        x = self.x0.copy()
        for (i, nq), v in zip(self.idx, q_rad):
            if nq == 2:
                x[i], x[i + 1] = math.cos(v), math.sin(v)
            else:
                x[i] = v
        self.pin.framesForwardKinematics(self.model, self.data, x)
        return (self.data.oMf[self.base].inverse() * self.data.oMf[self.tip]).homogeneous


class DHRobotFK:
    """Frame of the tip of wang7dof's arm by roboticstoolbox's ``DHRobot`` (Corke and Haviland,
    ICRA 2021) of the paper's standard DH table (:data:`fkopt.mechanisms.dh_arm.WANG7DOF`, lengths
    in m): the independent check of fkopt's DH model (its own DH code, in mm)."""

    name = "rtb DHRobot FK"

    def __init__(self):
        import roboticstoolbox as rtb
        self.robot = rtb.DHRobot([rtb.RevoluteDH(a=a / 1000, alpha=math.radians(al), d=d / 1000)
                                  for a, al, d in zip(WANG7DOF["a"], WANG7DOF["alpha"], WANG7DOF["d"])])

    def frame(self, q_rad) -> np.ndarray:
        """4x4 tip-in-base frame at joints ``q_rad`` (n,), SI units."""
        return self.robot.fkine(np.asarray(q_rad, dtype=float)).A


def frame_errors(T, Tt) -> tuple[float, float]:
    """(position error, geodesic rotation error in rad) of frame T against target Tt (4x4):
    the angle from atan2(|vee(M - M^T)| / 2, (tr M - 1) / 2), M = R^T Rt, accurate near 0."""
    M = T[:3, :3].T @ Tt[:3, :3]
    s = 0.5 * math.sqrt((M[2, 1] - M[1, 2]) ** 2 + (M[0, 2] - M[2, 0]) ** 2 + (M[1, 0] - M[0, 1]) ** 2)
    c = 0.5 * (M[0, 0] + M[1, 1] + M[2, 2] - 1.0)
    return float(np.linalg.norm(T[:3, 3] - Tt[:3, 3])), math.atan2(s, c)


class Arm:
    """One arm of the bench: fkopt's model, rtb's ETS, the independent check, poses and targets.
    ``scale``: the arm's length unit per m (1000 for the DH arm in mm); ``tol``: :data:`TOL` in it."""

    def __init__(self, name, n, seed):
        self.name = name
        if name == DH_ARM:
            self.m = m = fkopt.mechanism("7dof-arm")
            self.check = DHRobotFK()
            source = ArmURDF.from_file(urdf.DEFAULT_FILE, "link0", "tool")     # fkopt's URDF of the paper's table
            self.scale = 1000.0
            self.periodic = fkopt.mechanism("urdf").periodic_mask()      # the URDF's q1 is continuous
        else:
            self.m = m = urdf.example_robot(name)
            self.check = PinocchioFK(m)
            # example-robot-data's own file as people use it (not a user's: from_file proves it
            # holds nothing xacro would evaluate)
            source = ArmURDF.from_file(m.path, m.base_link, m.tip_link, m.joint_names)
            self.scale = 1.0
            self.periodic = m.periodic_mask()
        self.tol = (TOL[0] * self.scale, TOL[1])
        self.ets, self.rtb_version = chain_ets(source)
        rng = np.random.default_rng(seed)
        self.Q = m.bounds[:, 0] + rng.random((n, m.dof)) * (m.bounds[:, 1] - m.bounds[:, 0])
        self.T = np.array([self.check.frame(np.radians(q)) for q in self.Q])
        self.P = m.fk(self.Q)                                  # the same targets as fkopt's poses
        lo, hi = np.radians(m.bounds[:, 0]), np.radians(m.bounds[:, 1])
        self.q0 = lo + rng.random((n, m.dof)) * (hi - lo)     # rtb's first start per pose

    def fkopt_frame(self, q_deg) -> np.ndarray:
        """fkopt's FK of joints (n, dof) in deg, lengths in m."""
        T = self.m.fk_matrix(q_deg)
        T[..., :3, 3] /= self.scale
        return T

    def problem(self) -> str | None:
        """Why this arm cannot be compared (readers disagree), or None."""
        m = self.m
        if self.ets.n != m.dof:
            return f"{self.name}: rtb's chain has {self.ets.n} joints, fkopt's {m.dof}"
        q = np.radians(self.Q[0])
        mine = self.fkopt_frame(self.Q[:1])[0]
        gap_rtb = np.abs(self.ets.fkine(q).A - self.T[0]).max()
        gap_check = np.abs(self.T[0] - mine).max()
        if not gap_check < 1e-9:
            return f"{self.name}: {self.check.name} differs from fkopt's by {gap_check:.2g} m"
        if not gap_rtb < 1e-9:
            return (f"{self.name}: rtb's ETS FK differs from {self.check.name} and fkopt's by {gap_rtb:.2g} "
                    "(rtb misreads it)")
        return None

    def rtb(self, k):
        sol = self.ets.ik_LM(self.T[k], q0=self.q0[k], ilimit=30, slimit=100, tol=RTB_TOL, joint_limits=True)
        return np.degrees(sol.q if hasattr(sol, "q") else sol[0])

    def verified(self, q_deg, k) -> bool:
        """The independent check of one answer (deg) to pose k: both tolerances, inside the limits."""
        q = np.array(q_deg, dtype=float)
        if not np.isfinite(q).all():
            return False
        q[self.periodic] = (q[self.periodic] + 180.0) % 360.0 - 180.0
        b = self.m.bounds
        if not ((q >= b[:, 0]) & (q <= b[:, 1])).all():
            return False
        pe, re = frame_errors(self.check.frame(np.radians(q)), self.T[k])
        return pe <= TOL[0] and re <= TOL[1]


def arms(names, n, messages):
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import pinocchio  # noqa: F401
            import roboticstoolbox  # noqa: F401
    except Exception as err:
        messages.append(f"ik sections skipped: {type(err).__name__}: {err} (pip install roboticstoolbox-python pin)")
        return []
    if urdf.example_robots_folder() is None:
        messages.append("ik sections: example-robot-data not installed (pip install example-robot-data): "
                        f"the {DH_ARM} arm only")
        names = [k for k in names if k == DH_ARM]
    out = []
    for i, name in enumerate(names):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            a = Arm(name, n, 2026 + i)
        why = a.problem()
        if why:
            messages.append(f"ik sections: {why}; left out")
        else:
            out.append(a)
    return out


def ratio_summary(rows, sec, ratios, target_median, target_max, what, label=""):
    """Two rows of a section: the median over arms of fkopt's time over rtb's and the largest."""
    names = list(ratios)
    r = np.array([ratios[k] for k in names])
    worst = names[int(np.argmax(r))]
    rows.add(sec, f"{label}median over arms", float(np.median(r)), "x rtb",
             f"{what}; {len(r)} arms; target <= {target_median}: {'met' if np.median(r) <= target_median else 'NOT met'}")
    rows.add(sec, f"{label}largest", float(r.max()), "x rtb",
             f"{worst}; target <= {target_max}: {'met' if r.max() <= target_max else 'NOT met'}; "
             f"arms above: {', '.join(k for k in names if ratios[k] > target_max) or 'none'}")
