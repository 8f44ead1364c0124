"""Hostile robot files (issue 42, breaks 1-8 and 19): no code runs from a robot file, every file an
outside library opens on fkopt's behalf gets the top file's checks, and MJCF's numbers, names and
ranges get URDF's rules. Each test reproduces one break of the attacker's report."""
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import fkopt
from fkopt.errors import FkoptError

#: A xacro expression that escapes xacro's ``safe_eval`` (no ``__`` *names*, only strings) and
#: makes the folder MARKER: what roboticstoolbox's ``URDF_file`` evaluates in any attribute.
ESCAPE = ("${[g for C in python.vars(python.type)['__subclasses__'](python.type(1).mro()[-1]) "
          "if 'wrap_close' in python.str(C) for f in [python.vars(C)['__init__']] "
          "for d in [python.vars(python.type(f))['__globals__']] "
          "for g in [python.vars(python.type(d))['__get__'](d, f)['mkdir']('MARKER')]] and 'x'}")


def two_joint_urdf(extra="", names=("j1", "j2"), tail=""):
    a, b = names
    return textwrap.dedent(f"""\
        <robot name="r">
          {extra}
          <link name="l0"/><link name="l1"/><link name="l2"/>{tail and '<link name="l3"/>'}
          <joint name="{a}" type="revolute"><parent link="l0"/><child link="l1"/>
            <origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
          <joint name="{b}" type="revolute"><parent link="l1"/><child link="l2"/>
            <origin xyz="0.4 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
          {tail}
        </robot>""")


def escape_to(marker: Path) -> str:
    return ESCAPE.replace("MARKER", str(marker)).replace("'", "&apos;")


def test_escape_payload_really_runs_code_when_xacro_reads_the_file(tmp_path):
    """The payload of the tests below is live: rtb's own reader, given the file, makes the marker
    (so a marker that never appears below means fkopt never handed the file over)."""
    pytest.importorskip("roboticstoolbox")
    from roboticstoolbox.models.URDF.URDFRobot import URDF_file
    marker = tmp_path / "marker"
    path = tmp_path / "evil.urdf"
    path.write_text(two_joint_urdf(f'<material name="{escape_to(marker)}"/>'))
    URDF_file(str(path))
    assert marker.exists()


def test_break1_rtb_never_evaluates_an_expression_in_the_users_urdf(tmp_path):
    """Break 1: a ``${...}`` in an element fkopt ignores (<material name>) ran a command whenever
    rtb read the arm; outside packages now read the URDF fkopt writes from its own chain."""
    pytest.importorskip("roboticstoolbox")
    from fkopt.adapters.field import arm_urdf
    from fkopt.registry import clock_solver as make_ik
    marker = tmp_path / "marker"
    path = tmp_path / "evil.urdf"
    path.write_text(two_joint_urdf(f'<material name="{escape_to(marker)}"/>'))
    arm = fkopt.mechanism("urdf", file=str(path))
    assert "${" not in arm_urdf(arm).text
    w = make_ik("rtb-ik_LM", arm, timeout=0.01, rng=np.random.default_rng(0))
    assert w.settings["urdf"].startswith("written from fkopt's chain")
    assert not marker.exists()


def test_break2_an_mjcf_joint_name_is_never_copied_as_an_expression(tmp_path):
    """Break 2: ``chain_urdf`` copied an MJCF joint name into the URDF written for outside solvers;
    XML escaping held but ``${...}`` is not XML. Written names hold only [A-Za-z0-9_] and stay unique."""
    pytest.importorskip("mujoco")
    pytest.importorskip("roboticstoolbox")
    from fkopt.registry import clock_solver as make_ik
    from fkopt.mechanisms.urdf_writer import chain_urdf
    marker = tmp_path / "marker"
    evil = escape_to(marker)
    path = tmp_path / "arm.xml"
    path.write_text(textwrap.dedent(f"""\
        <mujoco><worldbody><body name="b1" pos="0 0 0.3"><joint name="{evil}" axis="0 0 1" range="-2 2"/>
          <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
          <body name="b2" pos="0.4 0 0"><joint name="a b" axis="0 1 0" range="-2 2"/>
            <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
            <body name="b3" pos="0.1 0 0"><joint name="a_b" axis="1 0 0" range="-2 2"/>
              <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></body></body></worldbody></mujoco>"""))
    arm = fkopt.mechanism("mjcf", file=str(path))
    w = chain_urdf(arm)
    assert "$" not in w.text and "{" not in w.text
    assert len(set(w.joint_names)) == 3 and all(n.replace("_", "").isalnum() for n in w.joint_names)
    make_ik("rtb-ik_LM", arm, timeout=0.01, rng=np.random.default_rng(0))
    assert not marker.exists()


def test_an_own_urdf_read_as_it_stands_must_hold_no_expression(tmp_path):
    """The one route that still hands a file as it stands to rtb (``ArmURDF.from_file``, for
    example-robot-data's files in ``fkopt bench``) proves first that nothing in it is evaluated."""
    from fkopt.adapters.field import ArmURDF
    for extra in ('<material name="${1+1}"/>', '<material name="$(find x)"/>',
                  '<xacro:include xmlns:xacro="http://www.ros.org/wiki/xacro" filename="/etc/passwd"/>'):
        path = tmp_path / "x.urdf"
        path.write_text(two_joint_urdf(extra))
        with pytest.raises(FkoptError) as err:
            ArmURDF.from_file(path, "l0", "l2")
        assert str(path) in str(err.value) and "\n" not in str(err.value)


def test_break8_an_arm_with_a_joint_named_like_a_written_fixed_joint(tmp_path):
    """Break 8: the writer named its fixed joints ``fixed{N}``; an arm's own ``fixed3`` collided and
    every outside solver refused a valid arm. Written fixed joints and links can no longer collide."""
    from fkopt.mechanisms.urdf_writer import chain_urdf
    tail = ('<joint name="tcp" type="fixed"><parent link="l2"/><child link="l3"/>'
            '<origin xyz="0 0 0.1" rpy="0.3 1.5707 0"/></joint>')
    for names in (("fixed3", "fixed5"), ("fixed1", "fixed2"), ("link1", "tip"), ("base", "link2")):
        path = tmp_path / "arm.urdf"
        path.write_text(two_joint_urdf(names=names, tail=tail))
        arm = fkopt.mechanism("urdf", file=str(path), tool=[0, 0, 0.05, 0, 89.99, 0])
        w = chain_urdf(arm)
        back_path = tmp_path / "back.urdf"
        back_path.write_text(w.text)
        back = fkopt.mechanism("urdf", file=str(back_path), base=w.base_link, tip=w.tip_link)
        assert back.joint_names == w.joint_names == names
        q = np.array([[0.3, -0.7], [1.0, 0.2]]) * 50
        assert np.abs(back.fk_matrix(q) - arm.fk_matrix(q)).max() < 1e-12


@pytest.mark.parametrize("solver", ["tracik", "rtb-ik_LM", "pin-clik", "ikpy"])
def test_break8_every_outside_solver_reads_an_arm_with_a_fixed3_joint(solver, tmp_path):
    from fkopt.registry import SOLVERS, clock_solver as make_ik
    import importlib.util
    module = {"pin": "pinocchio", "roboticstoolbox-python": "roboticstoolbox"}.get(SOLVERS[solver].package,
                                                                                  SOLVERS[solver].package)
    if importlib.util.find_spec(module) is None:
        pytest.skip(f"{module} is not installed")
    tail = ('<joint name="tcp" type="fixed"><parent link="l2"/><child link="l3"/>'
            '<origin xyz="0 0 0.1" rpy="0.3 1.5707 0"/></joint>')
    path = tmp_path / "arm.urdf"
    path.write_text(two_joint_urdf(names=("fixed3", "fixed5"), tail=tail))
    arm = fkopt.mechanism("urdf", file=str(path), tool=[0, 0, 0.05, 0, 89.99, 0])
    w = make_ik(solver, arm, timeout=0.01, rng=np.random.default_rng(0))
    assert w.settings["urdf"].startswith("written from fkopt's chain")
