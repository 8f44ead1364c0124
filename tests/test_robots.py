"""kinbench's real arms (fkopt.kinbench.robots): each stored kinematics-only copy gives its package's
own FK -- pinocchio on example-robot-data's original URDF, MuJoCo's mj_kinematics on robosuite's
original MJCF -- on random configurations inside the joint limits."""
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import fkopt
from fkopt.kinbench.robots import ARMS, original_file, original_model

SUITES = Path(__file__).resolve().parents[1] / "configs" / "suites"


def stored_arm(arm):
    return fkopt.mechanism(arm.format, file=str(SUITES / arm.file), base=arm.base, tip=arm.tip)


def random_joints(mech, rows=25, seed=5):
    lo, hi = mech.bounds[:, 0], mech.bounds[:, 1]
    return lo + np.random.default_rng(seed).random((rows, mech.dof)) * (hi - lo)


def si_values(mech, row) -> dict:
    """Joint name -> value in SI units (rad, m) of every chain joint, mimics from their masters."""
    si = {n: np.radians(v) if u == "deg" else v for n, v, u in zip(mech.joint_names, row, mech.joint_units)}
    return {cj["name"]: cj["multiplier"] * si[cj["unknown"]] + cj["offset"] for cj in mech.chain_joints}


def frames(mech, q):
    p, R = mech.frame(q)
    return (np.stack(p, axis=-1), np.stack([np.stack(r, axis=-1) for r in R], axis=-2))


def test_the_table_holds_twenty_arms_of_five_to_fifteen_joints_and_every_stored_file_loads():
    dofs = {}
    for arm in ARMS:
        text = (SUITES / arm.file).read_text(encoding="utf-8")
        assert arm.licence in text and arm.source in text and "<mesh" not in text and "<visual" not in text
        dofs[arm.name] = stored_arm(arm).dof
    assert len(ARMS) >= 20 and all(5 <= d <= 15 for d in dofs.values()), dofs
    assert sum(a.format == "mjcf" for a in ARMS) >= 4 and sum(d > 7 for d in dofs.values()) >= 2
    pr2 = stored_arm(next(a for a in ARMS if a.name == "pr2-left-gripper"))
    assert any(cj["unknown"] != cj["name"] for cj in pr2.chain_joints)          # the mimic joint


@pytest.mark.parametrize("arm", [a for a in ARMS if a.format == "urdf"], ids=lambda a: a.name)
def test_stored_urdf_copy_matches_pinocchio_on_the_original(arm):
    pin = pytest.importorskip("pinocchio")
    src = original_file(arm)
    if src is None:
        pytest.skip(f"{arm.package} is not installed")
    model = pin.buildModelFromUrdf(str(src))
    data = model.createData()
    base, tip = (model.getFrameId(n, pin.FrameType.BODY) for n in (arm.base, arm.tip))     # the link, not its joint
    mech = stored_arm(arm)
    q = random_joints(mech)
    p, R = frames(mech, q)
    for i, row in enumerate(q):
        x = pin.neutral(model)
        for name, v in si_values(mech, row).items():
            j = model.joints[model.getJointId(name)]
            if j.nq == 2:                          # continuous joint: (cos, sin)
                x[j.idx_q:j.idx_q + 2] = np.cos(v), np.sin(v)
            else:
                x[j.idx_q] = v
        pin.framesForwardKinematics(model, data, x)
        rel = data.oMf[base].inverse() * data.oMf[tip]
        assert np.abs(rel.translation - p[i]).max() < 1e-12, arm.name
        assert np.abs(rel.rotation - R[i]).max() < 1e-12, arm.name


@pytest.mark.parametrize("arm", [a for a in ARMS if a.format == "mjcf"], ids=lambda a: a.name)
def test_stored_mjcf_copy_matches_mj_kinematics_on_the_original(arm):
    mujoco = pytest.importorskip("mujoco")
    src = original_file(arm)
    if src is None:
        pytest.skip(f"{arm.package} is not installed")
    model = original_model(arm)
    data = mujoco.MjData(model)
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, arm.tip)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, arm.tip)
    b0 = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, arm.base)
    mech = stored_arm(arm)
    q = random_joints(mech)
    p, R = frames(mech, q)
    for i, row in enumerate(q):
        data.qpos[:] = model.qpos0
        for name, v in si_values(mech, row).items():
            data.qpos[model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)]] = v
        mujoco.mj_kinematics(model, data)
        pt, Rt = ((data.xpos[body], data.xmat[body]) if body >= 0 else (data.site_xpos[site], data.site_xmat[site]))
        R0 = data.xmat[b0].reshape(3, 3)
        assert np.abs(R0.T @ (pt - data.xpos[b0]) - p[i]).max() < 1e-12, arm.name
        assert np.abs(R0.T @ Rt.reshape(3, 3) - R[i]).max() < 1e-12, arm.name


def test_the_cutters_keep_only_the_chain_and_refuse_what_they_do_not_cut(tmp_path):
    from fkopt.errors import FkoptError
    from fkopt.kinbench.robots import cut_mjcf, cut_urdf
    f = tmp_path / "arm.xml"
    f.write_text("""<mujoco><compiler angle="degree"/><asset><mesh name="m" file="m.stl"/></asset><worldbody>
      <body name="b0"><geom type="sphere" size="0.1"/><body name="l1" pos="0 0 0.3"><joint name="j1" axis="0 0 1"
        damping="3" range="-90 90"/><geom type="mesh" mesh="m"/><body name="tip" pos="0.2 0 0"/></body>
        <body name="other"><joint name="j9"/></body></body></worldbody><actuator><motor joint="j1"/></actuator>
      <equality><joint joint1="j9" joint2="j1"/></equality></mujoco>""")
    text = ET.tostring(cut_mjcf(f, "b0", "tip"), "unicode")
    assert 'name="other"' not in text and "mesh" not in text and "geom" not in text and "damping" not in text
    assert "motor" not in text and "equality" not in text and 'range="-90 90"' in text and 'angle="degree"' in text
    f.write_text('<mujoco><worldbody><frame pos="1 0 0"><body name="a"><joint/><body name="t"/></body></frame>'
                 '</worldbody></mujoco>')
    with pytest.raises(FkoptError, match="a <frame> on the chain is not cut"):
        cut_mjcf(f, "a", "t")
    u = tmp_path / "arm.urdf"
    u.write_text('<robot name="r"><link name="a"><visual/></link><link name="b"/><link name="c"/>'
                 '<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
                 '<limit lower="-1" upper="1"/><dynamics damping="1"/></joint></robot>')
    text = ET.tostring(cut_urdf(u, "a", "b"), "unicode")
    assert "visual" not in text and "dynamics" not in text and 'lower="-1"' in text
    with pytest.raises(FkoptError, match="link 'c' is not below link 'a'"):
        cut_urdf(u, "a", "c")


def test_the_urdf_cutter_reads_bounded_through_fkopts_urdf_reader_and_copies_attribute_strings(tmp_path):
    """cut_urdf walks the chain fkopt's URDF arm walks (one reader, one walk), keeps each joint's
    strings as written (the same doubles), and refuses what the arm refuses, in one line."""
    from fkopt.errors import FkoptError
    from fkopt.kinbench.robots import cut_urdf
    from fkopt.mechanisms.urdf import MAX_URDF_BYTES
    u = tmp_path / "arm.urdf"
    u.write_text('<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
                 '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>'
                 '<origin xyz="0 0 0.10000000000000001" rpy="0 0 1.5707963267948966"/><axis xyz="0 0 1"/>'
                 '<limit lower="-1.0e0" upper="2.5" effort="9" velocity="1"/></joint>'
                 '<joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint></robot>')
    text = ET.tostring(cut_urdf(u, "a", "c"), "unicode")
    assert 'xyz="0 0 0.10000000000000001"' in text and 'lower="-1.0e0"' in text and 'effort="9"' in text
    assert text.index('name="j1"') < text.index('name="j2"') and text.count("<link") == 3
    u.write_text('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute">'
                 '<parent link="a"/><child link="b"/><axis xyz="0 0 1e308"/></joint></robot>')
    with pytest.raises(FkoptError, match="joint 'j' axis") as err:
        cut_urdf(u, "a", "b")
    assert "\n" not in str(err.value)
    u.write_text("<robot>" + " " * MAX_URDF_BYTES + "</robot>")
    with pytest.raises(FkoptError, match="arm.urdf") as err:
        cut_urdf(u, "a", "b")
    assert "\n" not in str(err.value)
    u.write_text("<robot><link name='a'>")
    with pytest.raises(FkoptError, match="malformed URDF"):
        cut_urdf(u, "a", "b")
