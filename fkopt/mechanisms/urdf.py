"""Serial arms read from URDF files: ``fkopt.mechanism("urdf", file="arm.urdf", base="link0", tip="tool")``.

The chain is the joints from link ``base`` (default: the root link) to link ``tip``
(default: the only leaf link; name it when the tree branches). Each joint applies its fixed
``origin`` (xyz, rpy as URDF defines them: R = Rz(yaw) Ry(pitch) Rx(roll)) and then its motion
about/along its unit ``axis``: revolute and continuous joints rotate (unknowns in degrees),
prismatic joints translate (unknowns in metres), fixed joints only carry their origin.
Lengths stay in metres, as URDF has them; the pose is (x, y, z) of the tip frame's origin
in the base frame plus the Z-Y-Z Euler angles (degrees) of :class:`fkopt.mechanisms.dh_arm.DHArm`,
so :class:`fkopt.problems.IKProblem` treats both alike.

Bounds: revolute and prismatic joints take ``<limit lower upper>`` from the file; continuous
joints (no limits) get [-180, 180] deg and are *periodic* (``arm.periodic``): solvers may move
them through any angle and ``fkopt.inverse`` wraps the answer into [-180, 180). Any joint's
bounds can be overridden by the config's ``mechanism.bounds`` as for every mechanism (a
continuous joint given bounds is no longer periodic). In an experiment file, a relative
``geometry.file`` is relative to the config file's folder (see
:func:`fkopt.kinds.experiment.runner.build_mechanism`); from Python, to the working directory.
Without ``file`` the mechanism is wang7dof's arm written as URDF (``mechanisms/data/wang7dof.urdf``),
which gives the same poses as ``7dof-arm`` with lengths in metres instead of millimetres.

Mimic joints (``<mimic joint multiplier offset>``) are not unknowns: q = multiplier * q_master
+ offset (SI units, as URDF defines it), through chains of mimics; their limits narrow the
master's bounds, so every answer inside the bounds keeps them. A mimic whose master is not on
the chain is refused with one line. ``geometry.tool`` adds a tool (TCP) frame on the tip link.

Parsing uses the standard library's XML parser (links and joints only). FK and the analytic geometric frame Jacobian
(:meth:`URDFArm.frame_jacobian`) share one recursion (:meth:`URDFArm._walk`), elementwise over
the batch (no matmul), so batching never changes the numbers; ``frame_jacobian1`` is the same
recursion on Python floats for a single configuration.
"""
from __future__ import annotations

import math
import re
import sys
from collections import Counter
from importlib import metadata
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
from pydantic import Field, ValidationError

from fkopt.errors import FkoptError, did_you_mean
from fkopt.files import MAX_MAGNITUDE, check_geometry_file, parse_xml, read_input, short_token
from fkopt.numerics import rotations
from fkopt.numerics.chain import frame_jacobian1, from_terms
from fkopt.mechanisms.base import FrameArm, Geometry, describe_validation_error

DEFAULT_FILE = Path(__file__).resolve().parent / "data" / "wang7dof.urdf"
#: Bounds of continuous joints unless the config gives them (deg).
CONTINUOUS_BOUNDS = (-180.0, 180.0)
MOVING = ("revolute", "continuous", "prismatic")


class URDFGeometry(Geometry):
    file: str = Field(str(DEFAULT_FILE), description="URDF file (relative: to the config's folder)")
    base: str | None = Field(None, description="first link of the chain (default: the root link)")
    tip: str | None = Field(None, description="last link of the chain (default: the only leaf link)")
    tool: list[float] | None = Field(None, min_length=6, max_length=6,
                                     description="tool (TCP) frame on the tip link: x, y, z (m), roll, pitch, "
                                                 "yaw (deg, R = Rz(yaw) Ry(pitch) Rx(roll) as URDF origins)")


def _floats(text, count: int, default, what: str, path: Path) -> tuple:
    if text is None:
        return default
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != count or not all(map(math.isfinite, values)):
        raise FkoptError(f"urdf {path}: malformed URDF ({what}: expected {count} numbers, got '{short_token(text)}')")
    return check_numbers(values, what, f"urdf {path}")


def check_numbers(values, what: str, where: str) -> tuple[float, ...]:
    """The rule every number of a robot file meets (URDF's, and MJCF's as MuJoCo compiled it):
    finite and |v| <= :data:`MAX_URDF_VALUE` (m, rad); else one line naming ``where`` (format
    and file) and ``what`` (element and field). Checked before any cast or product."""
    values = tuple(float(v) for v in values)
    shown = short_token(" ".join(f"{v:g}" for v in values))
    if not all(map(math.isfinite, values)):
        raise FkoptError(f"{where}: {what}: {shown} is not finite; a robot file's numbers must be")
    if any(abs(v) > MAX_URDF_VALUE for v in values):
        raise FkoptError(f"{where}: {what}: {shown} is past the bound |v| <= {MAX_URDF_VALUE:g} "
                         "(m, rad) accepted for a robot file's number")
    return values


#: Most joints (moving, fixed and mimic) on the chain base -> tip: real arms have tens; FK, the
#: Jacobian and IK are linear in the chain's length and a 2000-joint IK took 30 s.
MAX_CHAIN_JOINTS = 1000
#: Largest magnitude of a number of a URDF file (lengths in m, angles in rad, factors): the one
#: bound of :data:`fkopt.files.MAX_MAGNITUDE`.
MAX_URDF_VALUE = MAX_MAGNITUDE


#: Largest URDF file read (bytes): a robot description with meshes referenced, not inlined, is
#: kilobytes; a parsed tree takes tens of times its file size in memory.
MAX_URDF_BYTES = 4 << 20


#: An attribute or element name with a namespace prefix (``drake:acceleration``).
_PREFIXED = re.compile(rb"[<\s/]([A-Za-z_][\w.-]*):[A-Za-z_][\w.-]*")
#: Prefixes already warned about, per file: the warning is one line per file and process.
_WARNED: set[tuple[str, tuple[str, ...]]] = set()


def _with_undeclared_prefixes(data: bytes, path: Path, err) -> Any:
    """The URDF parsed with its undeclared namespace prefixes bound to placeholder namespaces,
    after one warning line on stderr. Robot files written for one tool carry that tool's
    extensions without declaring them (airo-models' UR3e: ``<limit drake:acceleration=...>``);
    pinocchio's and yourdfpy's readers ignore such attributes and read the file, so fkopt does
    too -- it reads no prefixed attribute or element, so the kinematics are the file's.
    XML 1.0 names (https://www.w3.org/TR/xml-names/#ns-decl): ``xml`` is bound by definition."""
    declared = {m.decode() for m in re.findall(rb"xmlns:([A-Za-z_][\w.-]*)\s*=", data)} | {"xml", "xmlns"}
    used = sorted({m.decode() for m in _PREFIXED.findall(data)} - declared)
    if not used:
        raise FkoptError(f"urdf {path}: malformed URDF ({err})") from None
    root_tag = re.search(rb"<robot\b", data)
    if root_tag is None:
        raise FkoptError(f"urdf {path}: malformed URDF ({err})") from None
    bindings = b"".join(b' xmlns:%s="urn:fkopt:undeclared:%s"' % (p.encode(), p.encode()) for p in used)
    patched = data[:root_tag.end()] + bindings + data[root_tag.end():]
    try:
        root = parse_xml(patched, f"urdf {path}")
    except FkoptError:
        raise FkoptError(f"urdf {path}: malformed URDF ({err})") from None
    key = (str(path), tuple(used))
    if key not in _WARNED:
        _WARNED.add(key)
        print(f"fkopt: warning: urdf {path}: undeclared XML prefix {', '.join(repr(p + ':') for p in used)}; "
              "its attributes and elements are ignored (as pinocchio and yourdfpy read the file)", file=sys.stderr)
    return root


def load_urdf(path: Path) -> SimpleNamespace:
    """The links and joints of a URDF file (what a kinematic chain needs: no meshes, inertias
    or transmissions), read bounded (:func:`fkopt.files.read_input`) with the standard library's
    XML parser -- importing a URDF library cost 1.3-2.0 s per process. Every failure is one line
    naming the file. ``name``: the robot's; each joint keeps its XML ``element`` too (the cutter of
    kinbench's robot copies, :func:`fkopt.kinbench.robots.cut_urdf`, copies its attribute strings
    verbatim)."""
    check_geometry_file(path, "urdf", MAX_URDF_BYTES, "a URDF file")
    data = read_input(path, MAX_URDF_BYTES, field="urdf geometry.file")
    try:
        root = parse_xml(data, f"urdf {path}")           # nesting bounded (MAX_XML_DEPTH)
    except FkoptError as err:
        if "unbound prefix" not in str(err):
            raise FkoptError(str(err).replace("malformed XML", "malformed URDF")) from None
        root = _with_undeclared_prefixes(data, path, str(err).split("malformed XML (", 1)[-1].rstrip(")"))
    links = {e.get("name"): e for e in root.findall("link")}
    if root.tag != "robot" or not links or None in links:
        raise FkoptError(f"urdf {path}: malformed URDF (no <robot> with named links)")
    joints = {}
    for e in root.findall("joint"):
        name, kind = e.get("name"), e.get("type")
        parent, child = e.find("parent"), e.find("child")
        if not name or not kind or parent is None or child is None or not parent.get("link") \
                or not child.get("link"):
            raise FkoptError(f"urdf {path}: malformed URDF (joint '{name}' needs name, type, "
                             "<parent link> and <child link>)")
        if name in joints:
            raise FkoptError(f"urdf {path}: malformed URDF (joint '{name}' is defined twice)")
        origin = np.eye(4)
        o = e.find("origin")
        if o is not None:
            origin[:3, 3] = _floats(o.get("xyz"), 3, (0.0, 0.0, 0.0), f"joint '{name}' origin xyz", path)
            origin[:3, :3] = rotations.zyx1(*_floats(o.get("rpy"), 3, (0.0, 0.0, 0.0), f"joint '{name}' origin rpy", path))
        ax = e.find("axis")
        axis = _floats(None if ax is None else ax.get("xyz"), 3, (1.0, 0.0, 0.0), f"joint '{name}' axis", path)
        lim = e.find("limit")
        limit = None
        if lim is not None and lim.get("lower") is not None and lim.get("upper") is not None:
            limit = SimpleNamespace(lower=_floats(lim.get("lower"), 1, None, f"joint '{name}' limit lower", path)[0],
                                    upper=_floats(lim.get("upper"), 1, None, f"joint '{name}' limit upper", path)[0])
            if limit.lower > limit.upper:     # not swapped: a reversed pair is a mistake in the file
                raise FkoptError(f"urdf {path}: joint '{name}' <limit>: lower {limit.lower:g} > upper "
                                 f"{limit.upper:g}; needs lower <= upper")
        mi = e.find("mimic")
        mimic = None
        if mi is not None:
            if not mi.get("joint"):
                raise FkoptError(f"urdf {path}: malformed URDF (joint '{name}': <mimic> needs joint)")
            mimic = SimpleNamespace(
                joint=mi.get("joint"),
                multiplier=_floats(mi.get("multiplier"), 1, (1.0,), f"joint '{name}' mimic multiplier", path)[0],
                offset=_floats(mi.get("offset"), 1, (0.0,), f"joint '{name}' mimic offset", path)[0])
        joints[name] = SimpleNamespace(name=name, type=kind, parent=parent.get("link"), child=child.get("link"),
                                       origin=origin, axis=np.array(axis), limit=limit, mimic=mimic, element=e)
    return SimpleNamespace(name=root.get("name", "robot"), link_map=links, joint_map=joints)


def _inward(a: float, b: float, joint, lo_si: float, hi_si: float) -> tuple[float, float]:
    """Bounds [a, b] of an unknown in degrees, from a joint's limits [lo_si, hi_si] in radians,
    that never lie outside them: rounded to 9 decimals (so +-pi reads as +-180) only where that
    moves a bound inward, else kept as computed; then stepped inward by ulps until the joint
    value ``joint(bound)`` -- the conversion every check of an answer makes -- is within the
    limits. Rounding to the nearest moved a limit outward by up to 8.7e-12 rad (dexmate's
    Vega-1 arm: an exact answer at a limit failed a strict check by 5.6e-12 rad)."""
    def fits(v):
        q = joint(v)
        return lo_si <= q <= hi_si
    out = []
    for v, toward in ((a, math.inf), (b, -math.inf)):
        if not math.isfinite(v):
            out.append(v)
            continue
        r = round(v, 9)
        if (r < v) if toward > 0 else (r > v):      # rounding moved it outward: keep the computed value
            r = v
        for _ in range(64):                         # a few ulps at most (one multiply and add)
            if fits(r):
                break
            r = math.nextafter(r, toward)
        out.append(r)
    return out[0], out[1]


def urdf_chain(robot, path: Path, base: str | None, tip: str | None) -> list:
    """The joints of :func:`load_urdf`'s ``robot`` from link ``base`` to link ``tip``, base
    first: walked up from the tip through each link's parent joint (None: the one root, the one
    leaf). One line naming the file when a link is unknown, the tip is not below the base, the
    joints loop, or the chain is too long, holds an unsupported joint type or no moving joint."""
    links = robot.link_map
    by_child = {j.child: j for j in robot.joint_map.values()}
    parents = {j.parent for j in robot.joint_map.values()}
    for role, name in (("base", base), ("tip", tip)):
        if name is not None and name not in links:
            raise FkoptError(f"urdf {path}: unknown link '{name}' (geometry.{role}); links: "
                             f"{did_you_mean(name, links)}")
    if base is None:
        roots = [n for n in links if n not in by_child]
        if len(roots) != 1:
            raise FkoptError(f"urdf {path}: {len(roots)} root links, name geometry.base; links: "
                             f"{did_you_mean('', links)}")
        base = roots[0]
    if tip is None:
        leaves = [n for n in links if n not in parents]
        if len(leaves) != 1:
            raise FkoptError(f"urdf {path}: the tree has {len(leaves)} leaf links ({', '.join(sorted(leaves))}); "
                             "name geometry.tip")
        tip = leaves[0]
    chain, link = [], tip
    while link != base:
        joint = by_child.get(link)
        if joint is None:
            raise FkoptError(f"urdf {path}: link '{tip}' is not below link '{base}' (no chain between them)")
        chain.append(joint)
        link = joint.parent
        if len(chain) > len(robot.joint_map):
            raise FkoptError(f"urdf {path}: the joints form a loop")
    chain.reverse()
    if len(chain) > MAX_CHAIN_JOINTS:
        raise FkoptError(f"urdf {path}: the chain '{base}' -> '{tip}' has {len(chain)} joints; at most "
                         f"{MAX_CHAIN_JOINTS} are accepted (geometry.base, geometry.tip pick a shorter chain)")
    for j in chain:
        if j.type not in (*MOVING, "fixed"):
            raise FkoptError(f"urdf {path}: joint '{j.name}' has type '{j.type}'; the chain may hold "
                             "revolute, continuous, prismatic and fixed joints")
    if not any(j.type in MOVING for j in chain):
        raise FkoptError(f"urdf {path}: no moving joint between '{base}' and '{tip}'")
    return chain


#: Entries of the constant rotations within this of 0 or +-1 are snapped to it: URDF files
#: write quarter turns as rpy="0 0 1.5707963267948966", whose cosine is 6e-17, not 0; snapping
#: moves the frame by ~1e-16 and turns most constant products into copies (fewer array ops).
_SNAP = 1e-15


def _align(axis: np.ndarray) -> np.ndarray:
    """A rotation A whose third column is the unit ``axis``, so that Rot(axis, t) = A Rz(t) A^T:
    a signed permutation for a coordinate axis (the common case), else completed by
    Gram-Schmidt."""
    for k in range(3):
        for sign in (1.0, -1.0):
            if np.array_equal(axis, sign * np.eye(3)[k]):
                i, j = (k + 1) % 3, (k + 2) % 3            # e_i x e_j = e_k
                cols = (np.eye(3)[i], sign * np.eye(3)[j], sign * np.eye(3)[k])
                return np.stack(cols, axis=1)
    h = np.eye(3)[int(np.argmin(np.abs(axis)))]
    x = h - (h @ axis) * axis
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(axis, x), axis], axis=1)


def _snap(a: np.ndarray) -> np.ndarray:
    a = np.where(np.abs(a) < _SNAP, 0.0, a)
    return np.where(np.abs(np.abs(a) - 1.0) < _SNAP, np.sign(a), a)


def _terms(C: np.ndarray) -> tuple:
    """The non-zero entries of a constant 3x3 rotation by output column: ((row, value), ...) per
    column, for products ``F C`` written as sums of scaled columns of F."""
    return tuple(tuple((m, float(C[m, c])) for m in range(3) if C[m, c] != 0.0) for c in range(3))


def _combine(cols, terms):
    """Columns of F C (see :func:`_terms`): a copy-free column for a +1 entry, else sums."""
    out = []
    for tc in terms:
        acc = None
        for m, v in tc:
            t = cols[m] if v == 1.0 else (-cols[m] if v == -1.0 else cols[m] * v)
            acc = t if acc is None else acc + t
        out.append(acc)
    return out


def _offset(cols, v):
    """F v for a constant vector v (its non-zero entries only); None when v = 0."""
    acc = None
    for m in range(3):
        if v[m] != 0.0:
            t = cols[m] * v[m]
            acc = t if acc is None else acc + t
    return acc


class URDFArm(FrameArm):
    """Serial arm from a URDF chain (module docstring). Lengths in m, angles in deg."""

    name = "urdf"
    pose_units = ("m", "m", "m", "deg", "deg", "deg")
    Geometry = URDFGeometry
    #: Geometry keys holding file paths (relative ones are resolved against the config's folder).
    file_fields = ("file",)
    # Class-level values describe the default file (wang7dof); each instance sets its own.
    joint_names = tuple(f"q{i + 1}" for i in range(7))
    joint_units = ("deg",) * 7
    default_bounds = {"q1": CONTINUOUS_BOUNDS, "q2": (-90.0, 30.0), "q3": (-90.0, 120.0), "q4": (-90.0, 90.0),
                      "q5": (-90.0, 90.0), "q6": (-90.0, 90.0), "q7": (-30.0, 90.0)}

    def __init__(self, bounds: dict[str, Any] | None = None, **geometry: Any):
        try:
            g = self.Geometry(**geometry)
        except ValidationError as err:
            raise FkoptError(describe_validation_error(err, f"{self.name} geometry")
                             + f" (geometry keys: {did_you_mean('', self.Geometry.model_fields)})") from None
        path = Path(g.file)
        chain = self._read_chain(path, g)
        moving = [j for j in chain if j.type in MOVING]
        on_chain = {j.name: j for j in moving}
        names, units, limits = [], [], {}
        for j in moving:
            if j.mimic is None:
                names.append(j.name)
                units.append("m" if j.type == "prismatic" else "deg")
        twice = sorted(n for n, c in Counter(j.name for j in moving).items() if c > 1)
        if twice:      # two joints answering to one name: one answer column would stand for both
            raise FkoptError(f"{self.name} {path}: two joints of the chain are named '{twice[0]}'; names must be unique")
        index = {n: i for i, n in enumerate(names)}
        to_si = [math.pi / 180.0 if u == "deg" else 1.0 for u in units]

        def source(j):
            """(unknown index, multiplier, offset) of joint j in SI units: q_j = m q_src + o,
            following the chain of mimics iteratively (a 3000-deep chain is no recursion)."""
            steps, seen, start = [], set(), j
            while j.mimic is not None:
                master = on_chain.get(j.mimic.joint)
                if master is None or j.name in seen:
                    why = "is not on the chain" if master is None else "mimics in a loop"
                    raise FkoptError(f"{self.name} {path}: joint '{j.name}' mimics '{j.mimic.joint}', which {why} "
                                     f"between '{chain[0].parent}' and '{chain[-1].child}'")
                seen.add(j.name)
                steps.append(j.mimic)
                j = master
            var, mult, off = index[j.name], 1.0, 0.0
            for m in reversed(steps):      # q = a (m_master q_src + o_master) + b, innermost first
                a = 1.0 if m.multiplier is None else float(m.multiplier)
                b = 0.0 if m.offset is None else float(m.offset)
                mult, off = a * mult, a * off + b
            if not (math.isfinite(mult) and math.isfinite(off)) or abs(mult) > MAX_URDF_VALUE \
                    or abs(off) > MAX_URDF_VALUE:
                raise FkoptError(f"{self.name} {path}: joint '{start.name}': its chain of mimics multiplies to "
                                 f"{mult:g} q + {off:g}, past the bound |v| <= {MAX_URDF_VALUE:g}")
            return var, mult, off

        for j in moving:
            lim = j.limit
            has = lim is not None and lim.lower is not None and lim.upper is not None and j.type != "continuous"
            if j.type != "continuous" and not has:
                raise FkoptError(f"urdf {path}: joint '{j.name}' ({j.type}) needs <limit lower upper>")
            var, mult, off = source(j)
            if not has:
                lo_si, hi_si = -math.inf, math.inf
            else:
                lo_si, hi_si = float(lim.lower), float(lim.upper)
            if mult == 0.0:
                if not lo_si <= off <= hi_si:
                    raise FkoptError(f"{self.name} {path}: joint '{j.name}' mimics with multiplier 0 at offset "
                                     f"{off:g}, outside its limits [{lo_si:g}, {hi_si:g}]")
                continue
            # limits of the joint as limits of its unknown: q_src in [(lo - o)/m, (hi - o)/m]
            a, b = sorted(((lo_si - off) / mult, (hi_si - off) / mult))
            a, b = a / to_si[var], b / to_si[var]
            if units[var] == "deg":
                a, b = _inward(a, b, lambda v: mult * (v * to_si[var]) + off, lo_si, hi_si)
            lo, hi = limits.get(names[var], (-math.inf, math.inf))
            limits[names[var]] = (max(lo, a), min(hi, b))
        periodic = []
        for i, n in enumerate(names):
            lo, hi = limits[n]
            periodic.append(not (math.isfinite(lo) and math.isfinite(hi)))
            if periodic[-1]:                           # continuous: documented range, wrapped
                lo, hi = (max(lo, CONTINUOUS_BOUNDS[0]) if math.isfinite(lo) else CONTINUOUS_BOUNDS[0],
                          min(hi, CONTINUOUS_BOUNDS[1]) if math.isfinite(hi) else CONTINUOUS_BOUNDS[1])
                periodic[-1] = (lo, hi) == CONTINUOUS_BOUNDS
            if not lo < hi:
                raise FkoptError(f"{self.name} {path}: the limits of joint '{n}' and the joints mimicking it "
                                 "leave no motion")
            limits[n] = (lo, hi)
        self.joint_names = tuple(names)
        self.joint_units = tuple(units)
        self.default_bounds = limits
        super().__init__(bounds, **geometry)
        # a continuous joint is periodic unless the config bounds it
        self.periodic = np.array([p and tuple(b) == CONTINUOUS_BOUNDS
                                  for p, b in zip(periodic, self.bounds.tolist())])
        self.path = path
        self.base_link = chain[0].parent
        self.tip_link = chain[-1].child
        self._to_si = np.array(to_si)
        self._build(chain, source, g.tool)
        #: The chain's moving joints as URDF gives them (limits in rad or m; None: continuous),
        #: with the unknown each follows (itself unless it mimics another).
        self.chain_joints = []
        for j in moving:
            var, mult, off = source(j)
            lim = j.limit
            self.chain_joints.append({
                "name": j.name, "type": j.type,
                "limits": None if j.type == "continuous" or lim is None else [lim.lower, lim.upper],
                "unit": "rad" if j.type != "prismatic" else "m",
                "unknown": names[var], "multiplier": mult, "offset": off})

    def _read_chain(self, path: Path, g) -> list:
        """The chain from ``g.base`` to ``g.tip``: joints with name, type, parent, child, origin
        (4x4), axis, limit and mimic as :func:`load_urdf` gives them (the MJCF arm reads the same
        records from MuJoCo's compiled model)."""
        return urdf_chain(load_urdf(path), path, g.base, g.tip)

    def _build(self, chain, source, tool) -> None:
        """Constant parts of the recursion (module docstring of :meth:`frame`): per moving joint
        C_i = A_{i-1}^T T_R A_i and v_i = A_{i-1}^T T_p, with T the product of the fixed origins
        since the previous moving joint (its own origin included) and A_i turning z onto its axis;
        the tail (fixed joints after the last, then the tool) the same way."""
        acc = np.eye(4)
        A_prev = np.eye(3)
        joints, reach = [], 0.0
        for j in chain:
            origin = np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=float)
            reach += float(np.linalg.norm(origin[:3, 3]))
            acc = acc @ origin
            if j.type == "fixed":
                continue
            axis = np.array([1.0, 0.0, 0.0]) if j.axis is None else np.asarray(j.axis, dtype=float)
            norm = float(np.linalg.norm(axis))
            if not norm > 0:
                raise FkoptError(f"{self.name} {self.path}: joint '{j.name}' has a zero axis")
            A = _align(axis / norm)
            var, mult, off = source(j)
            joints.append((j.type == "prismatic", _terms(_snap(A_prev.T @ acc[:3, :3] @ A)),
                           tuple(float(v) for v in A_prev.T @ acc[:3, 3]), var, mult, off))
            if j.type == "prismatic":
                lo, hi = self.bounds[var] * self._to_si[var]
                reach += max(abs(mult * lo + off), abs(mult * hi + off))
            acc, A_prev = np.eye(4), A
        if tool is not None:
            T = np.eye(4)
            T[:3, :3] = rotations.zyx1(*np.radians(tool[3:]))
            T[:3, 3] = tool[:3]
            reach += float(np.linalg.norm(tool[:3]))
            acc = acc @ T
        self._joints = tuple(joints)
        self._tail = (_terms(_snap(A_prev.T @ acc[:3, :3])), tuple(float(v) for v in A_prev.T @ acc[:3, 3]))
        self._reach = reach
        self._plain = all(m == 1.0 and o == 0.0 and v == i for i, (_, _, _, v, m, o) in enumerate(joints))
        self._key = (self.name, self._joints, self._tail)

    @property
    def reach(self) -> float:
        """Upper bound of the tip's distance from the base origin (sum of origin offsets + strokes)."""
        return self._reach

    def kinematic_key(self) -> tuple:
        return self._key

    def _chain_values(self, q: np.ndarray) -> list:
        """Values (SI: rad, m) of the chain's moving joints for rows q (k, dof) in public units."""
        cols = [np.radians(q[:, i]) if u == "deg" else q[:, i] for i, u in enumerate(self.joint_units)]
        if self._plain:
            return cols
        return [cols[v] * m + o if (m, o) != (1.0, 0.0) else cols[v] for _, _, _, v, m, o in self._joints]

    def _walk(self, q: np.ndarray, jacobian: bool):
        """Tip frame of rows q (k, dof): position (3, k), columns x, y, z (3, k) of R and, when
        ``jacobian``, the axes and origins (3, k) of the moving joints. The carried frame
        F_i = W_i A_i has joint i's axis as its z column: F_i = F_{i-1} C_i Rz(t_i), origin
        p_i = p_{i-1} + F_{i-1} v_i (+ t_i z for a prismatic joint); the columns' update is
        u = c x + s y, v = c y - s x (a fixed number of array operations per joint)."""
        k = len(q)
        t = self._chain_values(q)
        cols = list(np.eye(3)[:, :, None] * np.ones(k))          # x, y, z of the base frame (3, k)
        p = np.zeros((3, k))
        axes, origins = [], []
        for ti, (prismatic, terms, v, _, _, _) in zip(t, self._joints):
            dp = _offset(cols, v)
            if dp is not None:
                p = p + dp
            cols = _combine(cols, terms)
            if jacobian:
                axes.append(cols[2])
                origins.append(p)
            if prismatic:
                p = p + cols[2] * ti
            else:
                c, s = np.cos(ti), np.sin(ti)
                x, y = cols[0], cols[1]
                cols = [x * c + y * s, y * c - x * s, cols[2]]
        terms, v = self._tail
        dp = _offset(cols, v)
        if dp is not None:
            p = p + dp
        cols = _combine(cols, terms)
        return p, cols, axes, origins

    def _check(self, joints) -> np.ndarray:
        joints = np.asarray(joints, dtype=float)
        if joints.shape[-1:] != (self.dof,):
            raise FkoptError(f"{self.name} joints: expected {self.dof} values "
                             f"({', '.join(self.joint_names)}), got shape {joints.shape}")
        return joints

    def frame(self, joints):
        """Tip frame as (p, R) -- p = (px, py, pz) in m, R a :data:`rotations.Matrix` -- computed
        elementwise over the batch shape of ``joints`` (..., dof) (:meth:`_walk`)."""
        joints = self._check(joints)
        shape = joints.shape[:-1]
        p, cols, _, _ = self._walk(joints.reshape(-1, self.dof), False)
        return (tuple(p[r].reshape(shape) for r in range(3)),
                tuple(tuple(cols[c][r].reshape(shape) for c in range(3)) for r in range(3)))

    def frame_jacobian(self, joints) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Tip position (..., 3), rotation (..., 3, 3) and geometric frame Jacobian (..., 6, n)
        per public joint unit (rows 0-2 d(position)/dq, rows 3-5 the angular velocity in the base
        frame): a revolute joint with world axis z through o contributes (z x (p - o), z), a
        prismatic one (z, 0) (Siciliano et al., Robotics, 2009, eq. 3.30); a mimicking joint adds
        its column times its multiplier to the column of the joint it follows."""
        joints = self._check(joints)
        shape = joints.shape[:-1]
        q = joints.reshape(-1, self.dof)
        k, n = len(q), self.dof
        p, cols, axes, origins = self._walk(q, True)
        Z, O = np.stack(axes, axis=1), np.stack(origins, axis=1)        # (3, m, k)
        D = p[:, None, :] - O
        Jc = np.empty((6, len(axes), k))
        Jc[0] = Z[1] * D[2] - Z[2] * D[1]
        Jc[1] = Z[2] * D[0] - Z[0] * D[2]
        Jc[2] = Z[0] * D[1] - Z[1] * D[0]
        Jc[3:] = Z
        pri = [i for i, j in enumerate(self._joints) if j[0]]
        if pri:
            Jc[:3, pri], Jc[3:, pri] = Z[:, pri], 0.0
        if self._plain:
            J = Jc * self._to_si[None, :, None]
        else:
            J = np.zeros((6, n, k))
            for i, (_, _, _, v, m, _) in enumerate(self._joints):
                J[:, v] += Jc[:, i] * (m * self._to_si[v])
        R = np.stack(cols, axis=-1)                                       # (3 rows, k, 3 columns)
        return (np.ascontiguousarray(p.T).reshape(shape + (3,)),
                np.ascontiguousarray(R.transpose(1, 0, 2)).reshape(shape + (3, 3)),
                np.ascontiguousarray(J.transpose(2, 0, 1)).reshape(shape + (6, n)))

    def frame_jacobian1(self, t) -> tuple[list[float], list[list[float]], list[list[float]]]:
        """:meth:`frame_jacobian` of one configuration on Python floats, in internal units (``t``
        in rad for angles, m for lengths; the Jacobian per rad / per m): the recursion of
        :meth:`_walk` on the arm's constants as a :class:`fkopt.numerics.chain.Chain`
        (:func:`fkopt.numerics.chain.frame_jacobian1`; compiled: :mod:`fkopt.numerics.compiled`)."""
        return frame_jacobian1(self.chain(), t)

    def chain(self):
        """The chain as arrays (:class:`fkopt.numerics.chain.Chain`) for the numerics kernels."""
        got = self.__dict__.get("_chain_arrays")
        if got is None:
            got = self.__dict__["_chain_arrays"] = from_terms(self._joints, self._tail, self.dof)
        return got

    def describe(self) -> dict[str, Any]:
        out = super().describe()
        out["chain"] = {"file": str(self.path), "base": self.base_link, "tip": self.tip_link}
        out["chain_joints"] = self.chain_joints
        return out


#: Serial chains of the PyPI package ``example-robot-data`` (version 6) that fkopt was tried on:
#: name -> (file under its robots/ folder, base link, tip link). Tests and ``fkopt bench
#: --section ik-one-pose`` / ``ik-batch`` use them; docs/robots.md lists the results.
EXAMPLE_ROBOTS = {
    "panda": ("panda_description/urdf/panda.urdf", "panda_link0", "panda_hand_tcp"),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", "base_link", "tool0"),
    "kinova": ("kinova_description/robots/kinova.urdf", "base", "j2s6s200_end_effector"),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", "link_base", "link_eef"),
    "z1": ("z1_description/urdf/z1.urdf", "link00", "gripperStator"),
    "baxter-left": ("baxter_description/urdf/baxter.urdf", "torso", "left_gripper"),
    "pr2-left-gripper": ("pr2_description/urdf/pr2.urdf", "torso_lift_link", "l_gripper_l_finger_tip_link"),
    "ur3": ("ur_description/urdf/ur3_robot.urdf", "base_link", "tool0"),
    "ur10": ("ur_description/urdf/ur10_robot.urdf", "base_link", "tool0"),
    "baxter-right": ("baxter_description/urdf/baxter.urdf", "torso", "right_gripper"),
    "pr2-left": ("pr2_description/urdf/pr2.urdf", "torso_lift_link", "l_wrist_roll_link"),
    "romeo-left": ("romeo_description/urdf/romeo.urdf", "torso", "l_wrist"),
    "tiago": ("tiago_description/robots/tiago_no_hand.urdf", "torso_lift_link", "arm_tool_link"),
    "talos-left": ("talos_data/robots/talos_reduced.urdf", "torso_2_link", "gripper_left_base_link"),
    "icub-left": ("icub_description/robots/icub.urdf", "chest", "l_hand"),
    "g1-left": ("g1_description/urdf/g1_29dof_rev_1_0.urdf", "torso_link", "left_rubber_hand"),
}


def example_robots_folder() -> Path | None:
    """The robots/ folder installed by the PyPI package example-robot-data (a cmeel prefix
    with no Python module, found through the package's file list), or None."""
    try:
        files = metadata.files("example-robot-data") or []
    except metadata.PackageNotFoundError:
        return None
    for f in files:
        if str(f).endswith("robots/panda_description/urdf/panda.urdf"):
            return Path(f.locate()).parents[2]
    return None


def example_robot(name: str, **geometry: Any) -> "URDFArm":
    """``URDFArm`` of chain ``name`` of :data:`EXAMPLE_ROBOTS` (example-robot-data must be installed)."""
    if name not in EXAMPLE_ROBOTS:
        raise FkoptError(f"unknown example robot '{name}'; allowed: {', '.join(EXAMPLE_ROBOTS)}")
    folder = example_robots_folder()
    if folder is None:
        raise FkoptError("example-robot-data is not installed: pip install example-robot-data")
    rel, base, tip = EXAMPLE_ROBOTS[name]
    return URDFArm(file=str(folder / rel), **{"base": base, "tip": tip, **geometry})
