"""The scalable chain family dh-chain (fkopt.mechanisms.dh_chain): seeded, non-degenerate, and its FK
equal to roboticstoolbox's DHRobot of the same table."""
import numpy as np
import pytest

import fkopt
from fkopt.errors import FkoptError
from fkopt.mechanisms.dh_chain import LIMIT, REACH, TWIST_RANGE, chain_table


def test_a_member_is_a_function_of_joints_and_seed_only():
    a, b = fkopt.mechanism("dh-chain", joints=12, seed=3), fkopt.mechanism("dh-chain", joints=12, seed=3)
    assert a.kinematic_key() == b.kinematic_key()
    assert a.kinematic_key() != fkopt.mechanism("dh-chain", joints=12, seed=4).kinematic_key()
    assert fkopt.mechanism("dh-chain", joints=30).dof == 30 and fkopt.mechanism("dh-chain").dof == 6


@pytest.mark.parametrize("n", [3, 6, 7, 12, 20, 30])
def test_tables_follow_the_documented_ranges_and_chains_are_not_degenerate(n):
    t = chain_table(n, 0)
    alpha = np.abs(t["alpha"])
    assert np.all((alpha >= TWIST_RANGE[0]) & (alpha <= TWIST_RANGE[1]))
    assert np.hypot(t["a"], t["d"]).sum() == pytest.approx(REACH)
    arm = fkopt.mechanism("dh-chain", joints=n, seed=0)
    assert np.array_equal(arm.bounds, np.array([[-LIMIT, LIMIT]] * n))
    q = arm.bounds[:, 0] + np.random.default_rng(1).random((20, n)) * np.diff(arm.bounds).ravel()
    _, _, J = arm.frame_jacobian(q)
    assert np.all(np.linalg.matrix_rank(J, tol=1e-8) == min(6, n))      # every joint adds a direction


@pytest.mark.parametrize("n", [3, 8, 25])
def test_fk_equals_roboticstoolbox_dhrobot_of_the_same_table(n):
    rtb = pytest.importorskip("roboticstoolbox")
    t = chain_table(n, 7)
    robot = rtb.DHRobot([rtb.RevoluteDH(a=a / 1000, alpha=np.radians(al), d=d / 1000, offset=np.radians(o))
                         for a, al, d, o in zip(t["a"], t["alpha"], t["d"], t["theta_offset"])])
    arm = fkopt.mechanism("dh-chain", joints=n, seed=7)
    q = arm.bounds[:, 0] + np.random.default_rng(2).random((10, n)) * np.diff(arm.bounds).ravel()
    p, R = arm.frame(q)
    for i, row in enumerate(q):
        T = robot.fkine(np.radians(row)).A
        assert np.abs(np.array([x[i] for x in p]) - 1000 * T[:3, 3]).max() < 1e-9
        assert np.abs(np.array([[c[i] for c in r] for r in R]) - T[:3, :3]).max() < 1e-12


def test_bad_geometry_is_one_line():
    with pytest.raises(FkoptError, match="dh-chain geometry.joints") as err:
        fkopt.mechanism("dh-chain", joints=0)
    assert "\n" not in str(err.value)
    with pytest.raises(FkoptError, match="dh-chain geometry"):
        fkopt.mechanism("dh-chain", a=[1, 2])
