"""ikpy (Manceron, github.com/Phylliade/ikpy): the chain's FK as matrices and
``scipy.optimize.least_squares`` on the position and the three orientation axes, bounded by the
URDF's joint limits. Settings: ikpy's defaults: ``Chain.from_urdf_file`` with ``symbolic=True`` (the
chain's FK compiled from sympy expressions once, when the wrapper is made: its FK runs ~5x
faster than the plain numpy path the board's first wrapper used), the numpy backend,
``optimizer="least_squares"``, scipy's default tolerances and budget (ikpy's ``tol`` and
``optimizer_budget`` left unset).

One documented difference: ``orientation_mode="all"`` (ikpy's default, None, is position-only
IK; the board asks for full poses). ikpy has no restart loop and no success test of its own, so
it runs in the board's one restart loop (:mod:`fkopt.adapters.field.restarts`): random starts
uniform in the limits from the wrapper's generator until ikpy's own FK of the answer is within
the board's rung (1e-5 m, 1e-5 rad; :func:`~fkopt.adapters.field.restarts.within_rung`), or
the wall-clock ``timeout`` has passed (checked between starts: one ikpy call is not
interruptible, its time is counted in full).

Quirks worked around: ``Chain.from_urdf_file`` follows the *first* child of every link unless
told the path, so on the UR5 it ends at ``ee_link``, not ``tool0``: the wrapper passes the full
link/joint path base -> tip (``base_elements``) read from the file. ikpy's chain holds every
link, fixed ones included; ``active_links_mask`` marks the moving joints, and the answer is read
at their places.
"""
from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET

import numpy as np

from fkopt.errors import FkoptError
from fkopt.adapters.field import FieldIK, arm_urdf
from fkopt.adapters.field.restarts import pose_error, restart, RUNG, SETTINGS


def chain_path(urdf) -> list[str]:
    """[base, joint, link, joint, ..., tip] of a URDF (:class:`~fkopt.adapters.field.ArmURDF`):
    the elements ikpy must follow."""
    base, tip, joints = urdf.base_link, urdf.tip_link, {}
    for j in ET.fromstring(urdf.text).iter("joint"):
        parent, child = j.find("parent"), j.find("child")
        if parent is not None and child is not None:
            joints[child.get("link")] = (j.get("name"), parent.get("link"))
    out, link = [tip], tip
    while link != base:
        if link not in joints:
            raise FkoptError(f"ikpy: {urdf.source}: no joint chain from {base} to {tip}")
        name, link = joints[link]
        out += [name, link]
    return out[::-1]


class IkPy(FieldIK):
    name = "ikpy"
    package = "ikpy"

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import ikpy
            from ikpy.chain import Chain
            urdf = arm_urdf(arm)
            elements = chain_path(urdf)
            with urdf.as_file() as path:                    # ikpy reads a file: a copy it owns briefly
                chain = Chain.from_urdf_file(str(path), base_elements=elements)
                mask = [link.joint_type != "fixed" for link in chain.links]
                self.chain = Chain.from_urdf_file(str(path), base_elements=elements, active_links_mask=mask)
        names = [link.name for link, on in zip(self.chain.links, mask) if on]
        if names != list(urdf.joint_names):
            raise FkoptError(f"ikpy: its chain of {urdf.source} moves {names}, fkopt's {list(urdf.joint_names)}")
        self._active = np.flatnonzero(mask)
        self._full = np.zeros(len(self.chain.links))
        self.settings.update(SETTINGS, urdf=urdf.source, symbolic=True, backend="numpy", optimizer="least_squares",
                             tol="ikpy's default (scipy's)", optimizer_budget="ikpy's default (scipy's)",
                             orientation_mode="all", accept=f"({RUNG} m, {RUNG} rad) on ikpy's FK",
                             version=ikpy.__version__, deadline="checked between starts")

    def solve1(self, T):
        def one(q0, deadline):
            x0 = self._full.copy()
            x0[self._active] = q0
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                x = self.chain.inverse_kinematics_frame(T, initial_position=x0, orientation_mode="all")
                p, r = pose_error(self.chain.forward_kinematics(x), T)
            return x[self._active], max(p, r), bool(p <= RUNG and r <= RUNG)
        q, ok, _ = restart(one, self.random_start, self.timeout)
        return self.public(q), ok
