"""ikpy (Manceron, github.com/Phylliade/ikpy): the chain's FK as numpy matrices and
``scipy.optimize.least_squares`` on the position and the three orientation axes
(``orientation_mode="all"``), bounded by the URDF's joint limits.

Settings: the numpy backend, ``optimizer="least_squares"`` (ikpy's default), ``tol`` = 1e-10
(ikpy's portable tolerance, passed to scipy's ftol/xtol/gtol), ``optimizer_budget`` = 200
evaluations per start (ikpy's portable budget), random starts uniform in the limits from the
wrapper's generator until an answer passes a (1e-8 m, 1e-8) check on ikpy's own FK, or the
wall-clock ``timeout`` has passed (checked between starts: one start of ikpy is not
interruptible, its time is counted in full).

Quirks worked around: ``Chain.from_urdf_file`` follows the *first* child of every link unless
told the path, so on the UR5 it ends at ``ee_link``, not ``tool0``: the wrapper passes the full
link/joint path base -> tip (``base_elements``) read from the file. ikpy's chain holds every
link, fixed ones included; ``active_links_mask`` marks the moving joints, and the answer is read
at their places. ikpy's ``symbolic`` / ``jax_precompile`` options are off (no JAX; the numpy
path is the one people run).
"""
from __future__ import annotations

import time
import warnings
import xml.etree.ElementTree as ET

import numpy as np

from fkopt.errors import FkoptError
from fkopt.adapters.field import FieldIK, arm_urdf


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
    TOL, BUDGET, ACCEPT = 1e-10, 200, 1e-8

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import ikpy
            from ikpy.chain import Chain
            urdf = arm_urdf(arm)
            elements = chain_path(urdf)
            with urdf.as_file() as path:                    # ikpy reads a file: a copy it owns briefly
                chain = Chain.from_urdf_file(str(path), base_elements=elements, symbolic=False,
                                             jax_precompile=False)
                mask = [link.joint_type != "fixed" for link in chain.links]
                self.chain = Chain.from_urdf_file(str(path), base_elements=elements, active_links_mask=mask,
                                                  symbolic=False, jax_precompile=False)
        names = [link.name for link, on in zip(self.chain.links, mask) if on]
        if names != list(urdf.joint_names):
            raise FkoptError(f"ikpy: its chain of {urdf.source} moves {names}, fkopt's {list(urdf.joint_names)}")
        self._active = np.flatnonzero(mask)
        self._full = np.zeros(len(self.chain.links))
        self.settings.update(urdf=urdf.source, backend="numpy", optimizer="least_squares", tol=self.TOL, optimizer_budget=self.BUDGET,
                             accept=f"({self.ACCEPT} m, {self.ACCEPT}) on ikpy's FK", version=ikpy.__version__,
                             start="uniform in limits (wrapper's generator), restarts until the timeout",
                             wall_clock_limit="between starts")

    def solve1(self, T):
        deadline = time.perf_counter() + self.timeout
        best, best_err = None, np.inf
        while True:
            x0 = self._full.copy()
            x0[self._active] = self.random_start()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                x = self.chain.inverse_kinematics_frame(T, initial_position=x0, orientation_mode="all",
                                                        tol=self.TOL, optimizer_budget=self.BUDGET)
                F = self.chain.forward_kinematics(x)
            err = max(np.linalg.norm(F[:3, 3] - T[:3, 3]), np.abs(F[:3, :3] - T[:3, :3]).max())
            if err < best_err:
                best, best_err = x[self._active], err
            if best_err <= self.ACCEPT or time.perf_counter() > deadline:
                return self.public(best), bool(best_err <= self.ACCEPT)
