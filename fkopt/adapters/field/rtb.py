"""roboticstoolbox-python's compiled ETS solvers ``ik_LM`` (Levenberg-Marquardt, Chan's damping)
and ``ik_NR`` (Newton-Raphson) on the chain's ETS (Corke and Haviland, ICRA 2021).

Settings: ``ilimit`` = 30 iterations per search, ``slimit`` = 100 searches (rtb's defaults), ``tol``
= 1e-16 on E = 1/2 e^T e (e = position error in m, rotation vector in rad: |e| <= 1.4e-8, so the
stopping test implies the loosest three rungs of the ladder and the last step of a quadratic
method usually the fourth), ``joint_limits=True`` (rtb rejects a search ending outside the
limits), first start q0 uniform in the limits from the wrapper's generator; rtb's further searches
draw from its own unseeded RNG. No wall-clock limit: rtb runs to ``slimit``.

rtb reads only the URDF written from fkopt's chain (:func:`fkopt.adapters.field.arm_urdf`): its
``URDF_file`` runs xacro, which evaluates ``${...}`` in every attribute, so the robot's own file
would run whatever expression it holds (issue 42).

Quirks worked around: rtb resolves the meshes' ``package://`` paths through xacro, so it reads a
copy of the file without visual, collision, transmission and gazebo elements (the written URDF
has none; a file from :meth:`~fkopt.adapters.field.ArmURDF.from_file` may); a sub-chain ``robot.ets(start, end)`` keeps the whole robot's joint indices (``jindex``),
so a chain starting below the root (Baxter's arm from its torso) would read q at the wrong
places, and it includes the joint into ``start`` when that one moves -- the wrapper composes the
links' own ETS from below ``base`` to ``tip`` and renumbers the chain's joints 0..n-1; the ETS is checked against fkopt's FK
at a random configuration when built (rtb misread iCub's own file by 1.5 m; it reads the written
URDF of every kinbench arm right), and an arm rtb misreads is refused with one line.
"""
from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET

import numpy as np

from fkopt.errors import FkoptError
from fkopt.adapters.field import FieldIK, arm_urdf, check_expression_free


def chain_ets(urdf):
    """roboticstoolbox's ETS of the chain base -> tip of a URDF (:class:`~fkopt.adapters.field.ArmURDF`),
    joints numbered 0..n-1."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import roboticstoolbox as rtb
        from roboticstoolbox.models.URDF.URDFRobot import URDF_file
    base, tip = urdf.base_link, urdf.tip_link
    tree = ET.ElementTree(ET.fromstring(urdf.text))
    for parent in list(tree.getroot().iter()):
        for e in list(parent):
            if e.tag in ("visual", "collision", "transmission", "gazebo"):
                parent.remove(e)
    text = ET.tostring(tree.getroot(), encoding="unicode")
    check_expression_free(text, urdf.source)              # xacro runs on what rtb reads (module docstring)
    with urdf.as_file(text) as copy:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            links, name, _ = URDF_file(str(copy))
    robot = rtb.Robot(links, name=name)
    # the links strictly below ``base`` up to ``tip``, each with the ETS from its parent (joint
    # included): rtb's own ``robot.ets(start, end)`` also takes the joint *into* ``base`` when that
    # joint moves (PR2's torso lift, TIAGo's, Talos's torso), one joint too many
    link, below = robot.link_dict.get(tip), []
    while link is not None and link.name != base:
        below.append(link)
        link = link.parent
    if link is None:
        raise FkoptError(f"rtb: link '{tip}' of {urdf.source} is not below '{base}'")
    ets = rtb.ETS()
    for lk in reversed(below):
        ets = ets * lk.ets
    k = 0
    for e in ets:
        if e.isjoint:
            e.jindex = k
            k += 1
    return rtb.ETS(list(ets)), rtb.__version__


class _Rtb(FieldIK):
    package = "roboticstoolbox-python"
    method = "?"
    ILIMIT, SLIMIT, TOL = 30, 100, 1e-16

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        urdf = arm_urdf(arm)
        self.ets, version, gap = self._read(urdf)
        if not gap < 1e-9:
            raise FkoptError(f"{self.name}: rtb's FK of {urdf.source} differs from fkopt's by {gap:.3g} "
                             "(rtb misreads this URDF)")
        self._call = getattr(self.ets, self.method)
        self.settings["urdf"] = urdf.source
        self.settings.update(method=self.method, ilimit=self.ILIMIT, slimit=self.SLIMIT, tol=self.TOL,
                             joint_limits=True, version=version, q0="uniform in limits (wrapper's generator)",
                             internal_rng="rtb's own, unseeded", wall_clock_limit=False)

    def _read(self, urdf):
        """(ETS, rtb's version, max |FK gap| to fkopt's at a random in-limit configuration);
        inf when rtb's chain has another number of joints."""
        ets, version = chain_ets(urdf)
        if ets.n != self.arm.dof:
            return ets, version, np.inf
        q = self.random_start()
        return ets, version, float(np.abs(ets.fkine(q).A - self.arm.fk_matrix(q / self.arm._to_si)).max())

    def solve1(self, T):
        sol = self._call(T, q0=self.random_start(), ilimit=self.ILIMIT, slimit=self.SLIMIT, tol=self.TOL,
                         joint_limits=True)
        return self.public(sol.q), bool(sol.success)


class RtbLM(_Rtb):
    name = "rtb-ik_LM"
    method = "ik_LM"


class RtbNR(_Rtb):
    name = "rtb-ik_NR"
    method = "ik_NR"
