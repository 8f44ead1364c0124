"""pinocchio's FK and Jacobian (Carpentier et al., SII 2019) in kinbench's closed-loop inverse
kinematics (CLIK): pinocchio publishes no IK solver, only the CLIK loop of its documentation
("Inverse kinematics (clik)", examples/inverse-kinematics.py). ``pin-clik`` is that loop on
pinocchio's own model of the URDF written from fkopt's chain
(:func:`fkopt.adapters.field.arm_urdf`, for every arm: no outside package reads the robot's own
file, docs/reliability.md section 10; FK-checked against MuJoCo in tests/test_urdf_writer.py), with the three things a random start needs that the example (which
starts at the neutral configuration of a reachable target) does not have, in the board's one
restart loop (:mod:`fkopt.adapters.field.restarts`, shared with ikpy, pink and the black-box
entries):

* a damped step: err = log6(oMtip^-1 oMdes) in the tip's frame (m, rad), J = -Jlog6 J_tip,
  v = -J^T (J J^T + damp I)^-1 err with ``damp`` = 1e-6 (the example's 1e-12 is an undamped
  Gauss-Newton step, which jumps far near a singularity);
* the step capped at ``step_max`` = 0.5 rad (or m) per joint, scaled as a whole, then clipped into
  the joint limits (a projected CLIK: the example ignores limits, most Panda answers leave them);
* a restart on a stall (:class:`~fkopt.adapters.field.restarts.Stall`: the error has not halved
  in 10 steps) or after ``it_max`` = 100 steps. The board's first CLIK (undamped full steps,
  restart only after 50 steps) ended 97-100 % of its failed starts stuck at a limit.

Settings: ``dt`` = 1 (a full step: the example's 0.1 shrinks the error by 0.9 per step); ``eps`` = 0.99e-5 on
|log6| implies the board's rung of 1e-5 m and 1e-5 rad (log6's linear part differs from the tip's
position error by a factor of at most 1 + angle / 2). The documented example itself (DT 0.1, damp
1e-12, eps 1e-4, from neutral) is reproduced by tests/test_field.py's reproduction check.

Quirks worked around: pinocchio's model holds every joint of the URDF (the Panda's fingers): the other joints are
locked at neutral with ``buildReducedModel``. Continuous joints are (cos, sin) pairs in
pinocchio's q (nq = 2); the wrapper converts. The target is in the chain's base frame,
pinocchio's in the model's root frame: the wrapper maps through oMbase (fixed, the base lies
above the chain).
"""
from __future__ import annotations

import time

import numpy as np

from fkopt.errors import FkoptError
from fkopt.adapters.field import FieldIK, arm_urdf
from fkopt.adapters.field.restarts import restart, SETTINGS, Stall


class PinCLIK(FieldIK):
    name = "pin-clik"
    package = "pin"
    DT, DAMP, EPS, IT_MAX, STEP_MAX = 1.0, 1e-6, 0.99e-5, 100, 0.5

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        import pinocchio as pin
        self._pin = pin
        urdf = arm_urdf(arm)
        full = pin.buildModelFromXML(urdf.text)
        keep = set(urdf.joint_names)
        missing = keep - set(full.names)
        if missing:
            raise FkoptError(f"pin-clik: pinocchio's model of {urdf.source} has no joint {sorted(missing)[0]}")
        lock = [full.getJointId(n) for n in full.names[1:] if n not in keep]
        model = pin.buildReducedModel(full, lock, pin.neutral(full)) if lock else full
        self.model, self.data = model, model.createData()
        # links are BODY frames; a joint may share a link's name (z1's gripperStator), so ask for the body
        self._tip = model.getFrameId(urdf.tip_link, pin.FrameType.BODY)
        self._base = model.getFrameId(urdf.base_link, pin.FrameType.BODY)
        if self._tip >= model.nframes or self._base >= model.nframes:
            raise FkoptError(f"pin-clik: pinocchio's model of {urdf.source} lacks frame {urdf.base_link} or "
                             f"{urdf.tip_link}")
        joints = [model.joints[model.getJointId(n)] for n in urdf.joint_names]
        self._idx_q = [j.idx_q for j in joints]
        self._nq = [j.nq for j in joints]
        self._idx_v = [j.idx_v for j in joints]
        if model.nv != arm.dof:
            raise FkoptError(f"pin-clik: pinocchio's reduced model of {urdf.source} has {model.nv} joints, fkopt {arm.dof}")
        pin.framesForwardKinematics(model, self.data, pin.neutral(model))
        self._oMbase = self.data.oMf[self._base].copy()
        self._per = arm.periodic_mask()
        self.settings.update(SETTINGS, urdf=urdf.source, dt=self.DT, damp=self.DAMP, eps=self.EPS, it_max=self.IT_MAX,
                             step_max=self.STEP_MAX, stall="error not halved in 10 steps", version=pin.__version__,
                             limits="q clipped into fkopt's limits after each step")

    def _to_pin(self, q_si: np.ndarray) -> np.ndarray:
        x = self._pin.neutral(self.model)
        for k, (i, nq) in enumerate(zip(self._idx_q, self._nq)):
            if nq == 2:
                x[i], x[i + 1] = np.cos(q_si[k]), np.sin(q_si[k])
            else:
                x[i] = q_si[k]
        return x

    def _from_pin(self, x: np.ndarray) -> np.ndarray:
        return np.array([np.arctan2(x[i + 1], x[i]) if nq == 2 else x[i] for i, nq in zip(self._idx_q, self._nq)])

    def solve1(self, T):
        oMdes = self._oMbase * self._pin.SE3(np.asarray(T[:3, :3], float), np.asarray(T[:3, 3], float))
        q, ok, _ = restart(lambda q0, deadline: self.clik(oMdes, q0, deadline), self.random_start, self.timeout)
        return self.public(q), ok

    def clik(self, oMdes, q_si: np.ndarray, deadline: float, *, dt: float | None = None, damp: float | None = None,
             eps: float | None = None, it_max: int | None = None, step_max: float | None = None,
             stall: bool = True, limits: bool = True) -> tuple[np.ndarray, float, bool]:
        """One start of the CLIK loop (module docstring): (joints, |log6|, converged). The keyword
        arguments replace the board's settings (the documented example: dt 0.1, damp 1e-12, eps
        1e-4, it_max 1000, no cap, no stall test, no limits)."""
        pin, model, data = self._pin, self.model, self.data
        dt, damp = self.DT if dt is None else dt, self.DAMP if damp is None else damp
        eps, it_max = self.EPS if eps is None else eps, self.IT_MAX if it_max is None else it_max
        step_max = self.STEP_MAX if step_max is None else step_max
        stalled = Stall()
        eye6 = np.eye(6)
        err_norm = np.inf
        for _ in range(it_max):
            x = self._to_pin(q_si)
            pin.framesForwardKinematics(model, data, x)
            iMd = data.oMf[self._tip].actInv(oMdes)
            err = pin.log6(iMd).vector                 # in the tip frame
            err_norm = float(np.linalg.norm(err))
            if err_norm < eps:
                return q_si, err_norm, True
            if (stall and stalled(err_norm)) or time.perf_counter() > deadline:
                break
            J = pin.computeFrameJacobian(model, data, x, self._tip, pin.LOCAL)
            J = -pin.Jlog6(iMd.inverse()) @ J
            v = -J.T @ np.linalg.solve(J @ J.T + damp * eye6, err)
            dq = v[self._idx_v] * dt
            if step_max:
                dq *= min(1.0, step_max / max(np.abs(dq).max(), 1e-300))
            q_si = q_si + dq
            q_si[self._per] = (q_si[self._per] + np.pi) % (2 * np.pi) - np.pi
            if limits:
                q_si = np.clip(q_si, self.lo_rad, self.hi_rad)
        return q_si, err_norm, False
