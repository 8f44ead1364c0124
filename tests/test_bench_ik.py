"""fkopt.tools.bench.ik_arms, ik_one_pose, ik_batch: the IK sections' independent check (pinocchio's
FK; rtb's DHRobot for the DH arm) and their rows, on the UR5 of example-robot-data and the wang7dof
arm (no timing is asserted)."""
import numpy as np
import pytest



@pytest.fixture(scope="module")
def ur5():
    pytest.importorskip("pinocchio")
    pytest.importorskip("roboticstoolbox")
    from fkopt.mechanisms import urdf
    if urdf.example_robots_folder() is None:
        pytest.skip("example-robot-data is not installed")
    from fkopt.tools.bench.ik_arms import Arm
    return Arm("ur5", 4, 7)


def test_pinocchio_check_accepts_the_drawn_joints_and_rejects_wrong_ones(ur5):
    assert ur5.problem() is None
    for k in range(4):
        assert ur5.verified(ur5.Q[k], k)
        off = ur5.Q[k].copy()
        off[0] += 1e-3                                   # 1e-3 deg at the base: > 1e-6 m at the tip
        assert not ur5.verified(off, k)
        assert not ur5.verified(np.full(ur5.m.dof, np.nan), k)
    q = ur5.Q[0].copy()
    q[1] = ur5.m.bounds[1, 1] + 1e-6                     # outside the limits, whatever its pose
    assert not ur5.verified(q, 0)


@pytest.fixture(scope="module")
def wang7dof():
    pytest.importorskip("pinocchio")
    pytest.importorskip("roboticstoolbox")
    from fkopt.tools.bench.ik_arms import Arm
    return Arm("wang7dof", 4, 7)


def test_the_dh_arm_is_checked_by_rtbs_dhrobot_in_metres_and_rejects_wrong_or_out_of_limit_joints(wang7dof):
    a = wang7dof
    assert a.problem() is None and a.check.name == "rtb DHRobot FK" and a.tol == (1e-3, 1e-6)   # mm
    T = a.m.fk_matrix(a.Q)
    assert np.abs(T[:, :3, 3] / 1000 - a.T[:, :3, 3]).max() < 1e-12      # fkopt's mm, rtb's m
    for k in range(4):
        assert a.verified(a.Q[k], k)
        off = a.Q[k].copy()
        off[3] += 1e-3
        assert not a.verified(off, k)
    q = a.Q[0].copy()
    q[0] += 360.0                                        # continuous q1: the same configuration
    assert a.verified(q, 0)
    q = a.Q[0].copy()
    q[6] = a.m.bounds[6, 1] + 1e-6
    assert not a.verified(q, 0)


def test_frame_errors_of_a_known_rotation_and_offset():
    from fkopt.tools.bench.ik_arms import frame_errors
    T = np.eye(4)
    U = np.eye(4)
    a = 1e-7
    U[:3, :3] = [[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]]
    U[:3, 3] = [3e-7, 4e-7, 0]
    pe, re = frame_errors(T, U)
    assert pe == pytest.approx(5e-7, rel=1e-9) and re == pytest.approx(a, rel=1e-6)


def test_ik_sections_report_every_arm_ratios_and_verified_counts(ur5, monkeypatch):
    from fkopt.tools.bench import ik_batch, ik_one_pose
    from fkopt.tools.bench.measuring import Rows
    for section in (ik_one_pose, ik_batch):
        monkeypatch.setattr(section, "QUICK_ARMS", ("ur5", "wang7dof"))
    rows, msgs = Rows(), []
    ik_one_pose.bench_ik_one_pose(rows, True, msgs)
    ik_batch.bench_ik_batch(rows, True, msgs)
    got = {(r["section"], r["item"]): r for r in rows.rows}
    for sec, n in (("ik-one-pose", 20), ("ik-batch", 200)):
        for arm in ("ur5", "wang7dof"):
            r = got[(sec, arm)]
            assert r["unit"] == "x rtb" and np.isfinite(r["value"]) and r["value"] > 0
            assert f"fkopt {n}/{n}" in r["note"] or f"fkopt {n - 1}/{n}" in r["note"]
        assert (sec, "median over arms") in got and (sec, "largest") in got
    assert got[("ik-one-pose", "prepared / fkopt.inverse")]["unit"] == "x"
    assert got[("ik-one-pose", "cold: prepared / fkopt.inverse")]["note"].startswith("ur5, 20 poses")
    assert "same joints as the solver 20/20" in got[("ik-one-pose", "ur5")]["note"]
    assert "rtb DHRobot FK" in got[("ik-batch", "wang7dof")]["note"]
    assert got[("ik-batch", "ur5")]["note"].endswith("fkopt reported solved but not: 0")
    # issue 38: the rates of the batch, wall and per CPU-second, with the load they were measured under
    for arm in ("ur5", "wang7dof"):
        wall, cpu = got[("ik-batch", f"{arm} IK/s wall")], got[("ik-batch", f"{arm} IK per CPU-second")]
        assert wall["unit"] == cpu["unit"] == "IK/s" and wall["value"] > 0 and cpu["value"] > 0
        assert "load average" in wall["note"] and "verified" in wall["note"]
    assert "load average" in got[("ik-one-pose", "median over arms")]["note"]
    assert got[("ik-one-pose", "median over arms")]["note"].startswith("fkopt.inverse(arm, pose) per call")
    assert ("ik-one-pose", "prepared solver: median over arms") in got
    assert not msgs
