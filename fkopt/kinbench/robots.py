"""The real arms of kinbench: one table (:data:`ARMS`) of where each arm comes from, and the cutters
that write its kinematics-only copy into ``configs/suites/robots/``.

Each arm is a chain ``base`` -> ``tip`` of a robot description shipped on PyPI under a licence
that allows redistribution: URDF from ``example-robot-data`` (the Gepetto/pinocchio collection)
and MJCF from ``robosuite``. The copy keeps the chain's own format and only what kinematics
reads:

* URDF (:func:`cut_urdf`): the links and joints from ``base`` to ``tip`` -- joint ``origin``,
  ``axis``, ``limit`` and ``mimic`` -- with their attribute strings copied verbatim (the same
  doubles); visuals, collisions, inertials, transmissions, gazebo and dynamics blocks dropped;
* MJCF (:func:`cut_mjcf`): ``compiler`` and the joint part of ``default`` classes, the bodies
  from the world down to ``tip`` (their frames: pos / quat / euler / axisangle / xyaxes / zaxis),
  the joints of the bodies below ``base`` (kinematic attributes only) with their inertials (MuJoCo
  refuses a moving body without mass), the tip site, and joint equalities between chain joints;
  meshes, geoms, cameras, actuators, sensors, contacts, keyframes and the rest of the tree dropped.

Every copy opens with a comment naming its source file, package and version, its upstream and
its licence. ``tests/test_robots.py`` checks each copy against its package's own model --
pinocchio on the original URDF, MuJoCo's ``mj_kinematics`` on the original MJCF -- on random
configurations. ``python -m fkopt.kinbench.freeze robots configs/suites/robots`` (re)writes the copies of
the arms added in v3 (v2's three copies stay as they were released).
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from fkopt.errors import FkoptError
from fkopt.files import installed_version, read_input
from fkopt.mechanisms.mjcf import MAX_MJCF_BYTES
from fkopt.mechanisms.urdf import example_robots_folder, load_urdf, urdf_chain


@dataclass(frozen=True)
class Arm:
    """One real arm of the suite: problem name (= file stem), format, source and chain."""

    name: str
    format: str          # "urdf" | "mjcf"
    package: str         # PyPI distribution the original ships in
    source: str          # the original's path inside the package's robots folder
    base: str
    tip: str
    title: str
    upstream: str
    licence: str
    released: str = "kinbench-v3"   # the version whose copy this is (v2's three are not rewritten)

    @property
    def file(self) -> str:
        return f"robots/{self.name}.{'urdf' if self.format == 'urdf' else 'xml'}"


_ERD, _RS = "example-robot-data", "robosuite"
ARMS: tuple[Arm, ...] = (
    Arm("ur5", "urdf", _ERD, "ur_description/urdf/ur5_robot.urdf", "base_link", "tool0", "Universal Robots UR5",
        "https://github.com/ros-industrial/universal_robot", "BSD-3-Clause", "kinbench-v2"),
    Arm("panda", "urdf", _ERD, "panda_description/urdf/panda.urdf", "panda_link0", "panda_hand_tcp",
        "Franka Emika Panda", "https://github.com/frankaemika/franka_ros", "Apache-2.0", "kinbench-v2"),
    Arm("kinova-j2s6s200", "urdf", _ERD, "kinova_description/robots/kinova.urdf", "base", "j2s6s200_end_effector",
        "Kinova JACO2 j2s6s200", "https://github.com/Kinovarobotics/kinova-ros", "BSD", "kinbench-v2"),
    Arm("ur3", "urdf", _ERD, "ur_description/urdf/ur3_robot.urdf", "base_link", "tool0", "Universal Robots UR3",
        "https://github.com/ros-industrial/universal_robot", "BSD"),
    Arm("ur10", "urdf", _ERD, "ur_description/urdf/ur10_robot.urdf", "base_link", "tool0", "Universal Robots UR10",
        "https://github.com/ros-industrial/universal_robot", "BSD"),
    Arm("xarm7", "urdf", _ERD, "xarm_description/urdf/xarm7.urdf", "link_base", "link_eef", "UFACTORY xArm 7",
        "https://github.com/xArm-Developer/xarm_ros2", "BSD-3-Clause"),
    Arm("z1", "urdf", _ERD, "z1_description/urdf/z1.urdf", "link00", "gripperStator", "Unitree Z1",
        "https://github.com/unitreerobotics/unitree_ros", "MPL-2.0"),
    Arm("so101", "urdf", _ERD, "so_arm_description/urdf/so101.urdf", "base_link", "gripper_link",
        "TheRobotStudio SO-101", "https://github.com/TheRobotStudio/SO-ARM100", "Apache-2.0"),
    Arm("baxter-left", "urdf", _ERD, "baxter_description/urdf/baxter.urdf", "torso", "left_gripper",
        "Rethink Baxter, left arm", "https://github.com/RethinkRobotics/baxter_common", "BSD"),
    Arm("pr2-left-gripper", "urdf", _ERD, "pr2_description/urdf/pr2.urdf", "torso_lift_link",
        "l_gripper_l_finger_tip_link", "Willow Garage PR2, left arm to a finger tip (mimic joint)",
        "https://github.com/pr2/pr2_common", "BSD"),
    Arm("tiago-torso", "urdf", _ERD, "tiago_description/robots/tiago.urdf", "base_footprint", "arm_tool_link",
        "PAL TIAGo, torso lift + arm", "https://github.com/pal-robotics/tiago_robot", "Apache-2.0"),
    Arm("talos-left", "urdf", _ERD, "talos_data/robots/talos_reduced.urdf", "base_link", "gripper_left_base_link",
        "PAL TALOS, torso + left arm", "https://github.com/pal-robotics/talos_robot", "Apache-2.0"),
    Arm("romeo-left", "urdf", _ERD, "romeo_description/urdf/romeo.urdf", "body", "l_wrist",
        "Aldebaran Romeo, trunk + left arm", "https://github.com/laas/romeo", "BSD"),
    Arm("icub-left", "urdf", _ERD, "icub_description/robots/icub.urdf", "root_link", "l_hand",
        "IIT iCub, torso + left arm", "https://github.com/robotology/icub-models", "CC-BY-SA-4.0"),
    Arm("g1-left", "urdf", _ERD, "g1_description/urdf/g1_29dof_rev_1_0.urdf", "pelvis", "left_wrist_yaw_link",
        "Unitree G1, waist + left arm", "https://github.com/unitreerobotics/unitree_ros", "BSD-3-Clause"),
    Arm("iiwa-mj", "mjcf", _RS, "iiwa/robot.xml", "base", "right_hand", "KUKA LBR iiwa 7",
        "https://github.com/ARISE-Initiative/robosuite", "MIT"),
    Arm("jaco-mj", "mjcf", _RS, "jaco/robot.xml", "base", "right_hand", "Kinova JACO2 j2s7s300",
        "https://github.com/ARISE-Initiative/robosuite", "MIT"),
    Arm("kinova3-mj", "mjcf", _RS, "kinova3/robot.xml", "base", "right_hand", "Kinova Gen3",
        "https://github.com/ARISE-Initiative/robosuite", "MIT"),
    Arm("ur5e-mj", "mjcf", _RS, "ur5e/robot.xml", "base", "right_hand", "Universal Robots UR5e",
        "https://github.com/ARISE-Initiative/robosuite", "MIT"),
    Arm("spot-arm-mj", "mjcf", _RS, "spot_arm/robot.xml", "base", "right_hand", "Boston Dynamics Spot arm",
        "https://github.com/ARISE-Initiative/robosuite", "MIT"),
    Arm("tiago-right-mj", "mjcf", _RS, "tiago/robot.xml", "base", "right_hand",
        "PAL TIAGo (robosuite), torso lift + right arm", "https://github.com/ARISE-Initiative/robosuite", "MIT"),
    Arm("sawyer-mj", "mjcf", _RS, "sawyer/robot.xml", "base", "right_hand", "Rethink Sawyer",
        "https://github.com/ARISE-Initiative/robosuite", "MIT"),
    Arm("baxter-right-mj", "mjcf", _RS, "baxter/robot.xml", "base", "right_hand", "Rethink Baxter, right arm",
        "https://github.com/ARISE-Initiative/robosuite", "MIT"),
    Arm("gr1-left-mj", "mjcf", _RS, "gr1/robot.xml", "whole_body", "left_eef", "Fourier GR1, waist + left arm",
        "https://github.com/ARISE-Initiative/robosuite", "MIT"),
)
ARM_NAMES = {a.name: a for a in ARMS}


def package_folder(package: str) -> Path | None:
    """The robots folder of ``package`` as installed, or None."""
    if package == _ERD:
        return example_robots_folder()
    if package == _RS:
        from importlib.util import find_spec
        spec = find_spec("robosuite")
        if spec is None or spec.origin is None:
            return None
        return Path(spec.origin).parent / "models" / "assets" / "robots"
    raise FkoptError(f"unknown robot package '{package}'; allowed: {_ERD}, {_RS}")


def original_file(arm: Arm) -> Path | None:
    folder = package_folder(arm.package)
    return None if folder is None else folder / arm.source


def original_model(arm: Arm):
    """MuJoCo's compiled model of ``arm``'s original MJCF. Sawyer's and Baxter's meshes are too thin
    for MuJoCo 4's volume-based mesh inertia ("mesh volume is too small"); they are compiled with
    shell inertia instead, as MuJoCo's message suggests -- inertia does not enter kinematics."""
    import mujoco
    path = original_file(arm)
    try:
        return mujoco.MjModel.from_xml_path(str(path))
    except ValueError as err:
        if "mesh volume is too small" not in str(err):
            raise
    spec = mujoco.MjSpec.from_file(str(path))
    for mesh in spec.meshes:
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
    return spec.compile()


def _header(arm: Arm, kept: str) -> str:
    return (f" {arm.title}, kinematics only ({kept}), cut by fkopt.kinbench.robots from {arm.source} of "
            f"{arm.package} {installed_version(arm.package)} (PyPI); upstream {arm.upstream}; licence {arm.licence} "
            f"(as {arm.package} states it for this robot). Chain used by kinbench: {arm.base} to {arm.tip}. "
            "Lengths in m; angles in rad (URDF) or as the compiler says (MJCF). ")


_URDF_JOINT_PARTS = ("origin", "axis", "limit", "mimic")


def cut_urdf(path: Path, base: str, tip: str) -> ET.Element:
    """The ``<robot>`` of the chain ``base`` -> ``tip`` of URDF ``path``, kinematics only: the
    chain as fkopt's URDF arm reads it (:func:`fkopt.mechanisms.urdf.load_urdf`, bounded, and
    :func:`~fkopt.mechanisms.urdf.urdf_chain`), each joint's parts copied from its XML element."""
    robot = load_urdf(path)
    out = ET.Element("robot", name=robot.name)
    ET.SubElement(out, "link", name=base)
    for joint in urdf_chain(robot, path, base, tip):
        e = joint.element
        ET.SubElement(out, "link", name=joint.child)
        j = ET.SubElement(out, "joint", name=joint.name, type=joint.type)
        ET.SubElement(j, "parent", link=joint.parent)
        ET.SubElement(j, "child", link=joint.child)
        for part in _URDF_JOINT_PARTS:
            kept = e.find(part)
            if kept is not None:
                ET.SubElement(j, part, dict(kept.attrib))
    return out


_FRAME_ATTRS = ("name", "pos", "quat", "euler", "axisangle", "xyaxes", "zaxis", "childclass")
_JOINT_ATTRS = ("name", "class", "type", "axis", "pos", "range", "limited", "ref")
_COMPILER_ATTRS = ("angle", "eulerseq", "autolimits")


def _kept(e: ET.Element, names) -> dict:
    return {k: v for k, v in e.attrib.items() if k in names}


def _cut_defaults(default: ET.Element) -> ET.Element:
    out = ET.Element("default", _kept(default, ("class",)))
    for child in default:
        if child.tag == "joint" and _kept(child, _JOINT_ATTRS):
            ET.SubElement(out, "joint", _kept(child, _JOINT_ATTRS))
        elif child.tag == "default":
            out.append(_cut_defaults(child))
    return out


def cut_mjcf(path: Path, base: str, tip: str) -> ET.Element:
    """The ``<mujoco>`` of the chain ``base`` -> ``tip`` (a body or a site) of MJCF ``path``,
    kinematics only (module docstring)."""
    try:
        root = ET.fromstring(read_input(path, MAX_MJCF_BYTES, field="robots"))
    except ET.ParseError as err:
        raise FkoptError(f"{path}: malformed MJCF ({err})") from None
    if root.find(".//include") is not None:
        raise FkoptError(f"{path}: <include> is not cut; compile and save the model first")
    world = root.find("worldbody")
    parents = {c: p for p in world.iter() for c in p}
    end = next((b for b in world.iter("body") if b.get("name") == tip), None)
    site = None
    if end is None:
        site = next((s for s in world.iter("site") if s.get("name") == tip), None)
        if site is None:
            raise FkoptError(f"{path}: no body or site '{tip}'")
        end = parents[site]
    path_bodies, b = [], end
    while b is not world:
        path_bodies.append(b)
        b = parents[b]
    path_bodies.reverse()
    if any(b.tag != "body" for b in path_bodies):
        raise FkoptError(f"{path}: a <{next(b.tag for b in path_bodies if b.tag != 'body')}> on the chain is not "
                         "cut; compile and save the model first")
    names = [b.get("name") for b in path_bodies]
    if base not in names:
        raise FkoptError(f"{path}: '{tip}' is not below body '{base}'")
    below = names.index(base) + 1
    out = ET.Element("mujoco", model=root.get("model", "arm"))
    compiler = root.find("compiler")
    if compiler is not None:
        ET.SubElement(out, "compiler", _kept(compiler, _COMPILER_ATTRS))
    for default in root.findall("default"):
        out.append(_cut_defaults(default))
    parent = ET.SubElement(out, "worldbody")
    chain_joints = set()
    for k, body in enumerate(path_bodies):
        new = ET.SubElement(parent, "body", _kept(body, _FRAME_ATTRS))
        if k >= below:
            joints = body.findall("joint")
            inertial = body.find("inertial")
            if inertial is not None:
                ET.SubElement(new, "inertial", dict(inertial.attrib))
            elif joints:        # MuJoCo needs mass on a moving body; kinematics does not read it
                ET.SubElement(new, "inertial", pos="0 0 0", mass="1", diaginertia="1 1 1")
            for j in joints:
                ET.SubElement(new, "joint", _kept(j, _JOINT_ATTRS))
                chain_joints.add(j.get("name"))
        parent = new
    if site is not None:
        ET.SubElement(parent, "site", _kept(site, ("name", "pos", "quat", "euler", "axisangle", "xyaxes",
                                                    "zaxis")))
    couplings = [e for eq in root.findall("equality") for e in eq.findall("joint")
                 if e.get("joint1") in chain_joints and e.get("joint2", e.get("joint1")) in chain_joints]
    if couplings:
        eq = ET.SubElement(out, "equality")
        for e in couplings:
            ET.SubElement(eq, "joint", _kept(e, ("name", "joint1", "joint2", "polycoef", "active")))
    return out


def stored_text(arm: Arm) -> str:
    """The kinematics-only copy of ``arm`` (its file's text), cut from the installed package."""
    src = original_file(arm)
    if src is None or not src.is_file():
        raise FkoptError(f"{arm.name}: {arm.package} is not installed (pip install {arm.package})")
    if arm.format == "urdf":
        tree = cut_urdf(src, arm.base, arm.tip)
        kept = "links and joints: origins, axes, limits, mimics"
    else:
        tree = cut_mjcf(src, arm.base, arm.tip)
        kept = "compiler, joint defaults, the chain's body frames, joints, inertials and tip"
    ET.indent(tree, "  ")
    head = '<?xml version="1.0"?>\n' if arm.format == "urdf" else ""
    return head + f"<!--{_header(arm, kept)}-->\n" + ET.tostring(tree, encoding="unicode") + "\n"


def write_robots(folder: Path) -> list[Path]:
    """Write the copies of the arms released in v3 into ``folder``; their paths."""
    out = []
    for arm in ARMS:
        if arm.released == "kinbench-v2":
            continue
        path = Path(folder) / Path(arm.file).name
        path.write_text(stored_text(arm), encoding="utf-8")
        out.append(path)
    return out
