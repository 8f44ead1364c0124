"""General 6-SPS Stewart-Gough platform, and the parallel CMM of liu2008 as a preset.

Six legs of variable length join base point b_i (base frame) to platform point p_i (platform
frame) through spherical joints. The pose is the position (x, y, z) of a point fixed to the
platform -- the platform origin moved by the probe offset s, i.e. the probe tip -- and Z-Y-X
Euler angles (alpha, beta, gamma) in degrees, R = Rz(gamma) Ry(beta) Rx(alpha)
(docs/models.md "Rotation matrix used by mao2017 and liu2008"). The inverse map is closed-form
(liu2008 eqs. (4)-(5)):

    l_i = R p_i + p_s - R s - b_i,    leg length |l_i|,    i = 1..6.

With s = 0 (the default) the position is that of the platform origin.

* :class:`SixSPS` (``"6-sps"``) takes any six base and six platform points. The default
  geometry is Dietmaier's general 6-6 platform, whose leg lengths
  (1, 0.645275, 1.086284, 1.503439, 1.281933, 0.771071) admit 40 real assemblies
  (P. Dietmaier, "The Stewart-Gough platform of general geometry can have 40 real postures",
  Advances in Robot Kinematics, 1998), the maximum possible.
* :class:`SixSPSCMM` (``"6-sps-cmm"``) is liu2008 (docs/models.md "liu2008 -- 6-SPS parallel CMM"):
  Liu, Liu, Wei (2008), "Measurement modeling for 6-DOF parallel-link coordinate measuring
  machine based on particle swarm optimization", eqs. (1)-(5), Tab. 2: b_i and p_i on circles
  of radius R_b = 0.5 m, R_p = 0.225 m at the angles of eq. (2) with short-side central angles
  t_b = t_p = 30 deg, probe offset s = (0, 0, l_s), l_s = 0.180 m. Lengths in metres.

Bounds (search box of the unknowns):

* ``6-sps``: x, y, z in [-2 S, 2 S] with S = max|b_i| + max|p_i - s| (the size of the
  mechanism; legs are not part of the geometry), all three angles in [-180, 180] (full turn).
* ``6-sps-cmm``: a workspace around the CMM's home pose (R = I, z = 0.976 m for legs at
  mid-range 0.86 m): x, y in [-0.2, 0.2] m, z in [0.7, 1.1] m, alpha, beta, gamma in
  [-30, 30] deg. It contains the Tab. 3 solution. The paper prints no workspace; this is our
  choice. ``bounds=FULL_TURN`` (or ``SixSPSCMM.full_turn_bounds()``) widens the angles to a full
  turn for either mechanism.

The inverse map is written structure-of-arrays, elementwise (no matmul), with the constant
parts of every leg folded in advance, so it is bit-identical whatever the batch size and fast
enough for swarm fitness evaluation (see :meth:`SixSPS.ik`).
"""
from __future__ import annotations

from typing import Any, ClassVar

import math

import numpy as np

from fkopt.numerics import rotations
from fkopt.mechanisms.base import ParallelMechanism, geometry_base, lazy_model

Vec3 = tuple[float, float, float]
Points6 = tuple[Vec3, Vec3, Vec3, Vec3, Vec3, Vec3]
_D2R = np.pi / 180.0
#: Batch size from which :meth:`SixSPS.ik_jacobian` works elementwise per leg.
_SOA_MIN = 256

#: Full-turn angle bounds, to pass as ``bounds=FULL_TURN`` (merged with the default position box).
FULL_TURN: dict[str, tuple[float, float]] = {
    "alpha": (-180.0, 180.0), "beta": (-180.0, 180.0), "gamma": (-180.0, 180.0)}

#: Dietmaier's general 6-6 platform with 40 real assemblies (default geometry of "6-sps").
DIETMAIER_BASE: Points6 = (
    (0.0, 0.0, 0.0), (1.107915, 0.0, 0.0), (0.549094, 0.756063, 0.0),
    (0.735077, -0.223935, 0.525991), (0.514188, -0.526063, -0.368418),
    (0.590473, 0.094733, -0.205018))
DIETMAIER_PLATFORM: Points6 = (
    (0.0, 0.0, 0.0), (0.542805, 0.0, 0.0), (0.956919, -0.528915, 0.0),
    (0.665885, -0.353482, 1.402538), (0.478359, 1.158742, 0.107672),
    (-0.137087, -0.235121, 0.353913))
#: Leg lengths of Dietmaier's example.
DIETMAIER_LEGS = (1.0, 0.645275, 1.086284, 1.503439, 1.281933, 0.771071)


def general_bounds(base, platform, probe) -> dict[str, tuple[float, float]]:
    """Default bounds of "6-sps": x, y, z in [-2 S, 2 S], S = max|b_i| + max|p_i - s|; full-turn angles."""
    size = np.linalg.norm(base, axis=1).max() + np.linalg.norm(platform - probe, axis=1).max()
    reach = float(2.0 * size) if size > 0 else 1.0
    out = {v: (-reach, reach) for v in ("x", "y", "z")}
    out.update(FULL_TURN)
    return out


def degenerate(points, what: str) -> str | None:
    """Why six joint points cannot make a 6-SPS (two coincide, or all lie on one line), else None."""
    pts = np.asarray(points, dtype=float)
    d = np.linalg.norm(pts[:, None, :] - pts[None, :, :], axis=-1)
    scale = max(float(d.max()), 1e-300)
    i, j = np.triu_indices(6, 1)
    close = d[i, j] <= 1e-9 * scale
    if close.any() or scale <= 1e-300:
        k = int(np.argmax(close)) if close.any() else 0
        return f"{what} joints {i[k] + 1} and {j[k] + 1} coincide ({pts[i[k]].tolist()})"
    if np.linalg.matrix_rank(pts - pts.mean(axis=0), tol=1e-9 * scale) < 2:
        return f"all six {what} joints lie on one line"
    return None


def _six_sps_geometry():
    from pydantic import Field, model_validator

    class SixSPSGeometry(geometry_base()):
        base: Points6 = Field(DIETMAIER_BASE, description="six base joints b_i [x, y, z] (base frame)")
        platform: Points6 = Field(DIETMAIER_PLATFORM,
                                  description="six platform joints p_i [x, y, z] (platform frame)")
        probe: Vec3 = Field((0.0, 0.0, 0.0),
                            description="probe offset s in the platform frame; the pose locates p_s = origin + R s")

        @model_validator(mode="after")
        def _not_degenerate(self):
            why = degenerate(self.base, "base") or degenerate(self.platform, "platform")
            if why:
                raise ValueError(f"degenerate geometry: {why}; six distinct joints not on one line "
                                 "are needed on the base and on the platform")
            return self

    SixSPSGeometry.__module__ = __name__
    return SixSPSGeometry


class SixSPS(ParallelMechanism):
    """General 6-SPS (Stewart-Gough) platform; leg i joins base i to platform i."""

    name = "6-sps"
    blas_free_fitness = True   # elementwise map (module docstring): no BLAS on the fitness path
    pose_names = ("x", "y", "z", "alpha", "beta", "gamma")
    pose_units = ("m", "m", "m", "deg", "deg", "deg")
    joint_names = ("l1", "l2", "l3", "l4", "l5", "l6")
    joint_units = ("m", "m", "m", "m", "m", "m")
    Geometry = lazy_model(_six_sps_geometry)           # pydantic model, built on first use
    geometry_defaults: ClassVar[dict[str, Any]] = {"base": DIETMAIER_BASE, "platform": DIETMAIER_PLATFORM,
                                                   "probe": (0.0, 0.0, 0.0)}
    default_bounds: ClassVar[dict[str, tuple[float, float]]]  # set below from the default geometry

    # -- geometry --------------------------------------------------------------------------
    def points(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(base (6, 3), platform (6, 3), probe (3,)) as arrays."""
        g = self.geometry_values()
        return (np.array(g.base, dtype=float), np.array(g.platform, dtype=float),
                np.array(g.probe, dtype=float))

    @classmethod
    def full_turn_bounds(cls) -> dict[str, tuple[float, float]]:
        """Angle bounds covering every rotation, to pass as ``bounds=``."""
        return dict(FULL_TURN)

    def _default_bounds(self) -> dict[str, tuple[float, float]]:
        return general_bounds(*self.points())

    def _make_bounds(self, overrides: dict[str, Any]) -> np.ndarray:
        # Default bounds may depend on the geometry, which is validated before this is called.
        self.default_bounds = self._default_bounds()
        self._prepare()
        return super()._make_bounds(overrides)

    def _prepare(self) -> None:
        """Fold the constants of the inverse map: l_i = R q_i + (p_s - b_i), q_i = p_i - s.

        A coordinate j of q_i shared by all legs (e.g. z of a planar platform) contributes the
        same R[:, j] q_j to every leg and is added once to the position; zero terms are skipped.
        """
        base, platform, probe = self.points()
        q = platform - probe
        self._common = tuple(float(q[0, j]) if np.all(q[:, j] == q[0, j]) else None for j in range(3))
        legs = []
        for i in range(6):
            terms = [(j, float(q[i, j])) for j in range(3) if self._common[j] is None and q[i, j] != 0.0]
            legs.append((terms, tuple(float(v) for v in base[i])))
        self._legs = legs
        self._q = q
        self._base = base
        self._qb = tuple((tuple(map(float, q[i])), tuple(map(float, base[i]))) for i in range(6))

    # -- inverse map -----------------------------------------------------------------------
    def ik(self, poses) -> np.ndarray:
        """Leg lengths (..., 6) for poses (..., 6) = (x, y, z, alpha, beta, gamma).

        Lean on purpose (it is the swarm's fitness): one transposing copy of the poses, the
        rotation from :func:`fkopt.numerics.rotations.zyx`, then every leg accumulated in place in two
        scratch arrays. The result is a view of a leg-major (6, ...) array, so the residual
        and the sum over legs in :class:`fkopt.problems.FKProblem` run on contiguous rows.
        """
        p = np.asarray(poses, dtype=float)
        shape = p.shape[:-1]
        pt = np.empty((6,) + shape)
        pt[...] = np.moveaxis(p, -1, 0)
        ang = pt[3:6]
        ang *= _D2R
        R = rotations.zyx(ang[0], ang[1], ang[2])
        # Point shared by all legs: p_s + sum_j R[:, j] q_j over the coordinates j common to all q_i.
        t = [pt[0], pt[1], pt[2]]
        for j, c in enumerate(self._common):
            if c:
                t = [t[k] + R[k][j] * c for k in range(3)]
        out = np.empty((6,) + shape)
        d = np.empty(shape)
        tmp = np.empty(shape)
        for i, (terms, b) in enumerate(self._legs):
            acc = out[i, ...]
            for k in range(3):
                np.subtract(t[k], b[k], out=d)
                for j, c in terms:
                    np.multiply(R[k][j], c, out=tmp)
                    d += tmp
                if k == 0:
                    np.multiply(d, d, out=acc)
                else:
                    d *= d
                    acc += d
            np.sqrt(acc, out=acc)
        return np.moveaxis(out, 0, -1)

    def jacobian(self, poses) -> np.ndarray:
        """d(leg lengths)/d(pose), shaped (..., 6, 6); see :meth:`ik_jacobian`."""
        return self.ik_jacobian(poses)[1]

    def ik_jacobian(self, poses) -> tuple[np.ndarray, np.ndarray]:
        """Leg lengths (..., 6) and d(leg lengths)/d(pose) (..., 6, 6), in the public units
        (m per m, m per degree), from the same leg vectors (one pass for Newton's r and J).

        With v_i = R q_i + p_s - b_i and l_i = |v_i|: dl_i/dp_s = v_i / l_i, and for the Z-Y-X
        angles dR/dalpha = R [e_x]x, dR/dbeta = [Rz(gamma) e_y]x R, dR/dgamma = [e_z]x R, so
        dl_i/dtheta = (v_i / l_i) . (axis_theta x R q_i) with axis_alpha = R e_x,
        axis_beta = Rz(gamma) e_y, axis_gamma = e_z (times pi/180 for degrees).
        Vectorised over the leading axes (batched 3x3 products).
        """
        p = np.asarray(poses, dtype=float)
        shape = p.shape[:-1]
        p = p.reshape(-1, 6)
        if len(p) >= _SOA_MIN:
            lengths, J = self._ik_jacobian_soa(p)
            return lengths.reshape(shape + (6,)), J.reshape(shape + (6, 6))
        a = p[:, 3:6] * _D2R
        ca, cb, cg = np.cos(a).T
        sa, sb, sg = np.sin(a).T
        R = np.empty((len(p), 3, 3))
        R[:, 0, 0], R[:, 0, 1], R[:, 0, 2] = cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa
        R[:, 1, 0], R[:, 1, 1], R[:, 1, 2] = sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa
        R[:, 2, 0], R[:, 2, 1], R[:, 2, 2] = -sb, cb * sa, cb * ca
        w = R @ self._q.T                                       # (n, 3, 6): R q_i
        v = w + (p[:, :3, None] - self._base.T)
        lengths = np.sqrt((v * v).sum(axis=1))
        u = v / lengths[:, None, :]                             # unit legs (n, 3, 6)
        w0, w1, w2 = w[:, 0], w[:, 1], w[:, 2]
        u0, u1, u2 = u[:, 0], u[:, 1], u[:, 2]
        # m = R q_i x u_i, so that axis . m = u_i . (axis x R q_i)
        m0, m1, m2 = w1 * u2 - w2 * u1, w2 * u0 - w0 * u2, w0 * u1 - w1 * u0
        J = np.empty((len(p), 6, 6))
        J[:, :, 0], J[:, :, 1], J[:, :, 2] = u0, u1, u2
        J[:, :, 3] = R[:, 0, 0, None] * m0 + R[:, 1, 0, None] * m1 + R[:, 2, 0, None] * m2
        J[:, :, 4] = -sg[:, None] * m0 + cg[:, None] * m1
        J[:, :, 5] = m2
        J[:, :, 3:] *= _D2R
        return lengths.reshape(shape + (6,)), J.reshape(shape + (6, 6))

    def ik_jacobian1(self, pose) -> tuple[list[float], list[list[float]]]:
        """:meth:`ik_jacobian` of one pose (6 floats) on Python floats: leg lengths (6) and the
        Jacobian as 6 rows of 6, the same formulas. For a single pose numpy's per-call
        overhead (~1 µs per operation on 6-element arrays) is most of the cost; these ~250
        float operations take a fraction of it (:func:`fkopt.forward` on one pose uses it)."""
        x, y, z, a, b, g = pose
        a, b, g = a * _D2R, b * _D2R, g * _D2R
        ca, sa, cb, sb, cg, sg = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(g), math.sin(g)
        r00, r01, r02 = cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa
        r10, r11, r12 = sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa
        r20, r21, r22 = -sb, cb * sa, cb * ca
        lengths, J = [], []
        for (q0, q1, q2), (b0, b1, b2) in self._qb:
            w0 = r00 * q0 + r01 * q1 + r02 * q2
            w1 = r10 * q0 + r11 * q1 + r12 * q2
            w2 = r20 * q0 + r21 * q1 + r22 * q2
            v0, v1, v2 = w0 + x - b0, w1 + y - b1, w2 + z - b2
            L = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
            if L == 0.0:      # a leg of length 0 (joints coincide): no direction, a zero row
                u0 = u1 = u2 = 0.0
            else:
                u0, u1, u2 = v0 / L, v1 / L, v2 / L
            m0, m1, m2 = w1 * u2 - w2 * u1, w2 * u0 - w0 * u2, w0 * u1 - w1 * u0
            lengths.append(L)
            J.append([u0, u1, u2, (r00 * m0 + r10 * m1 + r20 * m2) * _D2R, (cg * m1 - sg * m0) * _D2R,
                      m2 * _D2R])
        return lengths, J

    def _ik_jacobian_soa(self, p):
        """:meth:`ik_jacobian` for many poses (n, 6), elementwise per leg (structure of arrays).

        The Jacobian is filled as (leg, variable, pose) rows, each written contiguously, and
        returned as a (pose, leg, variable) view: strided writes of single columns of an
        (n, 6, 6) array cost more than the arithmetic."""
        n = len(p)
        pt = np.ascontiguousarray(p.T)
        ang = pt[3:6] * _D2R
        R = rotations.zyx(ang[0], ang[1], ang[2])
        sg, cg = np.sin(ang[2]), np.cos(ang[2])
        lengths = np.empty((6, n))
        J = np.empty((6, 6, n))
        for i in range(6):
            q, b = self._q[i], self._base[i]
            w = []
            for k in range(3):
                wk = None
                for j in range(3):
                    if q[j] != 0.0:
                        wk = R[k][j] * q[j] if wk is None else wk + R[k][j] * q[j]
                w.append(np.zeros(n) if wk is None else wk)
            v = [w[k] + (pt[k] - b[k]) for k in range(3)]
            L = np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2], out=lengths[i])
            inv = 1.0 / L
            Ji = J[i]
            u = [np.multiply(v[k], inv, out=Ji[k]) for k in range(3)]
            m0 = w[1] * u[2] - w[2] * u[1]
            m1 = w[2] * u[0] - w[0] * u[2]
            m2 = w[0] * u[1] - w[1] * u[0]
            np.multiply(R[0][0] * m0 + R[1][0] * m1 + R[2][0] * m2, _D2R, out=Ji[3])
            np.multiply(cg * m1 - sg * m0, _D2R, out=Ji[4])
            np.multiply(m2, _D2R, out=Ji[5])
        return lengths.T, J.transpose(2, 0, 1)

    def ik_vectors(self, poses) -> np.ndarray:
        """Leg vectors l_i (..., 6, 3) in the base frame (reference implementation, uses arrays)."""
        p = np.asarray(poses, dtype=float)
        R = rotations.to_array(rotations.zyx(*np.radians(np.moveaxis(p[..., 3:6], -1, 0))))
        Rq = np.einsum("...kj,ij->...ik", R, self._q)
        return Rq + p[..., None, 0:3] - self._base


SixSPS.default_bounds = general_bounds(np.array(DIETMAIER_BASE), np.array(DIETMAIER_PLATFORM), np.zeros(3))


def _six_sps_cmm_geometry():
    from pydantic import Field, model_validator

    class SixSPSCMMGeometry(geometry_base()):
        Rb: float = Field(0.5, gt=0, description="base joint circle radius R_b (m)")
        Rp: float = Field(0.225, gt=0, description="platform joint circle radius R_p (m)")
        tb: float = Field(30.0, gt=0, lt=120, description="base short-side central angle theta_b (deg)")
        tp: float = Field(30.0, gt=0, lt=120, description="platform short-side central angle theta_p (deg)")
        ls: float = Field(0.180, description="probe offset l_s along the platform z axis (m)")
        base: Points6 | None = Field(None, description="explicit base joints (replace Rb, tb)")
        platform: Points6 | None = Field(None, description="explicit platform joints (replace Rp, tp)")

        @model_validator(mode="after")
        def _not_both(self):
            fields = self.model_fields_set
            if self.base is not None and fields & {"Rb", "tb"}:
                raise ValueError("give either base or (Rb, tb), not both")
            if self.platform is not None and fields & {"Rp", "tp"}:
                raise ValueError("give either platform or (Rp, tp), not both")
            return self

    SixSPSCMMGeometry.__module__ = __name__
    return SixSPSCMMGeometry


def __getattr__(name: str):
    # The geometry models are built on first use (importing pydantic costs more than fk itself).
    if name == "SixSPSGeometry":
        return SixSPS.Geometry
    if name == "SixSPSCMMGeometry":
        return SixSPSCMM.Geometry
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class SixSPSCMM(SixSPS):
    """The 6-DOF parallel CMM of liu2008 (eqs. (1)-(5), Tab. 2); pose is the probe tip."""

    name = "6-sps-cmm"
    paper = "liu2008"
    Geometry = lazy_model(_six_sps_cmm_geometry)
    geometry_defaults: ClassVar[dict[str, Any]] = {"Rb": 0.5, "Rp": 0.225, "tb": 30.0, "tp": 30.0, "ls": 0.180,
                                                   "base": None, "platform": None}
    # Workspace around the home pose (not printed in liu2008; our choice, contains Tab. 3).
    default_bounds = {"x": (-0.2, 0.2), "y": (-0.2, 0.2), "z": (0.7, 1.1),
                      "alpha": (-30.0, 30.0), "beta": (-30.0, 30.0), "gamma": (-30.0, 30.0)}

    @staticmethod
    def joint_angles(tb: float, tp: float) -> tuple[np.ndarray, np.ndarray]:
        """theta_bi and theta_pi of liu2008 eq. (2), degrees."""
        theta_b = np.array([60 - tb / 2, 60 + tb / 2, 180 - tb / 2, 180 + tb / 2, 300 - tb / 2, 300 + tb / 2])
        theta_p = np.array([tp / 2, 120 - tp / 2, 120 + tp / 2, 240 - tp / 2, 240 + tp / 2, 360 - tp / 2])
        return theta_b, theta_p

    def points(self):
        g = self.geometry_values()
        theta_b, theta_p = np.radians(self.joint_angles(g.tb, g.tp))
        zero = np.zeros(6)
        base = (np.array(g.base, dtype=float) if g.base is not None else
                np.stack([g.Rb * np.cos(theta_b), g.Rb * np.sin(theta_b), zero], axis=1))
        platform = (np.array(g.platform, dtype=float) if g.platform is not None else
                    np.stack([g.Rp * np.cos(theta_p), g.Rp * np.sin(theta_p), zero], axis=1))
        return base, platform, np.array([0.0, 0.0, g.ls])

    def _default_bounds(self):
        return dict(type(self).default_bounds)
