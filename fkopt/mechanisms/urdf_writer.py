"""A minimal kinematic URDF written from fkopt's own chain of a serial arm, for packages that read
only URDF (roboticstoolbox, TRAC-IK, ikpy): MJCF arms, DH tables, arms with a tool frame.

The chain is the one every fkopt solver uses, :meth:`arm.chain` (:class:`fkopt.numerics.chain.Chain`):
moving joint i turns (or slides) about the z axis of its frame F_i = F_{i-1} [C_i, v_i], then a
fixed tail [C, v] (fixed joints, tool). Written as URDF: per moving joint one joint whose
``<origin>`` is [C_i, v_i] (xyz, and rpy as URDF reads it, R = Rz(yaw) Ry(pitch) Rx(roll)) and whose
axis is +z, or -z when it moves with multiplier -1; a constant joint offset (a DH theta offset)
is folded into the origin, so the URDF joint's value is fkopt's unknown (deg -> rad, length unit
-> m) and its ``<limit>`` the arm's bounds; the tail is a fixed joint. A rotation whose pitch is
within 0.1 rad of +-90 deg (where rpy loses digits) is written as two origins, a fixed joint
with [C Ry(90 deg), v] and then Ry(-90 deg) on the joint. Links carry no inertia, visuals or
collisions.

Only the chain's unknowns are written: a joint that follows another (a mimic with a multiplier
other than 0) has no plain-URDF form, and the writer refuses it with one line; a mimic with
multiplier 0 is a fixed joint and is written as one.

Names: the only text copied from the robot's file is the moving joints' names, and every one is
made safe first (:func:`safe_joint_names`): characters outside [A-Za-z0-9_] become ``_``, at most
64 characters, unique. XML escaping alone is not enough: roboticstoolbox runs xacro on what it
reads, and xacro evaluates ``${...}`` and ``$(...)`` in every attribute (issue 42: a joint name
ran a command). The writer's own links and fixed joints hold a ``-`` (``fkopt-base``,
``fkopt-link3``, ``fkopt-fixed4``), which no safe joint name holds, so an arm's own ``fixed3``
or ``base`` cannot collide with them.
"""
from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from fkopt.errors import FkoptError
from fkopt.numerics import rotations

#: Length unit of an arm's poses -> metres.
LENGTH_SCALE = {"m": 1.0, "mm": 1e-3}
#: A pitch this close to +-90 deg (cos below this) is written through a second origin (docstring).
GIMBAL_COS = math.sin(0.1)
BASE_LINK, TIP_LINK = "fkopt-base", "fkopt-tip"
#: Longest joint name written (characters).
MAX_NAME = 64
_UNSAFE = re.compile(r"[^A-Za-z0-9_]")


def safe_joint_names(names) -> tuple[str, ...]:
    """The joint names as written (module docstring): only [A-Za-z0-9_], 1..64 characters,
    unique; a name already safe is kept as it is, the others are changed (``_`` for each unsafe
    character, then ``_2``, ``_3``, ... until unused)."""
    names = [str(n) for n in names]
    kept = {n for n in names if n and len(n) <= MAX_NAME and not _UNSAFE.search(n)}
    out, used = [], set()
    for n in names:
        if n in kept and n not in used:
            out.append(n)
            used.add(n)
            continue
        stem = (_UNSAFE.sub("_", n) or "joint")[:MAX_NAME - 8]
        name, k = stem, 1
        while name in used or name in kept:
            k += 1
            name = f"{stem}_{k}"
        out.append(name)
        used.add(name)
    return tuple(out)


@dataclass(frozen=True)
class WrittenURDF:
    """The URDF text of an arm's chain, its base and tip links and its moving joints (the arm's
    unknowns, in the arm's order)."""
    text: str
    base_link: str
    tip_link: str
    joint_names: tuple[str, ...]


def _origins(C: np.ndarray, v: np.ndarray) -> list[tuple[tuple, tuple]]:
    """(xyz, rpy) of the one or two origins whose product is [C, v] (module docstring)."""
    if math.hypot(C[0, 0], C[1, 0]) >= GIMBAL_COS:
        return [(tuple(v), rotations.zyx_angles1(C))]
    return [(tuple(v), rotations.zyx_angles1(C @ rotations.ry1(math.pi / 2))), ((0.0, 0.0, 0.0), (0.0, -math.pi / 2, 0.0))]


def chain_urdf(arm) -> WrittenURDF:
    """The URDF of ``arm``'s chain (module docstring); refused with one line for a joint that
    follows another (mimic) or an arm without a chain."""
    if not hasattr(arm, "chain"):
        raise FkoptError(f"{getattr(arm, 'name', 'this mechanism')}: no serial chain to write as URDF")
    ch = arm.chain()
    scale = LENGTH_SCALE.get(arm.pose_units[0])
    if scale is None:
        raise FkoptError(f"{arm.name}: length unit '{arm.pose_units[0]}' has no URDF form; allowed: "
                         f"{', '.join(LENGTH_SCALE)}")
    uses = np.bincount(ch.var, minlength=ch.dof)
    names, units = list(safe_joint_names(arm.joint_names)), list(arm.joint_units)
    robot = ET.Element("robot", name=f"fkopt-{_UNSAFE.sub('_', str(arm.name))[:MAX_NAME]}")
    ET.SubElement(robot, "link", name=BASE_LINK)
    counter = iter(range(1 << 30))
    parent = BASE_LINK

    def joint(name, kind, xyz, rpy, axis=None):
        nonlocal parent
        child = f"fkopt-link{next(counter)}"
        ET.SubElement(robot, "link", name=child)
        j = ET.SubElement(robot, "joint", name=name, type=kind)
        ET.SubElement(j, "parent", link=parent)
        ET.SubElement(j, "child", link=child)
        ET.SubElement(j, "origin", xyz=" ".join(repr(float(x) * 1.0) for x in xyz),
                      rpy=" ".join(repr(float(a)) for a in rpy))
        if axis is not None:
            ET.SubElement(j, "axis", xyz=" ".join(repr(float(a)) for a in axis))
        parent = child
        return j

    def fixed(C, v):
        for xyz, rpy in _origins(C, v):
            joint(f"fkopt-fixed{len(robot)}", "fixed", xyz, rpy)

    bounds = np.asarray(arm.bounds, dtype=float)
    periodic = arm.periodic_mask()
    for i in range(len(ch.var)):
        k, mult, off, prismatic = int(ch.var[i]), float(ch.mult[i]), float(ch.off[i]), bool(ch.prismatic[i])
        C, v = np.asarray(ch.C[i], float), np.asarray(ch.v[i], float) * scale
        off_si = off * scale if prismatic else off
        if prismatic:                                  # q = mult t + off along z: the offset moves the origin
            v, motion = v + off_si * C[:, 2], np.eye(3)
        else:
            motion = rotations.rz1(off)
        if mult == 0.0:
            fixed(C @ motion, v)
            continue
        if abs(mult) != 1.0 or uses[k] != 1:
            raise FkoptError(f"{arm.name} {getattr(arm, 'path', '')}: joint of unknown '{arm.joint_names[k]}' follows another "
                             f"joint (mimic, multiplier {mult:g}); a URDF of the chain's unknowns cannot hold it")
        origins = _origins(C @ motion, v)
        for xyz, rpy in origins[:-1]:
            joint(f"fkopt-fixed{len(robot)}", "fixed", xyz, rpy)
        xyz, rpy = origins[-1]
        kind = "prismatic" if prismatic else ("continuous" if periodic[k] else "revolute")
        j = joint(names[k], kind, xyz, rpy, axis=(0.0, 0.0, mult))
        to_si = scale if units[k] != "deg" else math.pi / 180.0
        if units[k] not in ("deg", arm.pose_units[0]):
            raise FkoptError(f"{arm.name}: joint '{names[k]}' in '{units[k]}' has no URDF form")
        lo, hi = bounds[k] * to_si
        limit = {"effort": "1", "velocity": "1"}
        if kind != "continuous":
            limit.update(lower=repr(float(lo)), upper=repr(float(hi)))
        ET.SubElement(j, "limit", **limit)
    fixed(np.asarray(ch.tail_C, float), np.asarray(ch.tail_v, float) * scale)
    robot.find(f"link[@name='{parent}']").set("name", TIP_LINK)
    robot.findall("joint")[-1].find("child").set("link", TIP_LINK)
    ET.indent(robot)
    return WrittenURDF(ET.tostring(robot, encoding="unicode"), BASE_LINK, TIP_LINK, tuple(names))
