"""fkopt's entries of kinbench's ``all-solutions`` and ``paths`` tracks (:mod:`fkopt.kinbench.solution_sets`,
:mod:`fkopt.kinbench.paths`), with the interface of the field's entries there
(:mod:`fkopt.adapters.field.track_entries`: ``name``, ``package``, ``settings``, ``solutions`` or
``path``), so that the one solver registry (:mod:`fkopt.registry`) lists them beside EAIK, rtb and
TRAC-IK. A new module beside :mod:`.clock_entries` (no change to the solvers themselves).

* ``fkopt.inverse-all`` -- ``fkopt.inverse(arm, T, solutions="all")`` (:func:`fkopt.kinematics.branches.inverse_all`)
  with its defaults, ``fixed=`` the track's locked joint on a 7-joint arm (the locked joint's column
  dropped from the answers, so every entry answers on the same 6-joint chain), its seed per pose from
  the wrapper's generator;
* ``fkopt.inverse_path`` -- ``fkopt.inverse_path(arm, T, start=q0)`` with its defaults (one call per
  path; its ``breaks`` are not looked at: the track judges the joints).

The compiled kernels are loaded when the wrapper is made (one call on a pose at the middle of the
limits), outside the clock, as the field's packages parse their URDF outside it.
"""
from __future__ import annotations

import numpy as np

from fkopt.kinematics.branches import inverse_all, inverse_path


class FkoptAllSolutions:
    name = "fkopt.inverse-all"
    package = "fkopt"

    def __init__(self, arm, *, timeout: float, rng: np.random.Generator, fixed=None):
        self.arm, self.timeout, self.rng = arm, float(timeout), rng
        self.fixed = dict(fixed or {})
        self._free = [k for k, n in enumerate(arm.unknown_names) if n not in self.fixed]
        mid = arm.bounds.mean(axis=1)
        for k, n in enumerate(arm.unknown_names):
            if n in self.fixed:
                mid[k] = self.fixed[n]
        inverse_all(arm, arm.fk_matrix(mid[None])[0], fixed=self.fixed or None)      # kernels loaded
        self.settings = {"call": 'fkopt.inverse(arm, T, solutions="all")', "defaults": "fkopt.inverse's",
                         "tol": "1e-9 m, 1e-9 rad (its default)", "seed": "per pose from the wrapper's generator",
                         "wall_clock_limit": False, **({"fixed": self.fixed} if self.fixed else {})}

    def solutions(self, T) -> np.ndarray:
        r = inverse_all(self.arm, T, fixed=self.fixed or None, seed=int(self.rng.integers(2**31 - 1)))
        return np.asarray(r.solutions, dtype=float).reshape(-1, self.arm.dof)[:, self._free]


class FkoptPath:
    name = "fkopt.inverse_path"
    package = "fkopt"

    def __init__(self, arm, *, timeout: float, rng: np.random.Generator, fixed=None):
        self.arm, self.timeout, self.rng = arm, float(timeout), rng
        mid = arm.bounds.mean(axis=1)
        inverse_path(arm, arm.fk_matrix(np.stack([mid, mid])), start=mid)            # kernels loaded
        self.settings = {"call": "fkopt.inverse_path(arm, T, start=q0)", "defaults": "fkopt.inverse_path's",
                         "max_step": "0.05 rad (its default)", "wall_clock_limit": False}

    def path(self, T: np.ndarray, start: np.ndarray) -> np.ndarray:
        return np.asarray(inverse_path(self.arm, T, start=start).joints, dtype=float)
