"""The arguments of ``fkopt.forward`` and ``fkopt.inverse`` checked once (a mechanism by name or
object, joints, poses and tip frames, the task mask, tolerances: one clear line per bad value), and
inverse's joint units (public degrees and length units, internal radians)."""
from __future__ import annotations

import math

import numpy as np

from fkopt.api_bounds import MAX_API_VALUE, check_array
from fkopt.errors import FkoptError, did_you_mean
from fkopt.mechanisms.base import Mechanism, ParallelMechanism, SerialMechanism
from fkopt.mechanisms.catalog import MECHANISMS


def _mechanism(mechanism, kind: type, what: str) -> Mechanism:
    if isinstance(mechanism, str):
        if mechanism not in MECHANISMS:
            raise FkoptError(f"unknown mechanism '{mechanism}'; allowed: {did_you_mean(mechanism, list(MECHANISMS))} "
                             "(a plug-in: pass fkopt.mechanism(name))")
        mechanism = MECHANISMS[mechanism]()
    if not isinstance(mechanism, Mechanism):           # None, a number, a path: one line, not AttributeError
        raise FkoptError(f"{what}: expected a registered mechanism name or a mechanism object, got "
                         f"{type(mechanism).__name__}")
    if not isinstance(mechanism, kind):
        other = "inverse" if what == "forward" else "forward"
        raise FkoptError(f"{what} needs a {'parallel mechanism' if kind is ParallelMechanism else 'serial arm'}; "
                         f"'{mechanism.name}' is {mechanism.kind} (use fkopt.{other})")
    return mechanism


#: A target frame's rotation may be this far from orthonormal (max |R R^T - I|).
FRAME_ORTHONORMAL_TOL = 1e-9


def _targets(m, poses) -> np.ndarray:
    """Targets of :func:`inverse` as rows: poses (..., 6) as they are, tip frames (..., 4, 4) as
    (..., 12) = (x, y, z, R row-major); a frame needs a finite, orthonormal rotation and the
    last row (0, 0, 0, 1)."""
    try:
        a = np.asarray(poses)
        if a.dtype != np.float64 or a.size == 0:      # complex, text, empty: api_bounds says why in one line
            a = check_array(a, f"{m.name} target pose")
    except (TypeError, ValueError):
        raise FkoptError(f"{m.name} target pose: expected numbers, (..., {len(m.pose_names)}) values "
                         f"({', '.join(m.pose_names)}) or (..., 4, 4) tip frames; got {type(poses).__name__}") from None
    if a.ndim < 2 or a.shape[-2:] != (4, 4):
        return _values(m, a, m.pose_names, "target pose")
    if a.ndim == 2:                                    # one frame: the same checks on floats (a few µs less)
        f = a.ravel().tolist()
        a0, a1, a2, x, b0, b1, b2, y, c0, c1, c2, z = f[:12]
        gap = max(abs(a0 * a0 + a1 * a1 + a2 * a2 - 1.0), abs(b0 * b0 + b1 * b1 + b2 * b2 - 1.0),
                  abs(c0 * c0 + c1 * c1 + c2 * c2 - 1.0), abs(a0 * b0 + a1 * b1 + a2 * b2),
                  abs(a0 * c0 + a1 * c1 + a2 * c2), abs(b0 * c0 + b1 * c1 + b2 * c2))
        if abs(x) + abs(y) + abs(z) <= MAX_API_VALUE and gap <= FRAME_ORTHONORMAL_TOL \
                and f[12:] == [0.0, 0.0, 0.0, 1.0]:
            return np.array([x, y, z, a0, a1, a2, b0, b1, b2, c0, c1, c2])
    if not (np.abs(a) <= MAX_API_VALUE).all():
        raise FkoptError(f"{m.name} target frame: values must be finite and within +-{MAX_API_VALUE:g}")
    R = a[..., :3, :3]
    gap = np.abs(R @ np.swapaxes(R, -1, -2) - np.eye(3)).max()
    if not gap <= FRAME_ORTHONORMAL_TOL or not (a[..., 3, :] == (0.0, 0.0, 0.0, 1.0)).all():
        raise FkoptError(f"{m.name} target frame: needs an orthonormal rotation (max |R R^T - I| "
                         f"<= {FRAME_ORTHONORMAL_TOL:g}, got {gap:.3g}) and last row 0 0 0 1")
    return np.concatenate([a[..., :3, 3], R.reshape(a.shape[:-2] + (9,))], axis=-1)


def _values(mechanism: Mechanism, values, names, what: str) -> np.ndarray:
    if isinstance(values, np.ndarray) and values.dtype == np.float64 and values.shape == (len(names),):
        row = values.tolist()          # a control loop's call: one real row, checked on Python floats
        if math.isfinite(sum(row)) and max(map(abs, row)) <= MAX_API_VALUE:
            return values
    a = check_array(values, f"{mechanism.name} {what}")        # real, not empty, |v| <= 1e9
    if a.ndim == 0 or a.shape[-1] != len(names):
        raise FkoptError(f"{mechanism.name} {what}: expected (..., {len(names)}) values "
                         f"({', '.join(names)}), got shape {a.shape}")
    bad = ~np.isfinite(a).all(axis=-1)
    if bad.any():
        row = a.reshape(-1, len(names))[int(np.flatnonzero(bad.ravel())[0])]
        raise FkoptError(f"{mechanism.name} {what}: values must be finite, got {row.tolist()}")
    return a


def _internal(m, q):
    """Public joint values (deg, length unit) -> inverse's internal units (rad, length unit)."""
    a = m.angle_mask(m.joint_units)
    return np.where(a, np.radians(q), q) if not a.all() else np.radians(q)


def _public(m, u):
    """Inverse's internal units (rad, length unit) -> public joint values (deg, length unit)."""
    a = m.angle_mask(m.joint_units)
    return np.where(a, np.degrees(u), u) if not a.all() else np.degrees(u)


#: Names of the six task components ``mask`` selects, in order.
TASK = ("x", "y", "z", "rx", "ry", "rz")


def _task_mask(mask) -> np.ndarray | None:
    """``mask`` as a (6,) array of 0/1 over (x, y, z, rx, ry, rz), or None for the full pose."""
    if mask is None:
        return None
    if isinstance(mask, str):
        mask = [name in {t.strip() for t in mask.split(",")} for name in TASK] \
            if all(t.strip() in TASK for t in mask.split(",")) else mask
    try:
        W = np.asarray(mask, dtype=float)
    except (TypeError, ValueError):
        W = None
    if W is None or W.shape != (6,) or not np.isin(W, (0.0, 1.0)).all() or not W.any():
        raise FkoptError(f"inverse mask: expected 6 flags 0/1 over ({', '.join(TASK)}) with at least one "
                         f"set, or names like 'x,y,z'; got {mask!r}")
    return None if W.all() else W


def _unreachable(m, x, y, z, dist) -> FkoptError:
    """The one-line error of a target farther from the base than the arm's reach."""
    unit = m.pose_units[0]
    return FkoptError(f"{m.name} target ({x:g}, {y:g}, {z:g}) unreachable "
                      f"(distance {dist:.1f} {unit} > reach {m.reach:.1f} {unit})")


def _inverse_arm(arm) -> SerialMechanism:
    """``arm`` of :func:`inverse` as a serial mechanism with an analytic frame Jacobian."""
    m = _mechanism(arm, SerialMechanism, "inverse")
    if not hasattr(m, "frame_jacobian"):
        raise FkoptError(f"inverse needs an arm with an analytic frame Jacobian; '{m.name}' has none "
                         "(use fkopt.solve with an ik_problem)")
    return m


def _tolerance(tol) -> tuple[float, float]:
    """``tol`` of :func:`inverse` as (position, orientation) positive finite floats."""
    try:
        if isinstance(tol, tuple) and len(tol) == 2:      # the common case, without numpy's broadcast
            tp, tr = float(tol[0]), float(tol[1])
        else:
            tp, tr = (float(t) for t in np.broadcast_to(np.asarray(tol, dtype=float), (2,)))
    except (TypeError, ValueError):
        raise FkoptError(f"inverse tol: expected (position, orientation), got {tol!r}") from None
    if not (0 < tp <= MAX_API_VALUE and 0 < tr <= MAX_API_VALUE):
        raise FkoptError(f"inverse tol: both tolerances must be positive and at most {MAX_API_VALUE:g}, got {tol!r}")
    return tp, tr
