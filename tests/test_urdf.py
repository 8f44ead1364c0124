"""Serial arms from URDF: wang7dof as URDF gives 7dof-arm's poses, limits, errors, YAML paths."""
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

import fkopt
from fkopt.errors import FkoptError
from fkopt.kinds.experiment.config import load_config
from fkopt.kinds.experiment.runner import run_experiment
from fkopt.mechanisms.urdf import DEFAULT_FILE, example_robot, example_robots_folder
from fkopt.numerics.rotations import wrap_degrees

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
    assert er.own.mechanism.bounds[0].tolist() == [-90.0, 90.0]
    assert er.own.solves[0].result.fitness[0] < 1e-8
    assert DEFAULT_FILE.is_file()


# -- real robots (example-robot-data) --------------------------------------------------------------
ROBOTS = {   # name -> tip link for the FK comparison: the chains ikpy follows from the base
    "panda": "panda_hand_tcp", "ur5": "ee_link", "kinova": "j2s6s200_end_effector"}


def robot(name, **extra):
    if example_robots_folder() is None:
        pytest.skip("example-robot-data is not installed (pip install fkopt[test])")
    return example_robot(name, **{"tip": ROBOTS[name], **extra})


def random_joints(m, n, seed):
    rng = np.random.default_rng(seed)
    return m.bounds[:, 0] + rng.random((n, m.dof)) * (m.bounds[:, 1] - m.bounds[:, 0])


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_real_robot_fk_matches_ikpy(name):
    """Tip transforms against ikpy's own URDF reader and FK (an independent implementation)."""
    ikpy_chain = pytest.importorskip("ikpy.chain")
    import warnings
    m = robot(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = ikpy_chain.Chain.from_urdf_file(str(m.path), base_elements=[m.base_link])
    active = [i for i, link in enumerate(chain.links) if link.joint_type != "fixed"]
    assert [chain.links[i].name for i in active] == list(m.joint_names)
    q = random_joints(m, 100, 11)
    T = m.fk_matrix(q)
    for k in range(len(q)):
        v = np.zeros(len(chain.links))
        v[active] = np.radians(q[k])
        np.testing.assert_allclose(T[k], chain.forward_kinematics(v), atol=1e-12)


def _frame_derivatives(m, q, h):
    """Central differences of the tip position and of the rotation as angular velocity
    (omega^ = dR R^T) per public joint unit, columns (6, n) at q (n,)."""
    cols = []
    for i in range(m.dof):
        e = np.zeros(m.dof)
        e[i] = h[i]
        Tp, Tm = m.fk_matrix(q + e), m.fk_matrix(q - e)
        dp = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h[i])
        W = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h[i]) @ m.fk_matrix(q)[:3, :3].T
        cols.append(np.concatenate([dp, [W[2, 1], W[0, 2], W[1, 0]]]))
    return np.stack(cols, axis=1)


TOOL = [0.01, -0.02, 0.1, 10.0, 20.0, 90.0]


@pytest.mark.parametrize("name", sorted(ROBOTS))
@settings(max_examples=25, deadline=None)
@given(u=st.lists(st.floats(0.01, 0.99), min_size=7, max_size=7))
def test_real_robot_jacobian_matches_finite_differences(name, u):
    m = robot(name, tool=TOOL)
    q = m.bounds[:, 0] + np.array(u[:m.dof]) * (m.bounds[:, 1] - m.bounds[:, 0])
    p, R, J = m.frame_jacobian(q)
    T = m.fk_matrix(q)
    np.testing.assert_allclose(p, T[:3, 3], atol=1e-14)
    np.testing.assert_allclose(R, T[:3, :3], atol=1e-14)
    np.testing.assert_allclose(J, _frame_derivatives(m, q, np.full(m.dof, 1e-4)), atol=1e-8)
    # one configuration on floats (per radian) = the batched one (per degree)
    p1, R1, J1 = m.frame_jacobian1(np.radians(q).tolist())
    np.testing.assert_allclose(p1, p, atol=1e-15)
    np.testing.assert_allclose(R1, R, atol=1e-15)
    np.testing.assert_allclose(np.array(J1) * np.pi / 180.0, J, atol=1e-15)
    # any batch shape: the same numbers as one call per configuration
    Q = np.stack([q, q[::-1].clip(m.bounds[:, 0], m.bounds[:, 1])]).reshape(2, 1, m.dof)
    np.testing.assert_array_equal(m.frame_jacobian(Q)[2][0, 0], J)


@settings(max_examples=25, deadline=None)
@given(u=st.lists(st.floats(0.0, 1.0), min_size=2, max_size=2))
def test_prismatic_jacobian_matches_finite_differences(tmp_path_factory, u):
    path = tmp_path_factory.mktemp("rp") / "rp.urdf"
    path.write_text(TWO_JOINTS)
    m = fkopt.mechanism("urdf", file=str(path), tip="tool")
    q = m.bounds[:, 0] + np.array(u) * (m.bounds[:, 1] - m.bounds[:, 0])
    _, _, J = m.frame_jacobian(q)
    np.testing.assert_allclose(J, _frame_derivatives(m, q, np.array([1e-4, 1e-6])), atol=1e-8)
    _, _, J1 = m.frame_jacobian1([np.radians(q[0]), q[1]])
    np.testing.assert_allclose(np.array(J1) * [np.pi / 180.0, 1.0], J, atol=1e-15)


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_real_robot_inverse_on_random_reachable_poses(name):
    m = robot(name)
    q = random_joints(m, 200, 5)
    poses = m.fk(q)
    tol = (1e-4, 1e-3)                        # 0.1 mm, 1e-3 rad geodesic
    r = fkopt.inverse(m, poses, tol=tol, seed=1)
    assert r.solved.mean() >= 0.99
    # every row reported solved is one: in the limits, and its tip transform (recomputed here)
    # matches the target's
    T, Tt = m.fk_matrix(r.joints), m.fk_matrix(q)
    perr = np.linalg.norm(T[:, :3, 3] - Tt[:, :3, 3], axis=-1)
    M = np.einsum("kij,kil->kjl", T[:, :3, :3], Tt[:, :3, :3])
    angle = np.arccos(np.clip((np.trace(M, axis1=1, axis2=2) - 1) / 2, -1, 1))
    ok = r.solved
    assert (perr[ok] <= tol[0]).all() and (angle[ok] <= tol[1] + 1e-9).all()
    assert m.in_bounds(r.joints).all()
    # one pose at a time (the scalar path) solves them too
    one = [fkopt.inverse(m, poses[i], tol=tol, seed=1) for i in range(5)]
    assert all(o.solved for o in one)


@pytest.mark.parametrize("solver, population", [("lm", 1), ("dls", 1), ("gabc+lm", 10)])
def test_swarm_api_solvers_use_the_urdf_jacobian(solver, population):
    m = robot("panda")
    pose = m.fk(random_joints(m, 1, 3)[0])
    problem = fkopt.ik_problem(m, pose, objective="geodesic", w_p=1000.0)
    assert problem.has_jacobian
    np.testing.assert_array_equal(problem.jacobian(random_joints(m, 2, 1)).shape, (2, 6, 7))
    r = fkopt.solve(problem, solver, population=population, iterations=300, runs=4, seed=2)
    assert r.fitness.min() < 1e-6


def test_continuous_joints_are_periodic_and_answers_wrapped():
    m = robot("kinova")
    assert m.periodic.tolist() == [True, False, False, True, False, True]
    assert m.bounds[0].tolist() == [-180.0, 180.0]
    q = random_joints(m, 50, 9)
    r = fkopt.inverse(m, m.fk(q), tol=(1e-4, 1e-3))
    assert r.solved.all()
    assert ((r.joints[:, m.periodic] >= -180.0) & (r.joints[:, m.periodic] < 180.0)).all()
    bounded = robot("kinova", bounds={"j2s6s200_joint_1": [-90, 90]})
    assert bounded.periodic.tolist() == [False, False, False, True, False, True]


def test_tool_offset_is_the_tip_frame_times_the_tool_transform():
    from fkopt.numerics.rotations import zyx1
    m, t = robot("panda"), robot("panda", tool=TOOL)
    q = random_joints(m, 20, 4)
    X = np.eye(4)
    X[:3, :3] = zyx1(*np.radians(TOOL[3:]))
    X[:3, 3] = TOOL[:3]
    np.testing.assert_allclose(t.fk_matrix(q), m.fk_matrix(q) @ X, atol=1e-14)
    assert t.reach > m.reach
    with pytest.raises(FkoptError, match="tool"):
        robot("panda", tool=[0, 0, 0.1])


def test_masked_inverse_position_only():
    m = robot("ur5")
    q = random_joints(m, 50, 8)
    poses = m.fk(q)
    poses[:, 3:] = 0.0                                   # orientation ignored
    r = fkopt.inverse(m, poses, mask="x,y,z", tol=(1e-5, 1e-3))
    assert r.solved.all()
    np.testing.assert_allclose(m.fk(r.joints)[:, :3], poses[:, :3], atol=1e-5)
    assert (r.rotation_error == 0).all()
    one = fkopt.inverse(m, poses[0], mask=[1, 1, 1, 0, 0, 0], tol=(1e-5, 1e-3))
    assert one.solved
    with pytest.raises(FkoptError, match="inverse mask"):
        fkopt.inverse(m, poses[0], mask=[0] * 6)


def test_mimic_joints_follow_their_master_as_yourdfpy_does():
    """PR2's left gripper chain: the finger tip joint mimics the finger joint; it is not an
    unknown, and the FK agrees with yourdfpy's (which applies mimics itself)."""
    if example_robots_folder() is None:
        pytest.skip("example-robot-data is not installed")
    yourdfpy = pytest.importorskip("yourdfpy")
    m = example_robot("pr2-left-gripper")
    base, tip = m.base_link, m.tip_link
    assert len(m.joint_names) == 8 and "l_gripper_l_finger_tip_joint" not in m.joint_names
    tipj = next(j for j in m.chain_joints if j["name"] == "l_gripper_l_finger_tip_joint")
    assert tipj["unknown"] == "l_gripper_l_finger_joint" and tipj["multiplier"] == 1.0
    robot_ = yourdfpy.URDF.load(str(m.path), load_meshes=False, build_collision_scene_graph=False)
    q = random_joints(m, 20, 2)
    T = m.fk_matrix(q)
    for k in range(len(q)):
        cfg = {n: np.radians(v) for n, v in zip(m.joint_names, q[k])}
        robot_.update_cfg(cfg)
        np.testing.assert_allclose(T[k], robot_.get_transform(tip, base), atol=1e-12)
    r = fkopt.inverse(m, m.fk(q), tol=(1e-4, 1e-3))
    assert r.solved.mean() >= 0.9


MIMIC = """<?xml version="1.0"?>
<robot name="m">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-0.5" upper="0.2" effort="1" velocity="1"/><mimic joint="j1" multiplier="-2" offset="0.1"/></joint>
  <joint name="j3" type="prismatic"><parent link="b"/><child link="c"/><origin xyz="0.2 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/><mimic joint="{master}" multiplier="0.05"/></joint>
</robot>
"""


def test_mimic_coupling_limits_jacobian_and_refusal(tmp_path):
    path = tmp_path / "m.urdf"
    path.write_text(MIMIC.format(master="j1"))
    m = fkopt.mechanism("urdf", file=str(path))
    assert m.joint_names == ("j1",)
    # j2 = -2 j1 + 0.1 in [-0.5, 0.2] -> j1 in [-0.05, 0.3]; j3 = 0.05 j1 in [0, 0.1] -> j1 >= 0
    np.testing.assert_allclose(m.bounds[0], np.degrees([0.0, 0.3]), atol=1e-8)
    t = np.radians(10.0)
    a, b = t, t - 2 * t + 0.1                       # absolute angles of links a and b
    x = 0.3 * np.cos(a) + (0.2 + 0.05 * t) * np.cos(b)
    y = 0.3 * np.sin(a) + (0.2 + 0.05 * t) * np.sin(b)
    np.testing.assert_allclose(m.fk([10.0])[:3], [x, y, 0.0], atol=1e-15)
    _, _, J = m.frame_jacobian([10.0])
    np.testing.assert_allclose(J, _frame_derivatives(m, np.array([10.0]), [1e-4]), atol=1e-9)
    path.write_text(MIMIC.format(master="elsewhere"))
    with pytest.raises(FkoptError, match="mimics 'elsewhere', which is not on the chain") as info:
        fkopt.mechanism("urdf", file=str(path))
    assert "\n" not in str(info.value)


# -- command line ----------------------------------------------------------------------------------
def test_cli_list_and_ik_on_a_urdf_arm(tmp_path, fkopt_run):
    import json
    arm = tmp_path / "robot"
    arm.mkdir()
    (arm / "arm.urdf").write_text(DEFAULT_FILE.read_text())
    (arm / "arm.yaml").write_text("file: arm.urdf\ntip: tool\n")            # relative to the YAML
    out = json.loads(fkopt_run("list", "urdf", "--geometry", str(arm / "arm.yaml"), "--json", cwd=tmp_path).stdout)
    assert [j["name"] for j in out["chain_joints"]] == [f"q{i}" for i in range(1, 8)]
    assert out["chain_joints"][0]["type"] == "continuous" and out["chain_joints"][1]["limits"] is not None
    direct = fkopt_run("list", "urdf", "--geometry", str(arm / "arm.urdf"), cwd=tmp_path)
    assert direct.returncode == 0 and "chain joints" in direct.stdout
    m = fkopt.mechanism("urdf", file=str(arm / "arm.urdf"))
    q = [10, -20, 30, 40, -10, 20, 30]
    pose = ",".join(f"{k}={v!r}" for k, v in zip(m.pose_names, m.fk(q).tolist()))
    start = ",".join(f"q{i + 1}={v + 2}" for i, v in enumerate(q))
    res = fkopt_run("ik", "urdf", "--geometry", str(arm / "arm.yaml"), "--pose", pose, "--start", start, "--json",
               "--position-tol", "1e-6", "--orientation-tol", "1e-6")
    got = json.loads(res.stdout)
    assert got["solved"] and got["restarts"] == 0
    # solved at 1e-6 m / 1e-6 rad: the tip frame within those (Euler angles in deg are no tolerance's unit)
    T, Tq = m.fk_matrix(list(got["joints"].values())), m.fk_matrix(q)
    assert np.linalg.norm(T[:3, 3] - Tq[:3, 3]) <= 1e-6 * (1 + 1e-9)
    assert np.arccos(np.clip((np.trace(T[:3, :3].T @ Tq[:3, :3]) - 1) / 2, -1, 1)) <= 1e-6 + 1e-9
    masked = json.loads(fkopt_run("ik", "urdf", "--geometry", str(arm / "arm.yaml"), "--pose", pose,
                             "--mask", "x,y,z", "--json").stdout)
    assert masked["solved"] and "rotation_error_rad" not in masked     # no rotation sought, none reported
    bad = fkopt_run("ik", "urdf", "--geometry", str(arm / "arm.yaml"), "--pose", pose, "--mask", "x,y,w")
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1 and "inverse mask" in bad.stderr


def test_fkopt_run_resolves_the_urdf_beside_the_config(tmp_path, monkeypatch):
    """``fkopt run`` loads configs through ``load_any``: the URDF path is relative to the config
    (it was resolved against the working directory, so examples/urdf failed from elsewhere)."""
    from fkopt.run.pipeline import load_any
    from fkopt.kinds.experiment.runner import build_mechanism
    root = Path(__file__).resolve().parents[1]
    monkeypatch.chdir(tmp_path)
    config = load_any(root / "examples" / "urdf" / "ur5_ik.yaml")
    m = build_mechanism(config)
    assert m.dof == 6 and m.path == root / "examples" / "urdf" / "ur5.urdf"
    assert m.periodic_mask().sum() == 0                       # UR5 joints are revolute, +-360 deg


def test_start_returns_the_solution_nearest_to_the_current_joints():
    """A redundant arm (Panda) started at joints near a known solution: the answer is moved along
    the self-motion towards the start, so it is at least as near as that solution (median), and
    the same start as one pose agrees with the batch."""
    m = robot("panda")
    rng = np.random.default_rng(3)
    q = random_joints(m, 100, 12)
    start = np.clip(q + rng.normal(0.0, 2.0, q.shape), m.bounds[:, 0], m.bounds[:, 1])
    r = fkopt.inverse(m, m.fk(q), start=start, tol=(1e-4, 1e-3))
    assert r.solved.all()
    d, dq = np.linalg.norm(r.joints - start, axis=1), np.linalg.norm(q - start, axis=1)
    assert np.median(d) <= np.median(dq)
    one = fkopt.inverse(m, m.fk(q[0]), start=start[0], tol=(1e-4, 1e-3))
    assert one.solved and np.linalg.norm(one.joints - start[0]) <= dq[0] + 1e-9
    # a 6-joint arm started at a solution keeps it
    ur5 = robot("ur5")
    q6 = random_joints(ur5, 1, 4)[0]
    same = fkopt.inverse(ur5, ur5.fk(q6), start=q6, tol=(1e-4, 1e-3))
    assert same.solved and same.restarts == 0
    np.testing.assert_allclose(same.joints, q6, atol=1e-9)
