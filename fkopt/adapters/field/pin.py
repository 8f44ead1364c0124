"""pinocchio's closed-loop inverse kinematics (CLIK), the damped-least-squares loop of
pinocchio's documentation ("Inverse kinematics (clik)", examples/inverse-kinematics.py;
Carpentier et al., SII 2019), on pinocchio's own model of the URDF written from fkopt's chain
(:func:`fkopt.adapters.field.arm_urdf`, for every arm: no outside package reads the robot's own
file, docs/reliability.md section 10). Chosen over pinocchio's own MJCF reader
so that every field package reads one model of an MJCF arm, the written URDF FK-checked against
MuJoCo (tests/test_urdf_writer.py), and so that MuJoCo's ``qpos0``/``ref`` and joint equalities
mean what fkopt's MJCF reader says they mean rather than what a second reader makes of them.

The loop: err = log6(oMdes^-1 oMtip) in the tip's local frame (m, rad), J = Jlog6(oMdes^-1
oMtip) * J_tip(q), v = -J^T (J J^T + damp I)^-1 err, q <- integrate(q, v dt).

Settings: ``damp`` = 1e-12 (the example's), ``dt`` = 1 (a full Gauss-Newton step: the
example's 0.1 shrinks the error by only 0.9 per step, ~200 steps to 1e-9; measured on 20 random
UR5 poses at a 20 ms timeout: 0 % at (5 mm, 0.05 rad) with dt = 0.1 and 50 steps, 100 % with
dt = 1), ``eps`` = 1e-9 on |err| (the example's 1e-4 is looser than the ladder's two tight
rungs), ``it_max`` = 50 iterations per start (the example's 1000 are for dt = 0.1), random starts uniform in the limits from the wrapper's generator until ``eps`` is met or the
wall-clock ``timeout`` has passed (checked every iteration).

Quirks worked around: the example ignores joint limits; here q is clipped into the limits after
every step (a projected CLIK), otherwise most Panda answers leave them. pinocchio's model holds
every joint of the URDF (the Panda's fingers): the other joints are locked at neutral with
``buildReducedModel``. Continuous joints are (cos, sin) pairs in pinocchio's q (nq = 2); the
wrapper converts. The target is in the chain's base frame, pinocchio's in the model's root frame:
the wrapper maps through oMbase (fixed, the base lies above the chain).
"""
from __future__ import annotations

import time

import numpy as np

from fkopt.errors import FkoptError
from fkopt.adapters.field import FieldIK, arm_urdf


class PinCLIK(FieldIK):
    name = "pin-clik"
    package = "pin"
    DT, DAMP, EPS, IT_MAX = 1.0, 1e-12, 1e-9, 50

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
        self.settings.update(urdf=urdf.source, dt=self.DT, damp=self.DAMP, eps=self.EPS, it_max=self.IT_MAX, version=pin.__version__,
                             limits="q clipped into fkopt's limits after each step",
                             start="uniform in limits (wrapper's generator), restarts until the timeout",
                             wall_clock_limit=True)

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
        pin, model, data = self._pin, self.model, self.data
        oMdes = self._oMbase * pin.SE3(np.asarray(T[:3, :3], float), np.asarray(T[:3, 3], float))
        deadline = time.perf_counter() + self.timeout
        eye6 = np.eye(6)
        while True:
            q_si = self.random_start()
            for _ in range(self.IT_MAX):
                x = self._to_pin(q_si)
                pin.framesForwardKinematics(model, data, x)
                iMd = data.oMf[self._tip].actInv(oMdes)
                err = pin.log6(iMd).vector                 # in the tip frame
                if np.linalg.norm(err) < self.EPS:
                    return self.public(q_si), True
                J = pin.computeFrameJacobian(model, data, x, self._tip, pin.LOCAL)
                J = -pin.Jlog6(iMd.inverse()) @ J
                v = -J.T @ np.linalg.solve(J @ J.T + self.DAMP * eye6, err)
                dq = v[self._idx_v] * self.DT
                q_si = q_si + dq
                q_si[self._per] = (q_si[self._per] + np.pi) % (2 * np.pi) - np.pi
                q_si = np.clip(q_si, self.lo_rad, self.hi_rad)
                if time.perf_counter() > deadline:
                    return self.public(q_si), False
