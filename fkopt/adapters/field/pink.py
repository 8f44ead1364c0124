"""Pink (Caron et al., github.com/stephane-caron/pink; ``pin-pink``): differential inverse
kinematics as a quadratic program on pinocchio's model, solved by DAQP (Arnstrom et al., IEEE
TAC 2022; ``daqp``), the loop of its README: per step, ``solve_ik`` on a ``FrameTask`` for the tip
and integrate the velocity it returns.

Settings: pink's defaults -- ``FrameTask(tip, position_cost=1, orientation_cost=1)`` (gain 1, no
Levenberg-Marquardt damping), ``solve_ik`` with its Tikhonov ``damping`` 1e-12 and its default
limits (configuration limits with gain 0.5, velocity limits from the URDF) -- and ``dt`` = 1 s
per step (the task's error is closed in one step where the limits allow; a control loop's
``dt`` of milliseconds only scales the velocity limits' reach per step down). Pink has no
restart loop and no stopping test of its own, so it runs in the board's one restart loop
(:mod:`fkopt.adapters.field.restarts`): random in-limit starts from the wrapper's generator;
a start stops when the task error |log6| (``FrameTask.compute_error``) is below 0.99e-5 (implies
the board's rung of 1e-5 m and 1e-5 rad, as pin-clik's), when it stalls (its error has not
halved in 10 steps), after 100 steps, or at the query's wall-clock deadline.

Quirks worked around: ``solve_ik`` raises ``NoSolutionFound`` when the QP is infeasible (a start
pressed against a limit); that ends the start, as a stall does. The model is pin-clik's (:class:`fkopt.adapters.field.pin.PinCLIK`: pinocchio's model of the
URDF fkopt writes from its chain, the other joints locked); the target maps from the chain's base
frame to the model's root frame through oMbase.
"""
from __future__ import annotations

import time

import numpy as np

from fkopt.adapters.field.pin import PinCLIK
from fkopt.adapters.field.restarts import restart, Stall


class Pink(PinCLIK):
    name = "pink"
    package = "pin-pink"
    DT, EPS, IT_MAX, QP = 1.0, 0.99e-5, 100, "daqp"

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        import pink
        import pink.exceptions
        from pink.tasks import FrameTask
        import daqp  # noqa: F401  (pink's QP solver: a missing one is one line at build time)
        self._pink = pink
        tip = self.model.frames[self._tip].name
        self._task = FrameTask(tip, position_cost=1.0, orientation_cost=1.0)
        self.settings = {"timeout_s": self.timeout, **{k: v for k, v in self.settings.items()
                                                      if k in ("urdf", "restarts", "wall_clock_limit")},
                         "version": getattr(pink, "__version__", "?"), "qp_solver": self.QP, "dt": self.DT,
                         "task": "FrameTask(tip, position_cost=1, orientation_cost=1), pink's defaults otherwise",
                         "eps": self.EPS, "it_max": self.IT_MAX, "stall": "error not halved in 10 steps"}

    def solve1(self, T):
        oMdes = self._oMbase * self._pin.SE3(np.asarray(T[:3, :3], float), np.asarray(T[:3, 3], float))
        self._task.set_target(oMdes)
        q, ok, _ = restart(self._steps, self.random_start, self.timeout)
        return self.public(q), ok

    def _steps(self, q_si: np.ndarray, deadline: float) -> tuple[np.ndarray, float, bool]:
        """One start of pink's loop: (joints, |error|, converged)."""
        conf = self._pink.Configuration(self.model, self.data, self._to_pin(q_si))
        stalled = Stall()
        err = np.inf
        for _ in range(self.IT_MAX):
            err = float(np.linalg.norm(self._task.compute_error(conf)))
            if err < self.EPS:
                return self._from_pin(conf.q), err, True
            if stalled(err) or time.perf_counter() > deadline:
                break
            try:
                v = self._pink.solve_ik(conf, [self._task], self.DT, solver=self.QP, safety_break=False)
            except self._pink.exceptions.NoSolutionFound:      # an infeasible QP ends this start
                break
            conf.integrate_inplace(v, self.DT)
        return np.clip(self._from_pin(conf.q), self.lo_rad, self.hi_rad), err, False
