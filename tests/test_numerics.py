"""The compiled numerics path (numba) held to the numpy/Python reference: the same chain FK and
frame Jacobian to 1e-12, and the same one-pose ``fkopt.inverse`` answers (joints, restarts,
evaluations) bit for bit, on real arms from example-robot-data and the DH arm of wang7dof."""
import numpy as np
import pytest

import fkopt
from fkopt.numerics import InverseOptions, chain as reference
from fkopt.numerics import path as numerics_path
from fkopt.mechanisms.urdf import example_robot, example_robots_folder

compiled = pytest.importorskip("fkopt.numerics.compiled", reason="numba is not installed")
TIPS = {"panda": "panda_hand_tcp", "ur5": "ee_link", "kinova": "j2s6s200_end_effector"}


def arms():
    out = [("7dof-arm", fkopt.mechanism("7dof-arm"))]
    if example_robots_folder() is not None:
        out += [(n, example_robot(n, tip=t)) for n, t in sorted(TIPS.items())]
    return out


def random_joints(m, n, seed):
    rng = np.random.default_rng(seed)
    return m.bounds[:, 0] + rng.random((n, m.dof)) * (m.bounds[:, 1] - m.bounds[:, 0])


@pytest.mark.parametrize("name,arm", arms(), ids=lambda v: v if isinstance(v, str) else "")
def test_compiled_chain_fk_and_jacobian_equal_the_reference(name, arm):
    ch = arm.chain()
    # both paths read the same chain in internal units (rad, m); any values exercise them equally
    for t in np.random.default_rng(1).uniform(-3.0, 3.0, (25, ch.dof)):
        p0, R0, J0 = reference.frame_jacobian1(ch, t.tolist())
        p1, R1, J1 = compiled.frame_jacobian(ch, t)
        assert np.max(np.abs(np.asarray(p0) - p1)) <= 1e-12
        assert np.max(np.abs(np.asarray(R0) - R1)) <= 1e-12
        assert np.max(np.abs(np.asarray(J0) - J1)) <= 1e-12


@pytest.mark.parametrize("name,arm", arms(), ids=lambda v: v if isinstance(v, str) else "")
def test_compiled_one_pose_inverse_gives_the_reference_answers(name, arm):
    targets = arm.fk(random_joints(arm, 8, 2))
    for k in range(8):
        pose = {key: v[k] for key, v in targets.items()} if isinstance(targets, dict) else targets[k]
        a = fkopt.inverse(arm, pose, seed=k, options=InverseOptions(compiled=False))
        b = fkopt.inverse(arm, pose, seed=k, options=InverseOptions(compiled=True))
        assert bool(a.solved) and bool(b.solved)
        assert np.array_equal(a.joints, b.joints)
        assert np.array_equal(a.restarts, b.restarts)
        for key in a.evaluations:
            assert np.array_equal(a.evaluations[key], b.evaluations[key])


def test_the_environment_switch_forces_the_reference(monkeypatch):
    monkeypatch.setenv(numerics_path.ENV, "numpy")
    assert numerics_path.compiled(None) is None
    monkeypatch.setenv(numerics_path.ENV, "bogus")
    with pytest.raises(fkopt.errors.FkoptError, match="allowed values auto, numpy, compiled"):
        numerics_path.requested()


@pytest.mark.parametrize("name,arm", arms(), ids=lambda v: v if isinstance(v, str) else "")
def test_compiled_batch_rows_are_the_one_pose_reference_answers(name, arm):
    """A batch through the compiled path solves every row as its one-pose call: the same joints,
    restarts and evaluations as the Python reference for that pose alone, whatever the batch."""
    targets = arm.fk(random_joints(arm, 6, 3))
    b = fkopt.inverse(arm, targets, seed=4, options=InverseOptions(compiled=True))
    assert b.joints.shape == (6, arm.dof) and b.solved.all()
    for k in range(6):
        a = fkopt.inverse(arm, targets[k], seed=4, options=InverseOptions(compiled=False))
        assert np.array_equal(a.joints, b.joints[k])
        assert int(a.restarts) == int(b.restarts[k])
        assert int(a.evaluations["jacobian"]) == int(b.evaluations["jacobian"][k])
        assert float(a.position_error) == pytest.approx(float(b.position_error[k]), abs=1e-12)
        assert float(a.rotation_error) == pytest.approx(float(b.rotation_error[k]), abs=1e-12)
