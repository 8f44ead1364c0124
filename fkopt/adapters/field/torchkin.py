"""pytorch-kinematics (Zhong, Power and Berenson, github.com/UM-ARM-Lab/pytorch_kinematics;
``pip install -e ".[torch]"``, outside ``[test]``: torch is large): batched damped-least-squares
IK (``PseudoInverseIK``) on CPU, many target poses and many starts per pose in one tensor
computation. A throughput-track entry (``tracks.throughput.solvers``): it answers a batch of
queries in one call (:meth:`TorchIK.solve_batch`); on the per-query clock it would pay torch's
per-call overhead for one pose, which is not how its authors use it.

Settings: the README's IK call -- ``PseudoInverseIK(chain, num_retries=10, joint_limits=...,
early_stopping_any_converged=True, early_stopping_no_improvement="all")`` -- with the class's own
defaults otherwise (``max_iterations`` 50, ``lr`` 1, ``lm_damping`` 0.1), except:

* ``pos_tolerance`` = ``rot_tolerance`` = 0.99e-5 (m, rad; its defaults 1e-3 and 1e-2 are the
  loose rungs): its test then implies the board's rung of 1e-5 m and 1e-5 rad;
* the chain in float64 (the README's IK example does so too; float32 cannot hold 1e-8 m at a
  metre's reach);
* the 10 starts per pose drawn uniform in the limits from the wrapper's generator and given as
  ``retry_configs`` (its own sampling draws from torch's global RNG).

Quirks worked around: its own start sampling draws from torch's global RNG (so the starts are
given); its ``converged`` flag is per start. Per pose the answer is the first converged start, else the start with the smallest position +
rotation error; every answer is judged by kinbench's FK. One torch thread per call
(``torch.set_num_threads(1)`` around it): the throughput track lets an entry use every core, but
torch's OpenMP threads wait for each other spinning, and on this shared 2-core machine (load ~13)
100 poses took 15.9 s with two threads and 1.4 s with one. The chain is read from the URDF fkopt writes
(:func:`fkopt.adapters.field.arm_urdf`).
"""
from __future__ import annotations

import numpy as np

from fkopt.errors import FkoptError
from fkopt.files import installed_version
from fkopt.adapters.field import FieldIK, arm_urdf


class TorchIK(FieldIK):
    name = "pytorch-kinematics"
    package = "pytorch-kinematics"
    extra = "torch"
    TOL, RETRIES = 0.99e-5, 10

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        import torch
        import pytorch_kinematics as pk
        self._torch, self._pk = torch, pk
        urdf = arm_urdf(arm)
        chain = pk.build_serial_chain_from_urdf(urdf.text.encode(), urdf.tip_link, urdf.base_link)
        self.chain = chain.to(dtype=torch.float64)
        names = list(self.chain.get_joint_parameter_names(exclude_fixed=True))
        if names != list(urdf.joint_names):
            raise FkoptError(f"pytorch-kinematics: its chain of {urdf.source} moves {names}, "
                             f"fkopt's {list(urdf.joint_names)}")
        self._limits = torch.tensor(np.stack([self.lo_rad, self.hi_rad], axis=1), dtype=torch.float64)
        self.settings.update(urdf=urdf.source, version=installed_version("pytorch-kinematics"), torch=torch.__version__,
                             solver="PseudoInverseIK", num_retries=self.RETRIES, pos_tolerance=self.TOL,
                             rot_tolerance=self.TOL, dtype="float64", early_stopping_any_converged=True,
                             early_stopping_no_improvement="all", device="cpu",
                             retry_configs="uniform in limits (wrapper's generator)", wall_clock_limit=False)

    def _ik(self):
        retry = self._torch.tensor(np.stack([self.random_start() for _ in range(self.RETRIES)]),
                                   dtype=self._torch.float64)
        return self._pk.PseudoInverseIK(self.chain, pos_tolerance=self.TOL, rot_tolerance=self.TOL,
                                        retry_configs=retry, joint_limits=self._limits,
                                        early_stopping_any_converged=True, early_stopping_no_improvement="all")

    def solve_batch(self, T: np.ndarray) -> np.ndarray:
        """Joints (b, dof) in fkopt's public units for b target frames (b, 4, 4); one call."""
        torch = self._torch
        goal = self._pk.Transform3d(matrix=torch.tensor(np.asarray(T, float), dtype=torch.float64))
        threads = torch.get_num_threads()
        torch.set_num_threads(1)          # module docstring: its OpenMP threads spin on a busy machine
        try:
            sol = self._ik().solve(goal)
        finally:
            torch.set_num_threads(threads)
        err = (sol.err_pos + sol.err_rot).numpy()
        conv = sol.converged.numpy()
        pick = np.where(conv.any(axis=1), conv.argmax(axis=1), err.argmin(axis=1))
        q = sol.solutions.numpy()[np.arange(len(pick)), pick]
        return np.array([self.public(x) for x in q]).reshape(len(T), self.arm.dof)

    def solve1(self, T):
        q = self.solve_batch(np.asarray(T, float)[None])[0]
        return q, None
