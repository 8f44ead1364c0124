"""Serial arms read from MJCF (MuJoCo) files: ``fkopt.mechanism("mjcf", file="arm.xml", base="link0", tip="tool")``.

The file is compiled by the ``mujoco`` package's own compiler (``MjModel.from_xml_path``), so
everything MJCF defines -- ``<default>`` classes, ``<include>``, ``euler``/``axisangle``/``xyaxes``
orientations, ``angle="degree"``, ``ref``, ``autolimits`` -- means what MuJoCo says it means;
fkopt reads the compiled model (``body_pos``, ``body_quat``, ``jnt_pos``, ``jnt_axis``,
``jnt_range``, ``qpos0``, ``site_pos``, ``site_quat``, ``eq_*``) and nothing of the XML.

The chain is the bodies from body ``base`` (default: the world body) down to ``tip``: a body or,
when no body has that name, a site (default: the only leaf body below ``base``; name it when the
tree branches). Each body on the way applies its fixed frame (pos, quat) and then its joints in
the order MuJoCo applies them in ``mj_kinematics``: a hinge rotates the body frame by
q - qpos0 about its axis through its anchor ``jnt_pos`` (T <- T Tr(a) Rot(axis, q - q0) Tr(-a)),
a slide translates it by (q - q0) along its axis. The chain is the same list of joint records
(fixed origin, unit axis, limits, mimic) that :class:`fkopt.mechanisms.urdf.URDFArm` builds from
a URDF file, so FK, the Jacobian, bounds, mimic handling and every solver are URDF's:

* unknowns are MuJoCo's qpos of the chain's hinges (deg) and slides (m); ``jnt_range`` gives the
  bounds; a hinge without a range is continuous (bounds [-180, 180] deg, periodic), a slide
  without one is refused (as URDF refuses a prismatic joint without limits);
* an active ``<equality><joint joint1 joint2 polycoef>`` with only a0, a1 non-zero couples
  joint1 to joint2 as a URDF mimic: q1 - q1_0 = a0 + a1 (q2 - q2_0); without joint2, joint1 is
  held at q1_0 + a0 (a fixed joint);
* refused with one line naming the file: a free or ball joint on the chain, a nonlinear joint
  equality, a tendon equality over a chain joint, an active connect/weld on a chain body (a
  closed loop), a coupling to a joint off the chain, an unknown body, site or joint.

Lengths stay in metres; the pose is the tip frame in the base body's frame as for URDF (x, y, z,
Z-Y-Z Euler angles in degrees). ``geometry.tool`` adds a tool frame on the tip as for URDF.
Without ``file`` the mechanism is wang7dof's arm written as MJCF (``mechanisms/data/wang7dof.xml``),
which gives the same poses as ``urdf`` without ``file``.
"""
from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from pydantic import Field

from fkopt.errors import FkoptError, did_you_mean
from fkopt.files import check_geometry_file
from fkopt.mechanisms.urdf import URDFArm, URDFGeometry

DEFAULT_FILE = Path(__file__).resolve().parent / "data" / "wang7dof.xml"
#: Largest MJCF file compiled (bytes), as for URDF: kinematic descriptions are kilobytes.
MAX_MJCF_BYTES = 4 << 20


class MJCFGeometry(URDFGeometry):
    file: str = Field(str(DEFAULT_FILE), description="MJCF file (relative: to the config's folder)")
    base: str | None = Field(None, description="body the chain starts from (default: the world body)")
    tip: str | None = Field(None, description="body or site the chain ends at (default: the only leaf body "
                                              "below base)")


def compile_model(path: Path):
    """MuJoCo's compiled model of an MJCF file; every failure is one line naming the file."""
    check_geometry_file(path, "mjcf", MAX_MJCF_BYTES, "an MJCF file")
    try:
        import mujoco
    except ImportError:
        raise FkoptError("mjcf needs the mujoco package: pip install 'fkopt[mjcf]'") from None
    try:
        return mujoco.MjModel.from_xml_path(str(path))
    except Exception as err:                  # mujoco raises ValueError with the compiler's message
        why = " ".join(str(err).split())
        raise FkoptError(f"mjcf {path}: MuJoCo cannot compile it ({why})") from None


def _names(model, kind) -> list[str]:
    import mujoco
    count = {mujoco.mjtObj.mjOBJ_BODY: model.nbody, mujoco.mjtObj.mjOBJ_SITE: model.nsite,
             mujoco.mjtObj.mjOBJ_JOINT: model.njnt}[kind]
    return [mujoco.mj_id2name(model, kind, i) or "" for i in range(count)]


def _quat_matrix(q) -> np.ndarray:
    """Rotation matrix of a unit quaternion (w, x, y, z), MuJoCo's convention (mju_quat2Mat)."""
    w, x, y, z = (float(v) for v in q)
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


def _frame(pos, rot=None) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = pos
    if rot is not None:
        T[:3, :3] = rot
    return T


def _axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by ``angle`` (rad) about the unit ``axis`` (Rodrigues)."""
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def read_chain(model, path: Path, base: str | None, tip: str | None) -> list:
    """Joint records (see :meth:`fkopt.mechanisms.urdf.URDFArm._read_chain`) of the chain from
    body ``base`` to body or site ``tip`` of a compiled MuJoCo model (module docstring)."""
    import mujoco
    obj = mujoco.mjtObj
    bodies, sites, joints = _names(model, obj.mjOBJ_BODY), _names(model, obj.mjOBJ_SITE), _names(model, obj.mjOBJ_JOINT)
    base_id = 0 if base is None else (bodies.index(base) if base in bodies else None)
    if base_id is None:
        raise FkoptError(f"mjcf {path}: unknown body '{base}' (geometry.base); bodies: "
                         f"{did_you_mean(base, [b for b in bodies if b])}")
    parent = model.body_parentid
    below = [b for b in range(model.nbody) if b != base_id and _above(parent, base_id, b)]
    site_id = None
    if tip is None:
        leaves = [b for b in below if not any(parent[c] == b for c in range(1, model.nbody))]
        if len(leaves) != 1:
            raise FkoptError(f"mjcf {path}: the tree below '{bodies[base_id]}' has {len(leaves)} leaf bodies ("
                             f"{', '.join(sorted(bodies[b] for b in leaves)[:12])}); name geometry.tip")
        tip_body = leaves[0]
    elif tip in bodies:
        tip_body = bodies.index(tip)
    elif tip in sites:
        site_id = sites.index(tip)
        tip_body = int(model.site_bodyid[site_id])
    else:
        raise FkoptError(f"mjcf {path}: unknown body or site '{tip}' (geometry.tip); bodies and sites: "
                         f"{did_you_mean(tip, [n for n in bodies + sites if n])}")
    if tip_body != base_id and tip_body not in below:
        raise FkoptError(f"mjcf {path}: '{tip}' is not below body '{bodies[base_id]}' (no chain between them)")
    path_bodies, b = [], tip_body
    while b != base_id:
        path_bodies.append(b)
        b = int(parent[b])
    path_bodies.reverse()
    on_chain = {j for b in path_bodies for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b])}
    couplings = _couplings(model, path, on_chain, set(path_bodies), bodies, joints)

    chain, pending, prev = [], np.eye(4), bodies[base_id]
    for b in path_bodies:
        pending = pending @ _frame(model.body_pos[b], _quat_matrix(model.body_quat[b]))
        for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
            kind = int(model.jnt_type[j])
            name = joints[j] or f"joint{j}"
            if kind in (mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_BALL):
                what = "free" if kind == mujoco.mjtJoint.mjJNT_FREE else "ball"
                raise FkoptError(f"mjcf {path}: joint '{name}' on the chain is a {what} joint; the chain may hold "
                                 "hinge and slide joints")
            axis = np.array(model.jnt_axis[j], dtype=float)
            axis = axis / np.linalg.norm(axis)
            q0 = float(model.qpos0[model.jnt_qposadr[j]])
            hinge = kind == mujoco.mjtJoint.mjJNT_HINGE
            anchor = np.array(model.jnt_pos[j], dtype=float) if hinge else np.zeros(3)
            held = couplings.get(j)
            if held is not None and held.joint is None:          # held at q0 + a0 by an equality
                d = held.offset
                pending = pending @ (_frame(anchor) @ _frame(np.zeros(3), _axis_angle(axis, d)) @ _frame(-anchor)
                                     if hinge else _frame(axis * d))
                continue
            # the reference qpos0 goes into the fixed origin: Rot(axis, q - q0) = Rot(axis, -q0) Rot(axis, q)
            origin = pending @ (_frame(anchor, _axis_angle(axis, -q0)) if hinge else _frame(-q0 * axis))
            limited = bool(model.jnt_limited[j])
            lo, hi = (float(v) for v in model.jnt_range[j])
            if not limited and not hinge:
                raise FkoptError(f"mjcf {path}: slide joint '{name}' needs a range")
            chain.append(SimpleNamespace(
                name=name, type=("revolute" if limited else "continuous") if hinge else "prismatic",
                parent=prev, child=bodies[b], origin=origin, axis=axis,
                limit=SimpleNamespace(lower=lo, upper=hi) if limited else None, mimic=held))
            pending, prev = _frame(-anchor), bodies[b]
    if site_id is not None:
        pending = pending @ _frame(model.site_pos[site_id], _quat_matrix(model.site_quat[site_id]))
    if not chain:
        raise FkoptError(f"mjcf {path}: no hinge or slide joint between '{bodies[base_id]}' and '{tip}'")
    chain.append(SimpleNamespace(name="(tip)", type="fixed", parent=prev,
                                 child=tip if tip is not None else bodies[tip_body], origin=pending,
                                 axis=None, limit=None, mimic=None))
    return chain


def _above(parent, ancestor: int, b: int) -> bool:
    while b != 0:
        b = int(parent[b])
        if b == ancestor:
            return True
    return ancestor == 0


def _couplings(model, path: Path, on_chain: set, chain_bodies: set, bodies, joints) -> dict:
    """Active equality constraints touching the chain, as URDF mimics: joint id -> SimpleNamespace
    (joint = master's name or None for a joint held still, multiplier, offset in SI units of
    qpos). Couplings the serial-arm model cannot express are refused (module docstring)."""
    import mujoco
    eq = mujoco.mjtEq
    out = {}
    for e in range(model.neq):
        if not model.eq_active0[e]:
            continue
        kind, a, b = int(model.eq_type[e]), int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
        if kind == eq.mjEQ_JOINT and a in on_chain:
            coef = [float(v) for v in model.eq_data[e][:5]]
            if any(coef[2:]):
                raise FkoptError(f"mjcf {path}: joint '{joints[a]}' is coupled by a nonlinear joint equality "
                                 f"(polycoef {' '.join(f'{c:g}' for c in coef)}); only q1 = a0 + a1 q2 is supported")
            y0 = float(model.qpos0[model.jnt_qposadr[a]])
            if b < 0:
                out[a] = SimpleNamespace(joint=None, multiplier=0.0, offset=coef[0])
                continue
            if b not in on_chain:
                raise FkoptError(f"mjcf {path}: joint '{joints[a]}' follows joint '{joints[b]}', which is not on "
                                 "the chain")
            x0 = float(model.qpos0[model.jnt_qposadr[b]])
            # q_a - y0 = a0 + a1 (q_b - x0); the chain's origin already holds -y0 (q_a is qpos)
            out[a] = SimpleNamespace(joint=joints[b], multiplier=coef[1], offset=y0 + coef[0] - coef[1] * x0)
        elif kind == eq.mjEQ_JOINT and b in on_chain:
            raise FkoptError(f"mjcf {path}: joint '{joints[a]}' (off the chain) is coupled to chain joint "
                             f"'{joints[b]}'; the chain must hold both")
        elif kind == eq.mjEQ_TENDON:
            for t in (a, b):
                if t >= 0 and _tendon_joints(model, t) & on_chain:
                    raise FkoptError(f"mjcf {path}: a tendon equality couples joints of the chain; tendon "
                                     "couplings are not supported")
        elif kind in (eq.mjEQ_CONNECT, eq.mjEQ_WELD) and int(model.eq_objtype[e]) == mujoco.mjtObj.mjOBJ_BODY \
                and {a, b} & chain_bodies:
            raise FkoptError(f"mjcf {path}: an active connect/weld equality on body "
                             f"'{bodies[a if a in chain_bodies else b]}' closes a loop; the chain must be serial")
    return out


def _tendon_joints(model, t: int) -> set:
    import mujoco
    adr, num = int(model.tendon_adr[t]), int(model.tendon_num[t])
    return {int(model.wrap_objid[w]) for w in range(adr, adr + num)
            if int(model.wrap_type[w]) == mujoco.mjtWrap.mjWRAP_JOINT}


class MJCFArm(URDFArm):
    """Serial arm from an MJCF chain compiled by MuJoCo (module docstring). Lengths in m, angles in deg."""

    name = "mjcf"
    Geometry = MJCFGeometry

    def _read_chain(self, path: Path, g) -> list:
        return read_chain(compile_model(path), path, g.base, g.tip)
