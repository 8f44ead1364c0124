"""IK along a path on one branch: fkopt.inverse_path (fkopt/kinematics/branches.py)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import fkopt
from fkopt.errors import FkoptError

SUITES = Path(__file__).resolve().parents[1] / "configs" / "suites"


def ur5(**geometry):
    return fkopt.mechanism("urdf", file=str(SUITES / "robots" / "ur5.urdf"), base="base_link", tip="tool0",
                           **geometry)


def segment(q0, q1, w=100):
    return q0 + np.linspace(0.0, 1.0, w)[:, None] * (np.asarray(q1) - q0)


def test_a_joint_space_segment_is_followed_on_its_branch_without_a_break():
    """FK of a joint-space segment (steps of at most 0.02 rad): every waypoint solved, no break,
    no joint step above 0.05 rad, and the answers are the generating joints (the branch of the
    start), where seeding each waypoint with a fresh one-answer IK flips between branches."""
    m = ur5()
    rng = np.random.default_rng(3)
    q0 = rng.uniform(-120, 120, 6)
    Q = segment(q0, q0 + rng.uniform(-60, 60, 6))
    assert np.abs(np.diff(np.radians(Q), axis=0)).max() <= 0.02
    r = fkopt.inverse_path(m, m.fk_matrix(Q), start=Q[0])
    assert r.breaks == [] and r.solved.all() and r.joints.shape == Q.shape
    assert np.abs(np.diff(np.radians(r.joints), axis=0)).max() <= 0.05
    assert np.abs(r.joints - Q).max() < 1e-6
    assert (r.position_error <= 1e-9).all() and (r.rotation_error <= 1e-9).all()
    fresh = fkopt.inverse(m, m.fk_matrix(Q)).joints                        # one answer per pose, no seed
    assert np.abs(np.diff(np.radians(fresh), axis=0)).max() > 0.05           # what branch following avoids


def test_an_unreachable_waypoint_is_a_break_that_says_so_and_the_path_goes_on():
    m = ur5()
    Q = segment(np.array([10.0, -70, 60, 20, 50, 30]), [40.0, -50, 80, 0, 70, 10])
    T = m.fk_matrix(Q)
    T[50, :3, 3] = [5.0, 0.0, 0.0]
    r = fkopt.inverse_path(m, T, start=Q[0])
    assert [(k, why) for k, why, _ in r.breaks] == [(50, "unreachable")]
    assert not r.solved[50] and r.solved[np.arange(100) != 50].all()
    assert np.abs(r.joints[51:] - Q[51:]).max() < 1e-6


def test_a_joint_limit_on_the_way_is_a_break_with_its_reason_never_a_silent_flip():
    """The elbow limited to [-180, 100] deg: the segment takes it from 90 to 110; the branch reaches
    the waypoints past 100 only outside the limits, so the path breaks there (reason 'joint limit'),
    re-seats on another solution in the limits, and every later step is small again."""
    m = ur5(bounds={"elbow_joint": [-180.0, 100.0]})
    Q = segment(np.array([10.0, -70, 90, 20, 50, 30]), [10.0, -70, 110, 20, 50, 30], 50)
    r = fkopt.inverse_path(m, m.fk_matrix(Q), start=Q[0])
    k = int(np.flatnonzero(Q[:, 2] > 100.0)[0])
    assert r.breaks and r.breaks[0][0] == k and r.breaks[0][1] == "joint limit"
    assert "elbow_joint" in r.breaks[0][2]
    assert m.in_bounds(r.joints).all() and r.solved.all()
    steps = np.abs(np.diff(np.radians(r.joints), axis=0)).max(axis=1)
    jumps = np.flatnonzero(steps > 0.05) + 1
    assert set(jumps.tolist()) <= {b[0] for b in r.breaks}                 # every jump is a stated break


def test_paths_in_a_batch_are_each_their_own_call():
    m = ur5()
    Qa = segment(np.array([10.0, -70, 60, 20, 50, 30]), [40.0, -50, 80, 0, 70, 10], 30)
    Qb = segment(np.array([-30.0, -100, 40, 60, -40, 0]), [-10.0, -80, 70, 20, -70, 40], 30)
    T = np.stack([m.fk_matrix(Qa), m.fk_matrix(Qb)])
    both = fkopt.inverse_path(m, T, start=np.stack([Qa[0], Qb[0]]))
    assert both.joints.shape == (2, 30, 6) and both.breaks == [[], []]
    for i, Q in enumerate((Qa, Qb)):
        alone = fkopt.inverse_path(m, T[i], start=Q[0])
        assert np.array_equal(alone.joints, both.joints[i])


def test_bad_input_is_one_line():
    m = ur5()
    T = m.fk_matrix(segment(np.array([10.0, -70, 60, 20, 50, 30]), [40.0, -50, 80, 0, 70, 10], 5))
    with pytest.raises(FkoptError, match="start: joints must be inside the limits"):
        fkopt.inverse_path(m, T, start=[0, 0, 400, 0, 0, 0])
    with pytest.raises(FkoptError, match="max_step: expected a positive number"):
        fkopt.inverse_path(m, T, start=[0] * 6, max_step=0)
    with pytest.raises(FkoptError, match="one start per path"):
        fkopt.inverse_path(m, np.stack([T, T]), start=np.zeros((3, 6)))
    with pytest.raises(FkoptError, match="expected waypoints"):
        fkopt.inverse_path(m, T[0], start=[0] * 6)


def test_an_elbow_passing_straight_keeps_its_branch():
    """The UR5's elbow crosses 0 (the arm straight, where the elbow-up and elbow-down branches
    meet): started from the previous answer alone, the loop was as near to the other branch and
    took it with small steps, a silent flip; the predictor (previous step continued) keeps the
    path on its own branch, the generating joints."""
    m = ur5()
    Q = segment(np.array([-212.0, -277.1, 4.5, -71.6, 6.0, 96.4]), [-203.0, -276.5, -6.0, -64.0, 14.0, 98.8])
    assert np.abs(np.diff(np.radians(Q), axis=0)).max() <= 0.02 and Q[0, 2] > 0 > Q[-1, 2]
    r = fkopt.inverse_path(m, m.fk_matrix(Q), start=Q[0])
    assert r.breaks == [] and np.abs(r.joints - Q).max() < 1e-6


def test_waypoints_whose_solutions_all_lie_outside_the_limits_are_joint_limit_breaks_not_unreachable():
    """The base limited to [-10, 10] deg and the path turning it from 0 to 30 deg: past 10 deg
    every solution of a waypoint needs the base outside its limits (the other shoulder side too),
    so those waypoints are 'joint limit' breaks with the previous joints kept, never 'unreachable'."""
    m = ur5(bounds={"shoulder_pan_joint": [-10.0, 10.0]})
    Q = segment(np.array([0.0, -70, 60, 20, 50, 30]), [30.0, -70, 60, 20, 50, 30], 40)
    r = fkopt.inverse_path(m, m.fk_matrix(Q), start=Q[0])
    past = np.flatnonzero(Q[:, 0] > 10.0 + 1e-9)
    assert [k for k, _, _ in r.breaks] == past.tolist()
    assert {why for _, why, _ in r.breaks} == {"joint limit"}
    assert not r.solved[past].any() and r.solved[:past[0]].all() and m.in_bounds(r.joints).all()
