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
    for extra in ('<material name="${1+1}"/>', '<material name="$(find x)"/>', '<material name="&#36;{1}"/>',
                  '<material name="m"><![CDATA[${1}]]></material>', '<gazebo>$(env HOME)</gazebo>',
                  '<xacro:include xmlns:xacro="http://www.ros.org/wiki/xacro" filename="/etc/passwd"/>',
                  '<material xmlns:xacro="u" xacro:if="1" name="m"/>'):
        path = tmp_path / "x.urdf"
        path.write_text(two_joint_urdf(extra))
        with pytest.raises(FkoptError) as err:
            ArmURDF.from_file(path, "l0", "l2")
        assert str(path) in str(err.value) and "\n" not in str(err.value)
    # a namespace declaration alone, as most of example-robot-data's files have, passes
    path.write_text(two_joint_urdf().replace('<robot name="r">',
                                             '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'))
    assert ArmURDF.from_file(path, "l0", "l2").text.startswith("<robot")


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
    import importlib.util
    from fkopt.registry import SOLVERS, clock_solver as make_ik
    package = SOLVERS[solver].package
    module = {"pin": "pinocchio", "roboticstoolbox-python": "roboticstoolbox"}.get(package, package)
    if importlib.util.find_spec(module) is None:
        pytest.skip(f"{module} is not installed")
    tail = ('<joint name="tcp" type="fixed"><parent link="l2"/><child link="l3"/>'
            '<origin xyz="0 0 0.1" rpy="0.3 1.5707 0"/></joint>')
    path = tmp_path / "arm.urdf"
    path.write_text(two_joint_urdf(names=("fixed3", "fixed5"), tail=tail))
    arm = fkopt.mechanism("urdf", file=str(path), tool=[0, 0, 0.05, 0, 89.99, 0])
    w = make_ik(solver, arm, timeout=0.01, rng=np.random.default_rng(0))
    assert w.settings["urdf"].startswith("written from fkopt's chain")


# --- break 3: nesting ----------------------------------------------------------------------------
def test_break3_a_urdf_nested_deep_outside_the_chain_is_refused_while_parsing(tmp_path):
    """Break 3: a URDF nested 100,000 deep outside the chain was accepted and then crashed TRAC-IK
    (exit 139). fkopt's reader refuses it first, with one line; no outside library sees it."""
    from fkopt.files import MAX_XML_DEPTH
    deep = "<a>" * 100_000 + "</a>" * 100_000
    path = tmp_path / "deep.urdf"
    path.write_text(two_joint_urdf(f"<material name='m'>{deep}</material>"))
    with pytest.raises(FkoptError) as err:
        fkopt.mechanism("urdf", file=str(path))
    assert str(path) in str(err.value) and f"deeper than {MAX_XML_DEPTH}" in str(err.value)
    assert "\n" not in str(err.value)
    ok = tmp_path / "ok.urdf"                    # nesting up to the bound stays accepted
    ok.write_text(two_joint_urdf("<a>" * (MAX_XML_DEPTH - 2) + "</a>" * (MAX_XML_DEPTH - 2)))
    assert fkopt.mechanism("urdf", file=str(ok)).dof == 2


# --- MJCF ----------------------------------------------------------------------------------------
BODY = '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'


def mjcf(tmp_path, inner="", head="", j1='name="j1" axis="0 0 1" range="-90 90"', pos1="0 0 0.3",
         j2='name="j2" axis="0 1 0" range="-90 90"', name="arm.xml"):
    path = tmp_path / name
    path.write_text(f"""<mujoco>{head}<worldbody><body name="b1" pos="{pos1}"><joint {j1}/>{BODY}
      <body name="b2" pos="0.4 0 0"><joint {j2}/>{BODY}{inner}<body name="tip" pos="0.1 0 0">{BODY}</body>
      </body></body></worldbody></mujoco>""")
    return path


def refused(path, *fragments, **geometry):
    with pytest.raises(FkoptError) as err:
        fkopt.mechanism("mjcf", file=str(path), **geometry)
    msg = str(err.value)
    assert "\n" not in msg and all(f in msg for f in fragments), msg
    return msg


def run_bounded(code: str, timeout: float = 120.0):
    """``code`` in a fresh interpreter, killed after ``timeout`` s (a hang fails the test, it does
    not hang the suite): (exit status, stderr)."""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout)
    return out.returncode, out.stderr


#: Reads an MJCF in a child process (run_bounded): a hang is a failure, not a hung suite.
REFUSED = """
import fkopt
from fkopt.errors import FkoptError
try:
    fkopt.mechanism("mjcf", file={path!r})
except FkoptError as err:
    raise SystemExit("FkoptError: " + str(err))
"""


@pytest.mark.parametrize("tag", ["include", "mesh"])
def test_break4_an_mjcf_naming_a_fifo_is_refused_not_a_hang(tag, tmp_path):
    """Break 4: an MJCF ``<include>`` or ``<mesh>`` of a FIFO blocked MuJoCo forever."""
    pytest.importorskip("mujoco")
    import os
    os.mkfifo(tmp_path / "pipe")
    head = ('<include file="pipe"/>' if tag == "include"
            else '<asset><mesh name="m" file="pipe"/></asset>')
    path = mjcf(tmp_path, head=head)
    status, err = run_bounded(REFUSED.format(path=str(path)))
    assert status != 0 and "FkoptError:" in err and "FIFO" in err and "pipe" in err, err


def test_break4_a_fifo_beside_an_included_file_is_refused_too(tmp_path):
    """MuJoCo also looks for a nested include beside the file that includes it (sub/a.xml naming
    b.xml finds sub/b.xml): that candidate gets the same checks."""
    pytest.importorskip("mujoco")
    import os
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "a.xml").write_text('<mujoco><include file="b.xml"/></mujoco>')
    os.mkfifo(tmp_path / "sub" / "b.xml")
    path = mjcf(tmp_path, head='<include file="sub/a.xml"/>')
    status, err = run_bounded(REFUSED.format(path=str(path)))
    assert status != 0 and "FkoptError:" in err and "FIFO" in err and "b.xml" in err, err


def test_break4_a_model_asset_is_checked_like_an_include(tmp_path):
    """``<asset><model file>`` is an MJCF MuJoCo parses in turn: its nesting and the files it names
    get the top file's checks."""
    pytest.importorskip("mujoco")
    from fkopt.files import MAX_XML_DEPTH
    deep = "<default>" * MAX_XML_DEPTH + "</default>" * MAX_XML_DEPTH
    (tmp_path / "gripper.xml").write_text(f"<mujoco>{deep}</mujoco>")
    path = mjcf(tmp_path, head='<asset><model name="g" file="gripper.xml"/></asset>')
    refused(path, "gripper.xml", f"deeper than {MAX_XML_DEPTH}")
    (tmp_path / "gripper.xml").write_text('<mujoco><asset><mesh name="m" file="/etc/passwd"/></asset></mujoco>')
    refused(path, "/etc/passwd", "only files inside")


@pytest.mark.parametrize("head", [
    '<include file="/etc/passwd"/>',
    '<include file="../outside.xml"/>',
    '<compiler meshdir="/"/><asset><mesh name="m" file="etc/passwd"/></asset>',
    '<compiler meshdir=".."/><asset><mesh name="m" file="outside.stl"/></asset>',
    '<asset><texture name="t" type="2d" file="/etc/hostname"/></asset>',
    '<asset><texture name="t" type="cube" fileright="../outside.png"/></asset>',
    '<asset><mesh name="m" file="link.stl"/></asset>',
], ids=["include-abs", "include-up", "meshdir-root", "meshdir-up", "texture-abs", "cube-face-up", "link-out"])
def test_break4_mjcf_files_outside_the_folder_are_refused(head, tmp_path):
    """Break 4: MuJoCo read includes and meshes anywhere (/etc/passwd, meshdir="/"); every file an
    MJCF names must resolve inside its folder, links included."""
    pytest.importorskip("mujoco")
    (tmp_path / "outside.xml").write_text("<mujoco/>")
    inner = tmp_path / "arm"
    inner.mkdir()
    (inner / "link.stl").symlink_to(tmp_path / "outside.xml")
    path = mjcf(inner, head=head)
    refused(path, str(path), "only files inside")


def test_mjcf_files_inside_the_folder_are_read_and_included_files_get_the_depth_bound(tmp_path):
    """What may be named still works (an include and a mesh beside the file, a meshdir below it),
    and an included file gets the top file's nesting bound."""
    pytest.importorskip("mujoco")
    from fkopt.files import MAX_XML_DEPTH
    (tmp_path / "meshes").mkdir()
    stl = tmp_path / "meshes" / "box.stl"
    import struct
    tris = [((0, 0, 1), (0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 1), (0, 0, 0), (0, 1, 0), (0, 0, 1)),
            ((0, 0, 1), (0, 0, 0), (0, 0, 1), (1, 0, 0)), ((0, 0, 1), (1, 0, 0), (0, 0, 1), (0, 1, 0))]
    stl.write_bytes(b"\0" * 80 + struct.pack("<I", 4)
                    + b"".join(struct.pack("<12fH", *(c for v in t for c in v), 0) for t in tris))
    (tmp_path / "opts.xml").write_text('<mujoco><option timestep="0.002"/></mujoco>')
    head = '<compiler meshdir="meshes"/><include file="opts.xml"/><asset><mesh name="m" file="box.stl"/></asset>'
    path = mjcf(tmp_path, head=head, inner='<geom type="mesh" mesh="m"/>')
    assert fkopt.mechanism("mjcf", file=str(path), tip="tip").dof == 2
    deep = "<default>" * MAX_XML_DEPTH + "</default>" * MAX_XML_DEPTH
    (tmp_path / "opts.xml").write_text(f"<mujoco>{deep}</mujoco>")
    refused(path, "opts.xml", f"deeper than {MAX_XML_DEPTH}", tip="tip")


def test_break5_an_mjcf_naming_a_huge_mesh_is_refused_by_size_before_it_is_read(tmp_path):
    """Break 5: a 300-byte MJCF naming a 1.9 GB mesh took 1.97 GB. The size is checked first
    (a sparse file: no disk or memory is spent here), per file and over all files named."""
    pytest.importorskip("mujoco")
    from fkopt.mechanisms.mjcf import MAX_MJCF_ASSET_BYTES, MAX_MJCF_TOTAL_BYTES
    big = tmp_path / "big.stl"
    with open(big, "wb") as fh:
        fh.truncate(2 << 30)
    path = mjcf(tmp_path, head='<asset><mesh name="m" file="big.stl"/></asset>', inner='<geom type="mesh" mesh="m"/>')
    refused(path, "big.stl", f"{MAX_MJCF_ASSET_BYTES >> 20} MB")
    part = tmp_path / "part.stl"
    with open(part, "wb") as fh:
        fh.truncate(MAX_MJCF_ASSET_BYTES)
    many = "".join(f'<mesh name="m{i}" file="part.stl"/>' for i in range(MAX_MJCF_TOTAL_BYTES // MAX_MJCF_ASSET_BYTES + 1))
    refused(mjcf(tmp_path, head=f"<asset>{many}</asset>"), "together")


def test_break5_a_png_declaring_a_huge_image_is_refused(tmp_path):
    pytest.importorskip("mujoco")
    import struct
    import zlib
    ihdr = struct.pack(">IIBBBBB", 40000, 40000, 8, 6, 0, 0, 0)
    png = (b"\x89PNG\r\n\x1a\n" + struct.pack(">I", len(ihdr)) + b"IHDR" + ihdr
           + struct.pack(">I", zlib.crc32(b"IHDR" + ihdr)))
    (tmp_path / "t.png").write_bytes(png)
    path = mjcf(tmp_path, head='<asset><texture name="t" type="2d" file="t.png"/></asset>')
    refused(path, "t.png", "40000 x 40000")


@pytest.mark.parametrize("pos1, j1, fragment", [
    ("nan 0 0", 'name="j1" axis="0 0 1" range="-90 90"', "<body pos='nan 0 0'> is not finite"),
    ("1e300 0 0", 'name="j1" axis="0 0 1" range="-90 90"', "body 'b1' pos"),
    ("1e20 0 0", 'name="j1" axis="0 0 1" range="-90 90"', "body 'b1' pos"),
    ("0 0 0.3", 'name="j1" type="slide" axis="0 0 1" range="-1e12 1e12"', "joint 'j1' range"),
    ("0 0 0.3", 'name="j1" axis="0 0 1" range="-90 90" pos="0 2e9 0"', "joint 'j1' pos"),
    ("0 0 0.3", 'name="j1" axis="0 0 1" range="-90 90" ref="1e300"', "joint 'j1' ref"),
], ids=["nan", "1e300", "1e20", "slide-1e12", "anchor-2e9", "ref-1e300"])
def test_break6_mjcf_numbers_get_urdfs_rules(pos1, j1, fragment, tmp_path):
    """Break 6: ``pos="nan 0 0"`` or ``1e300`` gave an ``fkopt ik`` traceback or NaN FK with exit 0;
    ``1e20`` and a slide range of +-1e12 were accepted. MJCF numbers now meet URDF's rule
    (:func:`fkopt.mechanisms.urdf.check_numbers`: finite, |v| <= 1e9)."""
    pytest.importorskip("mujoco")
    path = mjcf(tmp_path, pos1=pos1, j1=j1)
    refused(path, str(path), fragment)


@pytest.mark.parametrize("command", ["ik", "fk"])
def test_break6_the_cli_says_one_line_for_a_nan_mjcf(command, tmp_path, cli, monkeypatch):
    """``fkopt ik`` gave a traceback, ``fkopt fk`` printed NaN as null with exit 0; and MuJoCo's
    NaN warning wrote MUJOCO_LOG.TXT into the working folder."""
    pytest.importorskip("mujoco")
    monkeypatch.chdir(tmp_path)
    path = mjcf(tmp_path, pos1="nan 0 0")
    geometry = tmp_path / "g.yaml"
    geometry.write_text(f"file: {path}\n")
    args = (["--pose", "x=0.4,y=0,z=0.3,alpha=0,beta=90,gamma=0"] if command == "ik" else ["--joints", "j1=0,j2=0"])
    code, out, err = cli(command, "mjcf", "--geometry", geometry, *args)
    assert code == 2 and "Traceback" not in err and "pos='nan 0 0'" in err and "null" not in out, (out, err)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_break7_an_unnamed_mjcf_joint_never_takes_a_real_joints_name(tmp_path):
    """Break 7: an unnamed joint was named ``joint{j}`` and collided with a real ``joint0``:
    ``fkopt ik`` said solved and printed one joint of two."""
    pytest.importorskip("mujoco")
    path = mjcf(tmp_path, j1='axis="0 0 1" range="-90 90"', j2='name="joint0" axis="0 1 0" range="-90 90"')
    arm = fkopt.mechanism("mjcf", file=str(path), tip="tip")
    assert arm.dof == 2 and len(set(arm.joint_names)) == 2 and "joint0" in arm.joint_names
    q = np.array([[20.0, -30.0]])
    answer = fkopt.inverse(arm, arm.fk(q)[0])
    assert len(answer.joints) == 2


def test_break19_mjcf_range_lower_above_upper_is_refused_like_urdf(tmp_path):
    """Break 19: ``range="1 -1"`` silently became a continuous +-180 deg joint (MuJoCo makes it
    unlimited); URDF refuses lower > upper, and so does MJCF now."""
    pytest.importorskip("mujoco")
    path = mjcf(tmp_path, j1='name="j1" axis="0 0 1" range="1 -1"')
    refused(path, str(path), "joint 'j1' range", "lower 1 > upper -1")


# --- release pins ----------------------------------------------------------------------------------
SUITES = Path(__file__).resolve().parents[1] / "configs" / "suites"


@pytest.mark.parametrize("suite, robot", [("kinbench-v3.yaml", "iiwa-mj.xml"), ("kinbench-v3-robots.yaml", "ur5.urdf")])
def test_v3s_robot_files_are_pinned_by_sha256_like_v1_and_v2(suite, robot, tmp_path):
    """Only v1/v2's robot files were pinned: a v3 robot file could be changed (an expression added to
    an element fkopt ignores) and the suite still ran as released kinbench-v3."""
    import shutil
    from fkopt.kinbench.config import load_suite
    from fkopt.kinbench.posesets import load_pose_sets
    from fkopt.kinbench.releases import RELEASES
    assert "robots/" + robot in RELEASES["kinbench-v3"].files
    for name in ("kinbench-v3", "robots"):
        shutil.copytree(SUITES / name, tmp_path / name)
    shutil.copy(SUITES / suite, tmp_path / suite)
    load_pose_sets(load_suite(tmp_path / suite))            # as released: accepted
    edited = tmp_path / "robots" / robot
    text = edited.read_text()
    cut = text.rindex("</")
    edited.write_text(text[:cut] + '<!-- ${1} -->' + text[cut:])
    with pytest.raises(FkoptError) as err:
        load_pose_sets(load_suite(tmp_path / suite))
    assert f"robots/{robot}: differs from released kinbench-v3" in str(err.value) and "\n" not in str(err.value)
