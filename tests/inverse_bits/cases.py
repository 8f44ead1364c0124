"""The arms and one-pose calls of tests/inverse_bits/one_pose.json (shared by its recorder and
tests/test_inverse_solver.py)."""
import numpy as np

#: An MJCF arm with a slide joint, a hinge anchored off its body and a joint equality.
ANCHORED_MJCF = """<mujoco><compiler angle="degree"/><worldbody><body name="b0">
  <body name="l1" pos="0.1 0.2 0.3" quat="0.9 0.1 0.3 0.2"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
    <joint name="j1" type="hinge" axis="0.3 -1 0.2" pos="0.05 0.02 -0.1" ref="20" range="-170 150"/>
    <joint name="j2" type="slide" axis="1 1 0" range="-0.2 0.3" ref="0.05"/>
    <body name="l2" pos="0 0 0.4" euler="10 20 30"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
      <joint name="j3" type="hinge" axis="0 1 0" pos="0 0.1 0"/>
      <body name="l3" pos="0.2 0 0"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
        <joint name="j4" type="hinge" axis="1 0 0" range="-90 90"/>
        <joint name="j5" type="hinge" axis="0 0 1" range="-90 90"/>
        <site name="tcp" pos="0 0.03 0.1" axisangle="1 1 0 25"/></body></body></body></body></worldbody>
  <equality><joint joint1="j5" joint2="j4" polycoef="0.1 -0.5 0 0 0"/></equality></mujoco>"""


def arms(fkopt, example_robot, example_robots_folder, mjcf_file=None):
    """(name, arm): the DH arm, the URDF arm of wang7dof, the MJCF arm of wang7dof, the anchored
    MJCF arm (when ``mjcf_file`` is a path to write it to) and, with example-robot-data, UR5 and Panda."""
    out = [("7dof-arm", fkopt.mechanism("7dof-arm")), ("urdf", fkopt.mechanism("urdf")),
           ("mjcf", fkopt.mechanism("mjcf"))]
    if mjcf_file is not None:
        with open(mjcf_file, "w") as f:
            f.write(ANCHORED_MJCF)
        out.append(("mjcf-anchored", fkopt.mechanism("mjcf", file=str(mjcf_file), base="b0", tip="tcp")))
    if example_robots_folder() is not None:
        out += [("ur5", example_robot("ur5", tip="ee_link")), ("panda", example_robot("panda", tip="panda_hand_tcp"))]
    return out


def calls(arm, name):
    """(target, keywords) of the recorded calls: tip frames and ZYZ poses of seeded in-limit
    joints, default and strict tolerances, a start, a position-only mask, fewer restarts."""
    rng = np.random.default_rng(sum(map(ord, name)))
    q = arm.bounds[:, 0] + rng.random((4, arm.dof)) * (arm.bounds[:, 1] - arm.bounds[:, 0])
    frames, poses = arm.fk_matrix(q), arm.fk(q)
    mid = arm.bounds.mean(axis=1)
    out = [(frames[0], {"seed": 0}), (frames[1], {"seed": 7, "tol": (1e-9, 1e-9)}), (poses[2], {"seed": 3}),
           (frames[3], {"seed": 1, "restarts": 5, "table": 512}), (frames[2], {"seed": 2, "start": mid}),
           (frames[1], {"seed": 5, "mask": "x,y,z"}), (frames[0], {"seed": 4, "table": 0})]
    return out
