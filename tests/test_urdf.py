"""Serial arms from URDF: wang7dof as URDF gives 7dof-arm's poses, limits, errors, YAML paths."""
import numpy as np
import pytest
import yaml

import fkopt
from fkopt.errors import FkoptError
from fkopt.experiment.config import load_config
from fkopt.experiment.runner import run_experiment
from fkopt.mechanisms.urdf import DEFAULT_FILE
from fkopt.rotations import wrap_degrees

TWO_JOINTS = """<?xml version="1.0"?>
<robot name="rp">
  <link name="base"/><link name="a"/><link name="b"/><link name="tool"/><link name="camera"/>
  <joint name="turn" type="continuous"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>
    <origin xyz="0.2 0 0" rpy="0 1.5707963267948966 0"/><axis xyz="0 0 1"/>
    <limit lower="0.0" upper="0.3" effort="1" velocity="1"/></joint>
  <joint name="fix" type="fixed"><parent link="b"/><child link="tool"/><origin xyz="0 0 0.05"/></joint>
  <joint name="cam" type="fixed"><parent link="a"/><child link="camera"/></joint>
</robot>
"""


def test_wang7dof_urdf_gives_the_poses_of_7dof_arm():
    urdf, dh = fkopt.mechanism("urdf"), fkopt.mechanism("7dof-arm")
    assert urdf.joint_names == dh.joint_names and urdf.pose_units[:3] == ("m", "m", "m")
    np.testing.assert_allclose(urdf.bounds, dh.bounds)          # limits from the file (rad -> deg)
    rng = np.random.default_rng(7)
    q = dh.bounds[:, 0] + rng.random((500, 7)) * (dh.bounds[:, 1] - dh.bounds[:, 0])
    pu, pd = urdf.fk(q), dh.fk(q)
    np.testing.assert_allclose(pu[:, :3] * 1000.0, pd[:, :3], atol=1e-9)       # m vs mm
    np.testing.assert_allclose(wrap_degrees(pu[:, 3:] - pd[:, 3:]), 0.0, atol=1e-9)
    np.testing.assert_allclose(urdf.fk_matrix(q)[:, :3, :3], dh.fk_matrix(q)[:, :3, :3], atol=1e-12)
    assert urdf.reach * 1000.0 == pytest.approx(dh.reach)
    # vectorised: any batch shape gives the same numbers as one call per pose
    np.testing.assert_array_equal(urdf.fk(q[:6].reshape(2, 3, 7)).reshape(6, 6),
                                  np.stack([urdf.fk(x) for x in q[:6]]))


def test_ik_on_the_urdf_arm_recovers_the_pose():
    urdf = fkopt.mechanism("urdf")
    pose = urdf.fk([10, -20, 30, 40, -10, 20, 30])
    problem = fkopt.ik_problem(urdf, pose, objective="geodesic", w_p=1000.0)   # mm + deg, as 7dof-arm
    r = fkopt.solve(problem, "lm", population=8, iterations=60, runs=1, seed=3)
    assert r.fitness[0] < 1e-6
    np.testing.assert_allclose(urdf.fk(r.x[0])[:3], pose[:3], atol=1e-9)


def test_prismatic_continuous_and_fixed_joints(tmp_path):
    path = tmp_path / "rp.urdf"
    path.write_text(TWO_JOINTS)
    m = fkopt.mechanism("urdf", file=str(path), base="base", tip="tool")
    assert m.joint_names == ("turn", "slide") and m.joint_units == ("deg", "m")
    assert m.bounds.tolist() == [[-180.0, 180.0], [0.0, 0.3]]     # continuous: default +-180 deg
    # turn 90 deg, slide 0.1 m along the pitched z (= base x before the turn): tool at (0, 0.35, 0.1)
    np.testing.assert_allclose(m.fk([90.0, 0.1])[:3], [0.0, 0.2 + 0.1 + 0.05, 0.1], atol=1e-12)
    wide = fkopt.mechanism("urdf", file=str(path), tip="tool", bounds={"turn": [-360, 360]})
    assert wide.bounds[0].tolist() == [-360.0, 360.0]


def test_bad_urdf_input_is_one_line(tmp_path):
    path = tmp_path / "rp.urdf"
    path.write_text(TWO_JOINTS)
    cases = [
        (dict(file=str(path)), "2 leaf links (camera, tool); name geometry.tip"),
        (dict(file=str(path), tip="gripper"), "unknown link 'gripper' (geometry.tip)"),
        (dict(file=str(path), base="b", tip="camera"), "link 'camera' is not below link 'b'"),
        (dict(file=str(tmp_path / "missing.urdf")), "does not exist"),
        (dict(file=str(path), tip="tool", colour="red"), "geometry"),
    ]
    for kwargs, fragment in cases:
        with pytest.raises(FkoptError, match=fragment.replace("(", r"\(").replace(")", r"\)")) as info:
            fkopt.mechanism("urdf", **kwargs)
        assert "\n" not in str(info.value)
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'></robot>")
    with pytest.raises(FkoptError, match="malformed URDF"):
        fkopt.mechanism("urdf", file=str(bad))


def test_yaml_file_path_is_relative_to_the_config_folder(tmp_path, monkeypatch):
    sub = tmp_path / "configs" / "arm"
    sub.mkdir(parents=True)
    (sub / "rp.urdf").write_text(TWO_JOINTS)
    cfg = {"name": "rp", "mechanism": {"name": "urdf", "geometry": {"file": "rp.urdf", "tip": "tool"},
                                       "bounds": {"turn": [-90, 90]}},
           "cases": [{"joints": {"turn": 30, "slide": 0.2}}], "algorithms": [{"name": "lm"}],
           "population": 4, "iterations": 30, "runs": 1, "objective": "geodesic"}
    (sub / "rp.yaml").write_text(yaml.safe_dump(cfg))
    monkeypatch.chdir(tmp_path)            # not the config's folder
    er = run_experiment(load_config(sub / "rp.yaml"))
    assert er.mechanism.bounds[0].tolist() == [-90.0, 90.0]
    assert er.records[0].result.fitness[0] < 1e-8
    assert DEFAULT_FILE.is_file()
