"""OptIK through ``optik-py`` (Cesare, github.com/kylc/optik): SLSQP (NLopt's) on the squared norm
of the SE(3) log of the pose error, analytic gradient, random restarts inside the package until
the tolerance or the wall-clock limit, in Rust.

Settings: OptIK's defaults (``solution_mode`` = "speed": the first solution; unlimited restarts;
its own RNG, seeded by OptIK, deterministic single-threaded) except:

* ``tol_f`` = (0.99e-5)^2 on |log6|^2: implies the board's rung of 1e-5 m and 1e-5 rad (log6's
  linear part differs from the position error by a factor of at most 1 + angle / 2); OptIK's
  default 1e-6 would stop at |log6| ~ 1e-3;
* ``max_time`` = the query's timeout (OptIK's default 0.1 s);
* one thread (``set_parallelism(1)``): the clock track gives every entry one core; OptIK's
  default is a thread per core, and its README recommends one thread for deterministic results.

The start ``x0`` is a random in-limit configuration from the wrapper's generator (OptIK restarts
from its own random seeds after it). OptIK reads the URDF fkopt writes from its chain
(:func:`fkopt.adapters.field.arm_urdf`) through a temporary file, outside the clock.

Quirk worked around: OptIK's FK is wrong past a fixed joint that lies *between* two moving joints
(measured on the written UR5: exact up to wrist_2, 1.0 off after the fixed joint before wrist_3;
robots' own files have fixed joints only at the ends, so its authors' tests never meet one). The
wrapper folds each such fixed joint's origin into the next moving joint's (:func:`fold_fixed`),
the same chain; its FK is checked against fkopt's when the wrapper is made.

Not applicable (:class:`~fkopt.adapters.field.NotApplicable`): an arm with a prismatic joint (the
TIAGo's torso): OptIK 0.5's Jacobian panics on one ("not yet supported"), which aborts the process.
A continuous joint (which OptIK refuses with a panic) is given to it as a revolute joint with
limits of a full turn either way (:func:`fold_fixed`).
"""
from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET

import numpy as np

from fkopt.errors import FkoptError
from fkopt.files import installed_version
from fkopt.adapters.field import FieldIK, NotApplicable, arm_urdf


def optik_version() -> str:
    return installed_version("optik-py") or "(not installed)"


def fold_fixed(text: str) -> str:
    """The URDF ``text`` as OptIK 0.5 reads it right: a continuous joint made revolute with limits of
    a turn either way (OptIK panics on a continuous joint; answers are wrapped into [-180, 180) deg
    as every entry's), and every fixed joint whose child link is the parent of another joint
    folded into that joint: the child joint's origin becomes fixed origin x its origin (URDF rpy
    is the extrinsic x-y-z rotation), its parent the fixed joint's parent; the fixed joint and its
    link go."""
    from scipy.spatial.transform import Rotation
    root = ET.fromstring(text)

    def frame(j):
        o = j.find("origin")
        xyz = [float(v) for v in (o.get("xyz", "0 0 0") if o is not None else "0 0 0").split()]
        rpy = [float(v) for v in (o.get("rpy", "0 0 0") if o is not None else "0 0 0").split()]
        F = np.eye(4)
        F[:3, :3], F[:3, 3] = Rotation.from_euler("xyz", rpy).as_matrix(), xyz
        return F
    for j in root.findall("joint"):      # OptIK 0.5 refuses continuous joints (a panic): a turn either way
        if j.get("type") == "continuous":
            j.set("type", "revolute")
            limit = j.find("limit")
            if limit is None:
                limit = ET.SubElement(j, "limit", effort="1", velocity="1")
            limit.set("lower", repr(-2 * np.pi))
            limit.set("upper", repr(2 * np.pi))
    changed = True
    while changed:
        changed = False
        joints = root.findall("joint")
        by_parent = {j.find("parent").get("link"): j for j in joints}
        for f in joints:
            nxt = by_parent.get(f.find("child").get("link"))
            if f.get("type") != "fixed" or nxt is None:
                continue
            F = frame(f) @ frame(nxt)
            o = nxt.find("origin")
            if o is None:
                o = ET.SubElement(nxt, "origin")
            o.set("xyz", " ".join(repr(float(v)) for v in F[:3, 3]))
            with warnings.catch_warnings():      # gimbal lock: the angles still give the same matrix
                warnings.simplefilter("ignore")
                rpy = Rotation.from_matrix(F[:3, :3]).as_euler("xyz")
            o.set("rpy", " ".join(repr(float(v)) for v in rpy))
            nxt.find("parent").set("link", f.find("parent").get("link"))
            gone = f.find("child").get("link")
            root.remove(f)
            for link in root.findall("link"):
                if link.get("name") == gone:
                    root.remove(link)
            changed = True
            break
    return ET.tostring(root, encoding="unicode")


class OptIK(FieldIK):
    name = "optik"
    package = "optik-py"
    TOL_F = 0.99e-5 ** 2

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        import optik
        prismatic = [n for n, u in zip(arm.unknown_names, arm.unknown_units) if u != "deg"]
        if prismatic:       # its Jacobian panics ("prismatic joints not yet supported") and aborts the process
            raise NotApplicable(f"prismatic joint {prismatic[0]}: OptIK {optik_version()} supports revolute joints only")
        urdf = arm_urdf(arm)
        with urdf.as_file(fold_fixed(urdf.text)) as path:
            try:
                self._robot = optik.Robot.from_urdf_file(str(path), urdf.base_link, urdf.tip_link)
            except BaseException as err:       # a Rust panic arrives as pyo3's PanicException, a BaseException
                if isinstance(err, (KeyboardInterrupt, SystemExit)):
                    raise
                raise FkoptError(f"optik cannot read {urdf.source}: {str(err).splitlines()[0][:160]}") from None
        if self._robot.num_positions() != arm.dof:
            raise FkoptError(f"optik: {urdf.source} {urdf.base_link} -> {urdf.tip_link} has "
                             f"{self._robot.num_positions()} joints in OptIK, {arm.dof} in fkopt")
        mid = arm.bounds.mean(axis=1)
        if np.abs(np.asarray(self._robot.fk(mid * arm._to_si)) - arm.fk_matrix(mid[None])[0]).max() > 1e-9:
            raise FkoptError(f"optik: its FK of {urdf.source} differs from fkopt's")
        self._robot.set_parallelism(1)
        self._config = optik.SolverConfig(solution_mode="speed", max_time=self.timeout, tol_f=self.TOL_F)
        self.settings.update(urdf=urdf.source, solution_mode="speed", tol_f=self.TOL_F, max_time=self.timeout,
                             parallelism=1, start="uniform in limits (wrapper's generator), then OptIK's own restarts",
                             wall_clock_limit=True)

    def solve1(self, T):
        out = self._robot.ik(self._config, T, self.random_start())
        if out is None:
            return None, False
        q, cost = out
        return self.public(q), bool(cost <= self.TOL_F)
