"""The MJCF arm (fkopt.mechanisms.mjcf): FK equals MuJoCo's own mj_kinematics, refusals are one line."""
from pathlib import Path

import numpy as np
import pytest

import fkopt
from fkopt.errors import FkoptError

mujoco = pytest.importorskip("mujoco")


def mj_frames(arm, model, q, base, tip):
    """Tip (p, R) in the base body's frame from mj_kinematics, per row of q (public units)."""
    d = mujoco.MjData(model)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, tip) if tip else -1
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, tip) if tip else -1
    b0 = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, base) if base else 0
    out = []
    for row in q:
        d.qpos[:] = model.qpos0
        si = {n: np.radians(v) if u == "deg" else v for n, v, u in zip(arm.joint_names, row, arm.joint_units)}
        for cj in arm.chain_joints:             # a coupled joint from its master, as the equality says
            j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, cj["name"])
            d.qpos[model.jnt_qposadr[j]] = cj["multiplier"] * si[cj["unknown"]] + cj["offset"]
        mujoco.mj_kinematics(model, d)
        p, R = (d.xpos[body], d.xmat[body]) if body >= 0 else (d.site_xpos[site], d.site_xmat[site])
        R0 = d.xmat[b0].reshape(3, 3)
        out.append((R0.T @ (p - d.xpos[b0]), R0.T @ R.reshape(3, 3)))
    return out


def check_against_mujoco(arm, model, base, tip, rows=20):
    q = arm.bounds[:, 0] + np.random.default_rng(11).random((rows, arm.dof)) * np.diff(arm.bounds).ravel()
    p, R = arm.frame(q)
    for i, (pr, Rr) in enumerate(mj_frames(arm, model, q, base, tip)):
        assert np.abs(np.array([x[i] for x in p]) - pr).max() < 1e-12
        assert np.abs(np.array([[c[i] for c in r] for r in R]) - Rr).max() < 1e-12


def test_default_file_is_wang7dof_and_matches_mj_kinematics_and_the_urdf_arm():
    from fkopt.mechanisms.mjcf import DEFAULT_FILE
    arm, urdf = fkopt.mechanism("mjcf"), fkopt.mechanism("urdf")
    assert arm.joint_names == urdf.joint_names and np.array_equal(arm.bounds, urdf.bounds)
    q = arm.bounds[:, 0] + np.random.default_rng(3).random((30, 7)) * np.diff(arm.bounds).ravel()
    assert np.abs(arm.fk(q) - urdf.fk(q)).max() < 1e-12
    model = mujoco.MjModel.from_xml_path(str(DEFAULT_FILE))
    check_against_mujoco(arm, model, None, "tool")
    check_against_mujoco(fkopt.mechanism("mjcf", tip="tool_site"), model, None, "tool_site")


# an MJCF arm with a slide joint, a hinge anchored off its body and a joint equality (one copy,
# shared with the recorded one-pose answers of tests/inverse_bits)
from inverse_bits.cases import ANCHORED_MJCF as ANCHORED  # noqa: E402



def test_anchors_references_slides_and_joint_equalities_match_mj_kinematics(tmp_path):
    f = tmp_path / "arm.xml"
    f.write_text(ANCHORED)
    arm = fkopt.mechanism("mjcf", file=str(f), base="b0", tip="tcp")
    assert arm.joint_names == ("j1", "j2", "j3", "j4") and list(arm.periodic) == [False, False, True, False]
    assert arm.joint_units == ("deg", "m", "deg", "deg")
    check_against_mujoco(arm, mujoco.MjModel.from_xml_path(str(f)), "b0", "tcp")
    # j5 follows j4 through the equality: q5 = 0.1 - 0.5 q4 (mj_frames sets it so, as MuJoCo's constraint would)
    j5 = next(j for j in arm.chain_joints if j["name"] == "j5")
    assert j5["unknown"] == "j4" and j5["multiplier"] == -0.5 and j5["offset"] == pytest.approx(0.1)
    r = fkopt.inverse(arm, arm.fk(arm.bounds.mean(axis=1)))
    assert r.solved


@pytest.mark.parametrize("xml, match", [
    ('<body name="l1"><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
     '<body name="l2"><joint type="hinge"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></body>',
     "free joint"),
    ('<body name="l1"><joint name="b" type="ball"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>',
     "ball joint"),
    ('<body name="l1"><joint name="s" type="slide"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>',
     "needs a range"),
])
def test_refusals_are_one_line(tmp_path, xml, match):
    f = tmp_path / "bad.xml"
    f.write_text(f"<mujoco><worldbody>{xml}</worldbody></mujoco>")
    with pytest.raises(FkoptError, match=match) as err:
        fkopt.mechanism("mjcf", file=str(f))
    assert "\n" not in str(err.value) and str(f) in str(err.value)


def test_unknown_body_tendon_and_uncompilable_file_are_one_line(tmp_path):
    from fkopt.mechanisms.mjcf import DEFAULT_FILE
    with pytest.raises(FkoptError, match="unknown body or site 'tol'.*tool"):
        fkopt.mechanism("mjcf", tip="tol")
    with pytest.raises(FkoptError, match="unknown body 'lnk0'"):
        fkopt.mechanism("mjcf", base="lnk0")
    text = DEFAULT_FILE.read_text().replace(
        "</worldbody>", "</worldbody><tendon><fixed name='t'><joint joint='q2' coef='1'/>"
        "<joint joint='q3' coef='-1'/></fixed></tendon><equality><tendon tendon1='t'/></equality>")
    f = tmp_path / "tendon.xml"
    f.write_text(text)
    with pytest.raises(FkoptError, match="tendon equality"):
        fkopt.mechanism("mjcf", file=str(f))
    f.write_text("<mujoco><worldbody>")
    with pytest.raises(FkoptError, match="malformed XML"):          # fkopt's bounded parser, before MuJoCo
        fkopt.mechanism("mjcf", file=str(f))
    f.write_text('<mujoco><worldbody><body><joint type="bogus"/></body></worldbody></mujoco>')
    with pytest.raises(FkoptError, match="MuJoCo cannot compile"):
        fkopt.mechanism("mjcf", file=str(f))


@pytest.mark.external
@pytest.mark.parametrize("robot, base, tip", [("panda", "base", "right_hand"), ("iiwa", "base", "right_hand"),
                                              ("ur5e", "base", "right_hand"), ("jaco", "base", "right_hand")])
def test_robosuite_arms_match_mj_kinematics(robot, base, tip):
    robosuite = pytest.importorskip("robosuite")
    f = Path(robosuite.__file__).parent / "models" / "assets" / "robots" / robot / "robot.xml"
    arm = fkopt.mechanism("mjcf", file=str(f), base=base, tip=tip)
    assert 6 <= arm.dof <= 7
    check_against_mujoco(arm, mujoco.MjModel.from_xml_path(str(f)), base, tip)
    q = arm.bounds.mean(axis=1)
    assert fkopt.inverse(arm, arm.fk(q)).solved
