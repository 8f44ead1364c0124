"""Serial arms read from MJCF (MuJoCo) files: ``fkopt.mechanism("mjcf", file="arm.xml", base="link0", tip="tool")``.

Before MuJoCo opens anything, fkopt checks the file and every file it names
(:func:`check_mjcf_files`: includes and assets inside the file's folder, regular files, size
caps, bounded nesting, no NaN or inf); afterwards every number it takes from the compiled model
meets URDF's rule (:func:`fkopt.mechanisms.urdf.check_numbers`) and a range with lower > upper
is refused as URDF refuses it (docs/reliability.md section 10).

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
import os
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from pydantic import Field

from fkopt.errors import FkoptError, did_you_mean
from fkopt.files import (check_geometry_file, check_within, open_input, parse_xml, png_size, read_input,
                         short_token)
from fkopt.numerics import rotations
from fkopt.mechanisms.urdf import URDFArm, URDFGeometry, check_numbers

DEFAULT_FILE = Path(__file__).resolve().parent / "data" / "wang7dof.xml"
#: Largest MJCF file compiled (bytes), as for URDF: kinematic descriptions are kilobytes.
MAX_MJCF_BYTES = 4 << 20


class MJCFGeometry(URDFGeometry):
    file: str = Field(str(DEFAULT_FILE), description="MJCF file (relative: to the config's folder)")
    base: str | None = Field(None, description="body the chain starts from (default: the world body)")
    tip: str | None = Field(None, description="body or site the chain ends at (default: the only leaf body "
                                              "below base)")


#: Largest file an MJCF names (a mesh, texture, height field, skin or model asset; bytes), and the
#: most all of them may hold together, counted per reference (MuJoCo loads a file once per asset
#: naming it). Robot meshes are megabytes (robosuite's largest 9 MB); a 300-byte MJCF naming a
#: 1.9 GB mesh took 1.97 GB, and MuJoCo's peak memory is about 20 times the mesh bytes it
#: compiles (docs/reliability.md).
MAX_MJCF_ASSET_BYTES = 16 << 20
MAX_MJCF_TOTAL_BYTES = 64 << 20
#: Most pixels of a PNG texture or height field (MuJoCo decodes it whole: 4 bytes a pixel); a
#: small PNG can declare 30 000 x 30 000 pixels.
MAX_PNG_PIXELS = 4096 * 4096
#: Most files one MJCF may name, includes and assets together.
MAX_MJCF_FILES = 4096
#: <compiler> attributes naming the folders assets are read from (relative to the top file's folder).
_ASSET_DIRS = ("meshdir", "texturedir", "assetdir")


def check_mjcf_files(path: Path) -> None:
    """Every file MuJoCo would open for the MJCF ``path`` gets the top file's checks before MuJoCo
    opens any (issue 42): each ``<include file>``, recursively, bounded in bytes
    (:data:`MAX_MJCF_BYTES`) and in nesting (:data:`fkopt.files.MAX_XML_DEPTH`); every attribute
    naming a file (``file``, ``fileright``, ... on any element) and the ``<compiler>`` folders a
    relative path without ``..`` that resolves, links included, inside the top file's folder, to
    a regular file (not a FIFO, which blocked MuJoCo forever, nor a device) of at most
    :data:`MAX_MJCF_ASSET_BYTES`; all files named, counted per reference, at most
    :data:`MAX_MJCF_TOTAL_BYTES`; a PNG at most :data:`MAX_PNG_PIXELS`. MuJoCo looks for a name
    beside the top file and beside the file naming it, joined to the compiler's folders or not
    (``strippath``: the name without its folder), so every such candidate that exists is
    checked. One line naming the file."""
    folder = path.resolve().parent
    where = f"mjcf {path}"
    total, count = 0, 0

    def counted(fd: int, what: str) -> bytes:
        """The first 24 bytes of an opened file, its size added to the total (closed here)."""
        nonlocal total, count
        with os.fdopen(fd, "rb") as fh:
            size, head = os.fstat(fh.fileno()).st_size, fh.read(24)
        total, count = total + size, count + 1
        if count > MAX_MJCF_FILES:
            raise FkoptError(f"{where}: names more than {MAX_MJCF_FILES} files")
        if total > MAX_MJCF_TOTAL_BYTES:
            raise FkoptError(f"{where}: the files it names hold more than {MAX_MJCF_TOTAL_BYTES >> 20} MB together "
                             f"(at {what}), the most accepted")
        return head

    docs, queue, seen = [], [(path, None)], set()
    while queue:
        f, what = queue.pop()
        if what is not None:
            counted(open_input(f, MAX_MJCF_BYTES, what, within=folder), what)
        key = f.resolve()
        if key in seen:                        # parsed once; counted per reference above
            continue
        seen.add(key)
        field = "mjcf geometry.file" if what is None else what
        root = parse_xml(read_input(f, MAX_MJCF_BYTES, field=field, within=None if what is None else folder),
                         f"mjcf {f}")
        docs.append((root, key.parent))
        for inc in root.iter():
            name = inc.get("file")
            if inc.tag not in _XML_FILES or name is None:
                continue
            label = f"{where}: <{inc.tag} file='{short_token(name)}'>"
            for candidate in dict.fromkeys((_inside(folder, name, label), _inside(key.parent, name, label))):
                if candidate.exists() or candidate.is_symlink():
                    queue.append((candidate, label))
    bases = list(dict.fromkeys([folder, *(d for _, d in docs)]))
    dirs = list(bases)
    for root, _ in docs:
        for c in root.iter("compiler"):
            for attr in _ASSET_DIRS:
                value = c.get(attr)
                if value is not None:
                    label = f"{where}: <compiler {attr}='{short_token(value)}'>"
                    for base in bases:
                        d = _inside(base, value, label)
                        if d.exists() or d.is_symlink():
                            check_within(d, folder, label)
                        dirs.append(d)
    dirs = list(dict.fromkeys(dirs))
    for root, _ in docs:
        for e in root.iter():
            if e.tag in _XML_FILES:
                continue
            for attr, value in e.attrib.items():
                # a numeric attribute holding NaN or inf: refused here, as URDF's reader refuses it
                # (MuJoCo compiles it with a warning and writes MUJOCO_LOG.TXT into the working folder)
                if attr not in _NAME_ATTRS and _non_finite(value):
                    raise FkoptError(f"{where}: <{e.tag} {attr}='{short_token(value)}'> is not finite; a robot "
                                     "file's numbers must be")
            for attr, name in e.attrib.items():
                if not attr.startswith("file"):
                    continue
                what = f"{where}: <{e.tag} {attr}='{short_token(name)}'>"
                _inside(folder, name, what)
                for candidate in dict.fromkeys(d / n for d in dirs for n in (name, Path(name).name)):
                    if not candidate.exists() and not candidate.is_symlink():
                        continue
                    head = counted(open_input(candidate, MAX_MJCF_ASSET_BYTES, what, within=folder), what)
                    size = png_size(head)
                    if size is not None:
                        width, height = size
                        if width * height > MAX_PNG_PIXELS:
                            raise FkoptError(f"{what}: a PNG of {width} x {height} pixels; at most {MAX_PNG_PIXELS} "
                                             "pixels are accepted")


#: Elements naming an MJCF file MuJoCo parses in turn: ``<include>`` and ``<asset><model>``
#: (a model to ``<attach>``); each is checked like the top file, and so are the files it names.
_XML_FILES = ("include", "model")
#: Attributes that name things (never numbers), left out of the NaN/inf check.
_NAME_ATTRS = ("name", "class", "childclass", "prefix")


def _non_finite(value: str) -> bool:
    """True for a numeric attribute value (every token a number) with a NaN or infinite token."""
    tokens = value.split()
    try:
        numbers = [float(t) for t in tokens]
    except ValueError:
        return False
    return bool(numbers) and not all(map(math.isfinite, numbers))


def _inside(folder: Path, name: str, what: str) -> Path:
    """``folder / name`` for a relative ``name`` that stays inside ``folder`` as written (no
    absolute path, no ``..``); links are checked where the file is opened."""
    p = Path(name)
    if p.is_absolute() or ".." in p.parts or "\0" in name:
        raise FkoptError(f"{what}: names a file outside {folder}; only files inside the MJCF's folder are read")
    return folder / p


def compile_model(path: Path):
    """MuJoCo's compiled model of an MJCF file; every failure is one line naming the file. Every
    file MuJoCo would open is checked first (:func:`check_mjcf_files`)."""
    check_geometry_file(path, "mjcf", MAX_MJCF_BYTES, "an MJCF file")
    check_mjcf_files(path)
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


def _frame(pos, rot=None) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = pos
    if rot is not None:
        T[:3, :3] = rot
    return T


def read_chain(model, path: Path, base: str | None, tip: str | None) -> list:
    """Joint records (see :meth:`fkopt.mechanisms.urdf.URDFArm._read_chain`) of the chain from
    body ``base`` to body or site ``tip`` of a compiled MuJoCo model (module docstring)."""
    import mujoco
    obj = mujoco.mjtObj
    bodies, sites, joints = _names(model, obj.mjOBJ_BODY), _names(model, obj.mjOBJ_SITE), _names(model, obj.mjOBJ_JOINT)
    taken = {n for n in joints if n}
    for j, name in enumerate(joints):          # unnamed: joint{j}, never a name the file gives a joint
        if not name:
            name, k = f"joint{j}", 1
            while name in taken:
                k += 1
                name = f"joint{j}_{k}"
            joints[j] = name
            taken.add(name)
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

    where = f"mjcf {path}"

    def checked(values, what):                 # URDF's rule for every number (check_numbers)
        return np.array(check_numbers(np.ravel(values), what, where))

    chain, pending, prev = [], np.eye(4), bodies[base_id]
    for b in path_bodies:
        label = f"body '{bodies[b] or b}'"
        pending = pending @ _frame(checked(model.body_pos[b], f"{label} pos"),
                                   rotations.mujoco_quaternion1(checked(model.body_quat[b], f"{label} quat")))
        for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
            kind = int(model.jnt_type[j])
            name = joints[j]
            if kind in (mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_BALL):
                what = "free" if kind == mujoco.mjtJoint.mjJNT_FREE else "ball"
                raise FkoptError(f"mjcf {path}: joint '{name}' on the chain is a {what} joint; the chain may hold "
                                 "hinge and slide joints")
            axis = checked(model.jnt_axis[j], f"joint '{name}' axis")
            axis = axis / np.linalg.norm(axis)
            q0 = float(checked([model.qpos0[model.jnt_qposadr[j]]], f"joint '{name}' ref (qpos0)")[0])
            hinge = kind == mujoco.mjtJoint.mjJNT_HINGE
            anchor = checked(model.jnt_pos[j], f"joint '{name}' pos") if hinge else np.zeros(3)
            held = couplings.get(j)
            if held is not None and held.joint is None:          # held at q0 + a0 by an equality
                d = held.offset
                pending = pending @ (_frame(anchor) @ _frame(np.zeros(3), rotations.axis_angle1(axis, d)) @ _frame(-anchor)
                                     if hinge else _frame(axis * d))
                continue
            # the reference qpos0 goes into the fixed origin: Rot(axis, q - q0) = Rot(axis, -q0) Rot(axis, q)
            origin = pending @ (_frame(anchor, rotations.axis_angle1(axis, -q0)) if hinge else _frame(-q0 * axis))
            limited = bool(model.jnt_limited[j])
            lo, hi = checked(model.jnt_range[j], f"joint '{name}' range")
            if lo > hi:     # MuJoCo makes such a joint unlimited; URDF refuses lower > upper, so does fkopt
                raise FkoptError(f"{where}: joint '{name}' range: lower {lo:g} > upper {hi:g}; needs lower <= upper")
            if not limited and not hinge:
                raise FkoptError(f"mjcf {path}: slide joint '{name}' needs a range")
            chain.append(SimpleNamespace(
                name=name, type=("revolute" if limited else "continuous") if hinge else "prismatic",
                parent=prev, child=bodies[b], origin=origin, axis=axis,
                limit=SimpleNamespace(lower=lo, upper=hi) if limited else None, mimic=held))
            pending, prev = _frame(-anchor), bodies[b]
    if site_id is not None:
        label = f"site '{sites[site_id]}'"
        pending = pending @ _frame(checked(model.site_pos[site_id], f"{label} pos"),
                                   rotations.mujoco_quaternion1(checked(model.site_quat[site_id], f"{label} quat")))
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
            coef = list(check_numbers(model.eq_data[e][:5], f"joint '{joints[a]}' equality polycoef", f"mjcf {path}"))
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
