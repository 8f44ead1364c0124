"""Start tables of the exact solvers: configurations drawn by a fixed counter-based hash, their
features, and the exact nearest-neighbour query that gives every row its nearest starts.
``fkopt.inverse``'s table holds joint configurations and their tool features (:func:`_start_table`);
``fkopt.forward``'s holds poses of the bounds and their joints (:func:`_forward_table`). Both are
cached per arm or mechanism geometry in :data:`_TABLES`; the starts they give run through the one
restart loop (:mod:`fkopt.numerics.restart_loop`)."""
from __future__ import annotations

import numpy as np

from fkopt.kinematics.inputs import _internal, _public
from fkopt.numerics import rotations


def _sumsq(r):
    return np.einsum("...i,...i->...", r, r)


_M64 = np.uint64(0xFFFFFFFFFFFFFFFF)


def _uniform_hash(seed: int, row: np.ndarray, draw: np.ndarray, n: int) -> np.ndarray:
    """Uniforms in [0, 1) shaped (k, n), a pure function of (seed, row, draw, coordinate):
    SplitMix64's finaliser (Steele, Lea, Flood 2014) over a combined 64-bit counter. Each row
    of a batch thus gets the same restarts alone or in any batch."""
    with np.errstate(over="ignore"):
        c = (np.uint64(seed & 0xFFFFFFFF) * np.uint64(0x9E3779B97F4A7C15)
             ^ (row.astype(np.uint64) << np.uint64(20)) ^ (draw.astype(np.uint64) << np.uint64(4)))
        z = c[:, None] + np.arange(1, n + 1, dtype=np.uint64) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        z = z ^ (z >> np.uint64(31))
    return (z >> np.uint64(11)).astype(np.float64) * (1.0 / 9007199254740992.0)


_TABLES: dict = {}


def _start_table(m, size: int):
    """Joint configurations (size, n) in radians drawn uniformly inside the limits by a fixed
    hash (independent of ``seed``) and their tool features (position, w * rotation matrix
    entries; w = reach / (3 sqrt 2), so 1 rad of rotation weighs about reach / 3): ``inverse``
    starts from the configurations nearest to each target. Cached per arm (name, DH table,
    limits) as a dict with "q", "features", "w" (and "tree", see :func:`_nearest`). The arm's
    own forward map (``frame``) makes it, so it serves DH and URDF arms alike."""
    key = m.kinematic_key() + (m.bounds.tobytes(), size)
    got = _TABLES.get(key)
    if got is None:
        lo, hi = _internal(m, m.bounds[:, 0]), _internal(m, m.bounds[:, 1])
        tq = lo + (hi - lo) * _uniform_hash(0x5EED, np.arange(size), np.zeros(size, dtype=np.int64), m.dof)
        p, R = m.frame(_public(m, tq))
        wf = m.reach / (3.0 * np.sqrt(2.0))
        feats = np.concatenate([np.stack(p, axis=-1), wf * rotations.to_array(R).reshape(size, 9)], axis=-1)
        got = _TABLES[key] = {"q": tq, "features": feats, "w": wf}
    return got


def _masked_table(tab: dict, W: np.ndarray) -> dict:
    """The start table compared on the selected task components: masked position features,
    and the rotation features only when all three rotation components count (a rotation
    matrix entry is not one rotation-vector axis). Cached beside the table."""
    fmask = np.concatenate([W[:3], np.full(9, float(W[3:].all()))])
    key = ("masked", fmask.tobytes())
    if key not in tab:
        tab[key] = {"q": tab["q"], "features": tab["features"] * fmask, "w": tab["w"], "mask": fmask}
    return tab[key]


#: Batches from this many rows query the start table through scipy's k-d tree (importing
#: scipy.spatial costs ~0.4 s once per process); smaller ones by exact brute force.
_TREE_MIN = 32


def _nearest(table: dict, feats: np.ndarray, k: int) -> np.ndarray:
    """Indices (N, k) of the table's k nearest configurations (Euclidean in the features),
    nearest first."""
    if len(feats) >= _TREE_MIN:
        if "tree" not in table:
            from scipy.spatial import cKDTree
            table["tree"] = cKDTree(table["features"])
        _, near = table["tree"].query(feats, k=k)
        return np.asarray(near, dtype=np.intp).reshape(len(feats), k)
    F = table["features"]
    if "norms" not in table:
        table["norms"] = _sumsq(F)
    out = np.empty((len(feats), k), dtype=np.intp)
    for i, f in enumerate(feats):
        d2 = table["norms"] - 2.0 * (F @ f)              # |F - f|^2 - |f|^2
        part = np.argpartition(d2, k - 1)[:k] if k < len(d2) else np.arange(len(d2))
        out[i] = part[np.argsort(d2[part], kind="stable")]
    return out


def _forward_table(m, size: int) -> dict:
    """forward's start table: ``size`` poses drawn uniformly inside ``m.bounds`` by a fixed hash
    (independent of ``seed``; the same counter-based draws as inverse's table) and their joints by
    the closed-form inverse map, with the features k-d tree queries compare (:func:`_joint_features`:
    each joint divided by its spread over the table, so legs of different ranges weigh alike; an
    angle joint as (cos, sin) divided by its spread in radians). Poses whose joints are not finite
    are left out. Cached per mechanism class, bounds and geometry -- the joints of a few fixed
    probe poses stand for the geometry, so a mechanism built again (``forward("6-sps", ...)``)
    finds its table. A dict with "pose", "joints", "features", "feature_scale", "angle" (and "tree")."""
    n = len(m.pose_names)
    lo, hi = m.bounds[:, 0], m.bounds[:, 1]
    probe = lo + (hi - lo) * _uniform_hash(0xF0D, np.arange(4), np.zeros(4, dtype=np.int64), n)
    with np.errstate(all="ignore"):
        key = ("forward", type(m).__module__, type(m).__qualname__, m.bounds.tobytes(), int(size),
               np.asarray(m.ik(probe), dtype=float).tobytes())
    got = _TABLES.get(key)
    if got is None:
        poses = lo + (hi - lo) * _uniform_hash(0xF0D, np.arange(size), np.ones(size, dtype=np.int64), n)
        with np.errstate(all="ignore"):
            joints = np.asarray(m.ik(poses), dtype=float)
        keep = np.isfinite(joints).all(axis=-1)
        poses, joints = poses[keep], joints[keep]
        angle = m.angle_mask(m.joint_units)
        tab = {"pose": poses, "joints": joints, "angle": angle}
        raw = _joint_features(tab, joints)
        spread = raw.std(axis=0) if len(raw) > 1 else np.ones(raw.shape[-1])     # (no pose: no table)
        spread = np.where(spread > 0, spread, 1.0)
        tab["feature_scale"] = 1.0 / spread
        tab["features"] = raw * tab["feature_scale"]
        got = _TABLES[key] = tab
    return got


def _joint_features(tab: dict, joints: np.ndarray) -> np.ndarray:
    """Joints (k, m) as the start table's features: lengths as they are, an angle joint (deg) as
    (cos, sin) (so 359 deg is near 1 deg), each times the table's ``feature_scale`` once built."""
    angle = tab["angle"]
    if angle.any():
        a = np.radians(joints[:, angle])
        f = np.concatenate([joints[:, ~angle], np.cos(a), np.sin(a)], axis=-1)
    else:
        f = np.array(joints, dtype=float)
    return f * tab["feature_scale"] if "feature_scale" in tab else f
