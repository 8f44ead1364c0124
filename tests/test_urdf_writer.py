"""The URDF written from fkopt's chain (fkopt.mechanisms.urdf_writer), which the field's URDF-only
packages read for MJCF arms: read back by fkopt's own URDF reader it is the same arm, read by
pinocchio it is MuJoCo's mj_kinematics of the MJCF file it came from."""
from pathlib import Path

import numpy as np
import pytest

import fkopt
from fkopt.errors import FkoptError
from fkopt.kinbench.robots import ARMS
from fkopt.mechanisms.urdf_writer import chain_urdf

SUITES = Path(__file__).resolve().parents[1] / "configs" / "suites"
MIMIC = "pr2-left-gripper"          # its finger tip follows the finger: no plain-URDF form


def stored_arm(arm, **extra):
    return fkopt.mechanism(arm.format, file=str(SUITES / arm.file), base=arm.base, tip=arm.tip, **extra)


def random_joints(mech, rows=20, seed=3):
    lo, hi = mech.bounds[:, 0], mech.bounds[:, 1]
    return lo + np.random.default_rng(seed).random((rows, mech.dof)) * (hi - lo)


def read_back(tmp_path, mech):
    w = chain_urdf(mech)
    path = tmp_path / "chain.urdf"
    path.write_text(w.text)
    return w, fkopt.mechanism("urdf", file=str(path), base=w.base_link, tip=w.tip_link)


@pytest.mark.parametrize("arm", [a for a in ARMS if a.name != MIMIC], ids=lambda a: a.name)
def test_written_urdf_read_back_by_fkopt_is_the_same_arm(arm, tmp_path):
    mech = stored_arm(arm)
    w, back = read_back(tmp_path, mech)
    assert back.joint_names == mech.joint_names == w.joint_names
    assert np.allclose(back.bounds, mech.bounds, rtol=0, atol=1e-9)
    assert (back.periodic_mask() == mech.periodic_mask()).all()
    q = random_joints(mech)
    assert np.abs(back.fk_matrix(q) - mech.fk_matrix(q)).max() < 1e-12, arm.name


def test_written_urdf_of_a_dh_table_and_of_a_tool_frame(tmp_path):
    dh = fkopt.mechanism("dh-chain", joints=12, seed=0)          # mm, theta offsets folded into origins
    _, back = read_back(tmp_path, dh)
    q = random_joints(dh)
    F, G = dh.fk_matrix(q), back.fk_matrix(q)
    assert np.abs(G[:, :3, 3] * 1e3 - F[:, :3, 3]).max() < 1e-9 and np.abs(G[:, :3, :3] - F[:, :3, :3]).max() < 1e-12
    ur5 = next(a for a in ARMS if a.name == "ur5")
    tooled = stored_arm(ur5, tool=[0.01, -0.02, 0.15, 0.3, -1.5707963, 2.0])   # pitch near 90 deg: two origins
    _, back = read_back(tmp_path, tooled)
    q = random_joints(tooled)
    assert np.abs(back.fk_matrix(q) - tooled.fk_matrix(q)).max() < 1e-12


def test_a_mimic_joint_is_refused_with_one_line():
    with pytest.raises(FkoptError) as err:
        chain_urdf(stored_arm(next(a for a in ARMS if a.name == MIMIC)))
    assert "\n" not in str(err.value) and "mimic" in str(err.value) and "l_gripper_l_finger_joint" in str(err.value)


@pytest.mark.external
@pytest.mark.parametrize("arm", [a for a in ARMS if a.format == "mjcf"], ids=lambda a: a.name)
def test_written_urdf_in_pinocchio_matches_mj_kinematics_on_the_mjcf(arm):
    pin = pytest.importorskip("pinocchio")
    mujoco = pytest.importorskip("mujoco")
    mech = stored_arm(arm)
    w = chain_urdf(mech)
    pmodel = pin.buildModelFromXML(w.text)
    pdata = pmodel.createData()
    ptip = pmodel.getFrameId(w.tip_link, pin.FrameType.BODY)
    model = mujoco.MjModel.from_xml_path(str(SUITES / arm.file))
    data = mujoco.MjData(model)
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, arm.tip)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, arm.tip)
    b0 = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, arm.base)
    for row in random_joints(mech):
        si = {n: np.radians(v) if u == "deg" else v for n, v, u in zip(mech.joint_names, row, mech.joint_units)}
        x = pin.neutral(pmodel)
        data.qpos[:] = model.qpos0
        for name, v in si.items():
            j = pmodel.joints[pmodel.getJointId(name)]
            if j.nq == 2:                          # continuous joint: (cos, sin)
                x[j.idx_q:j.idx_q + 2] = np.cos(v), np.sin(v)
            else:
                x[j.idx_q] = v
        for cj in mech.chain_joints:               # MuJoCo's qpos of every chain joint, couplings included
            data.qpos[model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, cj["name"])]] = \
                cj["multiplier"] * si[cj["unknown"]] + cj["offset"]
        pin.framesForwardKinematics(pmodel, pdata, x)
        mujoco.mj_kinematics(model, data)
        pt, Rt = ((data.xpos[body], data.xmat[body]) if body >= 0 else (data.site_xpos[site], data.site_xmat[site]))
        R0 = data.xmat[b0].reshape(3, 3)
        got = pdata.oMf[ptip]
        assert np.abs(R0.T @ (pt - data.xpos[b0]) - got.translation).max() < 1e-10, arm.name
        assert np.abs(R0.T @ Rt.reshape(3, 3) - got.rotation).max() < 1e-10, arm.name
