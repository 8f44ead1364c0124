"""kinbench v3's physical success measures: errors in metres and radians, computed here.

Every answer is judged from the joints (IK) or the pose (FK of parallel mechanisms) a solver
returned, with fkopt's own FK / inverse map -- never from what the solver says about itself, so
a submission claiming success on a wrong answer is a failure.

IK (:func:`ik_verdicts`): the tip frame F = FK(q) against the target T gives the position
error |p_F - p_T| (m) and the geodesic rotation error, the angle of R_F^T R_T in [0, pi] rad
(:func:`fkopt.numerics.rotations.geodesic_angle`); an answer is a success at rung (e_p, e_r) of
:data:`LADDER` when both are within it and the joints are inside the arm's limits (exactly, no
tolerance: continuous joints are wrapped first). The ladder is the same on every arm: (5 mm,
0.05 rad) and (1 mm, 0.01 rad) as cuRobo reports (Sundaralingam et al. 2023), (1e-5 m, 1e-5 rad)
as TRAC-IK's default epsilon (Beeson and Ames 2015), and (1e-8 m, 1e-8 rad).

FK of parallel mechanisms (:func:`fk_verdicts`): the returned pose against the generating pose
(position in m, rotation geodesic in rad) and the leg residual |L(x) - L| / L per leg (the
inverse map L(x) of the mechanism, relative to each leg's length). An answer whose legs solve
the equations (residual within the rung's position tolerance per metre of leg) but whose pose
is not the generating one is in *another assembly mode*: it solves the problem as posed and is
counted separately (``other_mode``), not as a success at the generating pose.
"""
from __future__ import annotations

import numpy as np

from fkopt.numerics.rotations import geodesic_angle, to_array, zyx

#: (position m, rotation rad) rungs, loosest first.
LADDER = ((5e-3, 0.05), (1e-3, 0.01), (1e-5, 1e-5), (1e-8, 1e-8))


def rung_label(rung) -> str:
    """Column label of a rung: ``5mm_0.05rad``, ``1e-05m_1e-05rad``."""
    p, r = rung
    pos = f"{p * 1e3:g}mm" if p >= 1e-3 else f"{p:g}m"
    return f"{pos}_{r:g}rad"


def _soa(R: np.ndarray):
    return tuple(tuple(R[..., i, j] for j in range(3)) for i in range(3))


def frame_errors(F: np.ndarray, T: np.ndarray, length_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Position error (m) and geodesic rotation error (rad) of frames F against targets T, both
    (..., 4, 4) with lengths in the arm's unit; ``length_scale`` = that unit per metre (1000 for
    mm)."""
    pe = np.linalg.norm(F[..., :3, 3] - T[..., :3, 3], axis=-1) / length_scale
    return pe, geodesic_angle(_soa(F[..., :3, :3]), _soa(T[..., :3, :3]))


def length_scale(arm) -> float:
    """The arm's length unit per metre: URDF arms are in m, DH arms may be in mm."""
    units = getattr(arm, "pose_units", ("m",))
    return {"m": 1.0, "mm": 1000.0}.get(units[0], 1.0)


def in_limits(arm, joints: np.ndarray) -> np.ndarray:
    """Rows of joints (public units) inside the arm's limits, exactly; continuous joints are
    wrapped into [-180, 180) first (any angle of them is the same configuration)."""
    q = np.array(joints, dtype=float)
    per = arm.periodic_mask()
    q[..., per] = (q[..., per] + 180.0) % 360.0 - 180.0
    lo, hi = arm.bounds[:, 0], arm.bounds[:, 1]
    return np.all((q >= lo) & (q <= hi), axis=-1)


def ik_verdicts(arm, joints: np.ndarray, targets: np.ndarray, ladder=LADDER) -> dict[str, np.ndarray]:
    """Per query: ``position_m``, ``rotation_rad`` (inf where no answer: NaN joints),
    ``in_limits``, and ``success`` (n, len(ladder)) -- both errors within the rung and joints
    inside the limits. ``targets`` (n, 4, 4) in the arm's length unit."""
    joints = np.asarray(joints, dtype=float)
    answered = np.all(np.isfinite(joints), axis=-1)
    q = np.where(answered[:, None], joints, arm.bounds.mean(axis=1))
    pe, re = frame_errors(arm.fk_matrix(q), targets, length_scale(arm))
    pe, re = np.where(answered, pe, np.inf), np.where(answered, re, np.inf)
    lim = answered & in_limits(arm, q)
    success = np.stack([(pe <= p) & (re <= r) & lim for p, r in ladder], axis=-1)
    return {"position_m": pe, "rotation_rad": re, "in_limits": lim, "success": success}


def fk_verdicts(mechanism, poses: np.ndarray, generating: np.ndarray, legs: np.ndarray,
                ladder=LADDER) -> dict[str, np.ndarray]:
    """FK answers ``poses`` (n, 6: x, y, z in the mechanism's length unit, then its angles in
    deg) against the ``generating`` poses whose leg lengths are ``legs`` (n, legs). Returns
    ``position_m``, ``rotation_rad``, ``leg_residual`` (max over legs of |L(x) - L| / L),
    ``success`` (n, rungs: pose within the rung) and ``other_mode`` (n, rungs: the legs solved to
    the rung's position tolerance per metre of leg, the pose not the generating one)."""
    poses = np.asarray(poses, dtype=float)
    answered = np.all(np.isfinite(poses), axis=-1)
    x = np.where(answered[:, None], poses, generating)
    scale = {"m": 1.0, "mm": 1000.0}.get(mechanism.pose_units[0], 1.0)
    F, G = _pose_frames(x), _pose_frames(generating)
    pe, re = frame_errors(F, G, scale)
    leg = np.max(np.abs(mechanism.ik(x) - legs) / np.abs(legs), axis=-1)
    pe, re, leg = (np.where(answered, v, np.inf) for v in (pe, re, leg))
    success = np.stack([(pe <= p) & (re <= r) for p, r in ladder], axis=-1)
    solves = np.stack([leg <= p for p, _ in ladder], axis=-1)
    return {"position_m": pe, "rotation_rad": re, "leg_residual": leg, "success": success,
            "other_mode": solves & ~success}


def _pose_frames(x: np.ndarray) -> np.ndarray:
    """4x4 frames of parallel-mechanism poses (x, y, z, alpha, beta, gamma deg) with
    R = Rz(gamma) Ry(beta) Rx(alpha) (:func:`fkopt.numerics.rotations.zyx`, the convention of every
    6-DOF parallel mechanism in fkopt)."""
    T = np.zeros(x.shape[:-1] + (4, 4))
    T[..., :3, :3] = to_array(zyx(*np.radians(np.moveaxis(x[..., 3:6], -1, 0))))
    T[..., :3, 3] = x[..., :3]
    T[..., 3, 3] = 1.0
    return T
