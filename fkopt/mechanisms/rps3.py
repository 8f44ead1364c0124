"""3-RPS parallel manipulator of mao2017 (docs/models.md "mao2017 -- 3-RPS").

Mao, Xie, Wu, Yuan (2017), "Forward kinematics optimization of 3-RPS parallel manipulator
based on global-best artificial bee colony algorithm", eqs. (1)-(10).

Pose (alpha, beta, z): rotations about X and Y in degrees and the platform height in mm. The
revolute axes are perpendicular to the legs, which forces the parasitic motions (eq. 6)

    gamma = atan( sin(alpha) sin(beta) / (cos(alpha) + cos(beta)) ),
    x_e   = (r_b / 2) (cos(gamma) cos(beta) - sin(gamma) sin(beta) sin(alpha) - cos(gamma) cos(alpha)),
    y_e   = -r_b sin(gamma) cos(beta),

and the leg lengths are d_i = |R B_i + (x_e, y_e, z) - A_i| (eq. 10) with
R = Rz(gamma) Ry(beta) Rx(alpha) (eq. 2), A_i = r_a (cos phi_i, sin phi_i, 0),
B_i = r_b (cos phi_i, sin phi_i, 0), phi_i = 2 pi (i - 1) / 3 (eq. 3).
"""
from __future__ import annotations

import threading

import numpy as np
from pydantic import Field

from fkopt.numerics import rotations
from fkopt.numerics import path as numerics_path
from fkopt.mechanisms.base import CompiledFitness, Geometry, ParallelMechanism


_HALF_DEG = np.pi / 360.0          # degrees -> half-angle in radians
_S3 = 0.5 * np.sqrt(3.0)           # sin(120 deg)
#: Poses per block of :meth:`ThreeRPS.ik_columns` (its scratch array: 28 x BLOCK floats per thread).
BLOCK = 16384
_PLUS_MINUS = np.array([[1.0], [-1.0]])
_scratch = threading.local()


class _Rows:
    """Named row views of a (28, b) scratch array for :meth:`ThreeRPS._legs` (pairs as (2, b))."""

    def __init__(self, ws: np.ndarray):
        self.T, self.T2, self.R, self.S, self.C = ws[0:2], ws[2:4], ws[4:6], ws[6:8], ws[8:10]
        self.sa, self.sb = self.S
        self.ca, self.cb = self.C
        self.sbsa, self.tg = ws[10], ws[11]
        self.CS, self.RR, self.A, self.B, self.EF = ws[12:14], ws[14:16], ws[16:18], ws[18:20], ws[20:22]
        self.cg, self.sg = self.CS
        self.R00, self.R10 = self.RR
        self.R11, self.R01 = self.B[0], self.A[0]
        self.h, self.ax, self.ay, self.az, self.bz = self.A[1], self.tg, self.sbsa, self.B[1], self.cg
        self.e, self.f = self.EF
        self.BX, self.BY, self.BZ = ws[22:24], ws[24:26], ws[26:28]


def _scratch_rows(b: int) -> _Rows:
    """This thread's scratch rows for a block of ``b`` poses: views of a C-contiguous (28, b)
    prefix of one buffer of 28 * BLOCK floats (made on first use), cached for a few widths."""
    cache = getattr(_scratch, "rows", None)
    if cache is None:
        cache = _scratch.rows = {}
        _scratch.buffer = np.empty(28 * BLOCK)
    rows = cache.get(b)
    if rows is None:
        if len(cache) >= 8:
            cache.clear()
        rows = cache[b] = _Rows(_scratch.buffer[:28 * b].reshape(28, b))
    return rows


class ThreeRPSGeometry(Geometry):
    ra: float = Field(274.0, gt=0, description="base joint circle radius r_a (mm)")
    rb: float = Field(158.0, gt=0, description="platform joint circle radius r_b (mm)")


class ThreeRPS(ParallelMechanism):
    name = "3-rps"
    blas_free_fitness = True   # elementwise map (module docstring): no BLAS on the fitness path
    paper = "mao2017"
    pose_names = ("alpha", "beta", "z")
    pose_units = ("deg", "deg", "mm")
    joint_names = ("d1", "d2", "d3")
    joint_units = ("mm", "mm", "mm")
    Geometry = ThreeRPSGeometry
    # Workspace of mao2017 Sec. 3: alpha, beta in [-20, 20] deg, z in [400, 700] mm.
    default_bounds = {"alpha": (-20.0, 20.0), "beta": (-20.0, 20.0), "z": (400.0, 700.0)}

    def parasitic(self, poses):
        """(gamma [deg], x_e [mm], y_e [mm]) forced by the R-joint constraint (eq. 6)."""
        poses = np.asarray(poses, dtype=float)
        a, b = np.radians(poses[..., 0]), np.radians(poses[..., 1])
        g, xe, ye = self._parasitic(a, b)
        return np.degrees(g), xe, ye

    def _parasitic(self, a, b):
        rb = self.geometry.rb
        sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
        # arctan (not arctan2) as printed; cos a + cos b > 0 throughout |a|, |b| < 90 deg.
        g = np.arctan(sa * sb / (ca + cb))
        sg, cg = np.sin(g), np.cos(g)
        xe = 0.5 * rb * (cg * cb - sg * sb * sa - cg * ca)
        ye = -rb * sg * cb
        return g, xe, ye

    def ik(self, poses) -> np.ndarray:
        """Leg lengths (..., 3) of poses (..., 3): eq. (10) with eq. (6) substituted.

        Lean form (no sin/cos/arctan; :meth:`ik_columns` does the work): with the half-angle tangents
        t = tan(angle / 2), sin = 2t / (1 + t^2), cos = (1 - t^2) / (1 + t^2); the parasitic
        rotation tan(gamma) = sa sb / (ca + cb) gives cos(gamma) = 1 / sqrt(1 + tan^2) and
        sin(gamma) = tan(gamma) cos(gamma) (|gamma| < 90 deg). Substituting x_e = (r_b/2)(R00 - R11)
        and y_e = -r_b R10 into d_i = |R B_i + p - A_i| (phi = 0, 120, 240 deg) leaves

            d_1^2 = (1.5 r_b R00 - 0.5 r_b R11 - r_a)^2 + (z - r_b sb)^2      (leg 1 has dy = 0),
            d_2,3^2 = (a_x +- b_x)^2 + (a_y +- b_y)^2 + (a_z +- b_z)^2,

        a_x = (r_a - r_b R11)/2, b_x = (sqrt3/2) r_b R01, a_y = -1.5 r_b R10, b_y = -sqrt3 a_x,
        a_z = z + r_b sb / 2, b_z = (sqrt3/2) r_b cb sa. The same numbers as the textbook
        evaluation (:meth:`ik_reference`) to ~1e-13 mm, elementwise (batch-size independent).
        """
        poses = np.asarray(poses, dtype=float)
        shape = poses.shape[:-1]
        out = np.empty(shape + (3,))
        self.ik_columns(poses, out=out.reshape(-1, 3).T)
        return out

    def ik_columns(self, poses, out=None) -> np.ndarray:
        """The leg lengths of the flattened poses as rows: ``ik(poses).reshape(-1, 3).T``, (3, n)
        and C-contiguous (``out``, if given, receives them), the same numbers as :meth:`ik`.

        :class:`fkopt.problems.FKProblem` computes its fitness on these rows (three contiguous
        arrays instead of an interleaved (n, 3) one). The operations run in blocks of at most
        :data:`BLOCK` poses on a reused per-thread scratch array (``out=`` everywhere), so an
        evaluation allocates nothing but its result; the arithmetic is elementwise, so the
        numbers do not depend on the blocks.
        """
        poses = np.asarray(poses, dtype=float)
        p = poses.reshape(-1, 3).T                          # (3, n) view
        n = p.shape[1]
        if out is None:
            out = np.empty((3, n))
        for s in range(0, n, BLOCK):
            e = min(s + BLOCK, n)
            self._legs(p[:, s:e], out[:, s:e], _scratch_rows(e - s))
        return out

    def _legs(self, p, out, w: _Rows) -> None:
        """:meth:`ik_columns` of one block: poses ``p`` (3, b) into ``out`` (3, b), scratch rows ``w``.

        Pairs of rows go through one call where the formulas allow it (alpha and beta; cg and
        sg; legs 2 and 3 as a_* + (+-b_*), IEEE's a - b being exactly a + (-b)), and the
        scratch rows are contiguous, so a small batch costs few and cheap numpy calls. (The
        output of every call is its third positional argument.)"""
        ra, rb = self.geometry.ra, self.geometry.rb
        consts = self.__dict__.get("_pm")
        if consts is None:   # (+c, -c) pairs of legs 2 and 3
            consts = self._pm = (_S3 * rb * _PLUS_MINUS, -2.0 * _S3 * _PLUS_MINUS)
        pm_rb, pm_2 = consts
        mul, add, sub, div = np.multiply, np.add, np.subtract, np.divide
        T, T2, R, S, C = w.T, w.T2, w.R, w.S, w.C
        mul(p[:2], _HALF_DEG, T2)
        np.tan(T2, T)                                       # t
        mul(T, T, T2)                                       # t2
        add(1.0, T2, R)
        div(1.0, R, R)                                      # r = 1 / (1 + t2)
        add(T, T, S)
        mul(S, R, S)                                        # s = (t + t) r
        sub(1.0, T2, C)
        mul(C, R, C)                                        # c = (1 - t2) r
        sa, sb, ca, cb = w.sa, w.sb, w.ca, w.cb
        z = p[2]
        sbsa, tg, cg, sg, CS = w.sbsa, w.tg, w.cg, w.sg, w.CS
        mul(sb, sa, sbsa)                                   # = sa * sb
        add(ca, cb, tg)
        div(sbsa, tg, tg)                                   # tg = sa sb / (ca + cb)
        mul(tg, tg, cg)
        add(1.0, cg, cg)
        np.sqrt(cg, cg)
        div(1.0, cg, cg)                                    # cg = 1 / sqrt(1 + tg^2)
        mul(tg, cg, sg)
        mul(CS, cb, w.RR)                                   # R00 = cg cb, R10 = sg cb
        A, B = w.A, w.B
        mul(CS, sbsa, A)                                    # cg sbsa, sg sbsa
        mul(CS, ca, B)                                      # cg ca, sg ca
        R11, R01 = w.R11, w.R01
        add(A[1], B[0], R11)                                # R11 = sg sbsa + cg ca
        sub(A[0], B[1], R01)                                # R01 = cg sbsa - sg ca
        h, e, f = w.h, w.e, w.f                             # h, ax, ay, az, bz reuse free rows
        mul(0.5 * rb, R11, h)                               # (0.5 rb) R11, used twice
        mul(1.5 * rb, w.R00, e)
        sub(e, h, e)
        sub(e, ra, e)                                       # e
        mul(rb, sb, f)
        sub(z, f, f)                                        # f = z - rb sb
        mul(w.EF, w.EF, w.EF)
        add(e, f, e)
        np.sqrt(e, out[0])                                  # d1
        ax, ay, az, bz, BX, BY, BZ = w.ax, w.ay, w.az, w.bz, w.BX, w.BY, w.BZ
        sub(0.5 * ra, h, ax)
        mul(pm_rb, R01, BX)                                 # (+bx, -bx)
        mul(-1.5 * rb, w.R10, ay)
        mul(pm_2, ax, BY)                                   # (+by, -by)
        mul(0.5 * rb, sb, az)
        add(z, az, az)
        mul(cb, sa, bz)
        mul(pm_rb, bz, BZ)                                  # (+bz, -bz)
        add(ax, BX, BX)                                     # u = ax +- bx (legs 2, 3)
        add(ay, BY, BY)
        add(az, BZ, BZ)
        mul(BX, BX, BX)
        mul(BY, BY, BY)
        mul(BZ, BZ, BZ)
        add(BX, BY, BX)
        add(BX, BZ, BX)
        np.sqrt(BX, out[1:3])                               # d2, d3

    def compiled_fitness(self, poses, rows, absolute: bool):
        """The fitness of :meth:`fkopt.problems.FKProblem.fitness` of poses (n, 3) against leg rows
        (3, 1) or (3, n) compiled (:func:`fkopt.mechanisms.rps3_kernels.fitness`: numpy's ``np.tan``
        in this method's layout, the rest compiled, so the numpy path's bits), or None unless
        ``FKOPT_NUMERICS=compiled`` asks for it: importing numba (~0.5-0.9 s) does not pay for
        one fitness call (the swarm iterations compile on their own, :meth:`compiled_swarm_fitness`)."""
        if numerics_path.requested() != "compiled":
            return None
        numerics_path.compiled(True)
        from fkopt.mechanisms import rps3_kernels      # lazy: imports numba: only once the compiled path runs
        return rps3_kernels.fitness(poses, rows, self.geometry.ra, self.geometry.rb, absolute, BLOCK)

    def compiled_swarm_fitness(self) -> CompiledFitness | None:
        """This fitness in the three stages the compiled PSO, ABC and GABC iterations take
        (:class:`fkopt.mechanisms.base.CompiledFitness` of :mod:`fkopt.mechanisms.rps3_kernels`:
        numpy's ``np.tan`` in :meth:`ik_columns`' layout between compiled code, so the numpy path's
        bits), or None: with ``FKOPT_NUMERICS=numpy``, or without numba under the default
        (``auto``; ``compiled`` makes a missing numba an error). numba is imported here, on the
        first swarm iteration on this mechanism, never for a single fitness call."""
        if numerics_path.compiled() is None:
            return None
        from fkopt.mechanisms import rps3_kernels      # lazy: imports numba: only once the compiled path runs
        k = rps3_kernels
        return CompiledFitness(prepare=k.prepare, ufunc=k.numpy_tan, value=k.value, width=2, block=BLOCK,
                               params=(float(self.geometry.ra), float(self.geometry.rb)),
                               ufunc_compiled=k.numpy_tan_loop, ufunc_loop=k.numpy_tan_address())

    def jacobian(self, poses) -> np.ndarray:
        """d(d_1, d_2, d_3)/d(alpha, beta, z), shaped (..., 3, 3): mm per degree and mm per mm.

        The parasitic motion is differentiated too (eq. 6): with u = sa sb / (ca + cb),
        dgamma/dalpha = sb (1 + ca cb) / ((ca + cb)^2 (1 + u^2)) (alpha <-> beta for beta), and
        dR/dalpha = R [e_x]x + gamma_alpha [e_z]x R, dR/dbeta = [Rz(gamma) e_y]x R + gamma_beta [e_z]x R;
        x_e = (r_b/2)(R00 - R11) and y_e = -r_b R10 follow from dR. Then
        dd_i = v_i . (dR B_i + dp) / d_i with v_i = R B_i + p - A_i.
        """
        poses = np.asarray(poses, dtype=float)
        shape = poses.shape[:-1]
        P = poses.reshape(-1, 3)
        a, b, z = np.radians(P[:, 0]), np.radians(P[:, 1]), P[:, 2]
        ra, rb = self.geometry.ra, self.geometry.rb
        sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
        den = ca + cb
        u = sa * sb / den
        k = (1.0 + ca * cb) / (den * den * (1.0 + u * u))
        ga, gb = sb * k, sa * k                              # dgamma/dalpha, dgamma/dbeta (rad/rad)
        g = np.arctan(u)
        R = rotations.to_array(rotations.zyx(a, b, g))       # (n, 3, 3)
        sg, cg = np.sin(g), np.cos(g)

        def cross_left(axis, M):                             # [axis]x M, axis (n, 3)
            return np.cross(axis[:, :, None], M, axis=1)

        ez = np.broadcast_to([0.0, 0.0, 1.0], (len(P), 3))
        ey_g = np.stack([-sg, cg, np.zeros_like(sg)], axis=-1)
        Ex = np.zeros((3, 3))
        Ex[1, 2], Ex[2, 1] = -1.0, 1.0                       # [e_x]x
        dRa = R @ Ex + ga[:, None, None] * cross_left(ez, R)
        dRb = cross_left(ey_g, R) + gb[:, None, None] * cross_left(ez, R)
        phi = 2.0 * np.pi * np.arange(3) / 3.0
        B = rb * np.stack([np.cos(phi), np.sin(phi), np.zeros(3)])      # (3, 3 legs)
        A = ra * np.stack([np.cos(phi), np.sin(phi), np.zeros(3)])
        p = np.stack([0.5 * rb * (R[:, 0, 0] - R[:, 1, 1]), -rb * R[:, 1, 0], z], axis=-1)
        v = R @ B + (p[:, :, None] - A)                       # (n, 3, legs)
        d = np.sqrt((v * v).sum(axis=1))
        J = np.empty((len(P), 3, 3))
        for col, dR in ((0, dRa), (1, dRb)):
            dp = np.stack([0.5 * rb * (dR[:, 0, 0] - dR[:, 1, 1]), -rb * dR[:, 1, 0],
                           np.zeros(len(P))], axis=-1)
            dv = dR @ B + dp[:, :, None]
            J[:, :, col] = (v * dv).sum(axis=1) / d * (np.pi / 180.0)
        J[:, :, 2] = v[:, 2] / d
        return J.reshape(shape + (3, 3))

    def ik_reference(self, poses) -> np.ndarray:
        """Eq. (10) evaluated as printed (rotation matrix, parasitic motion, three legs); slower."""
        poses = np.asarray(poses, dtype=float)
        a, b, z = np.radians(poses[..., 0]), np.radians(poses[..., 1]), poses[..., 2]
        g, xe, ye = self._parasitic(a, b)
        R = rotations.zyx(a, b, g)
        ra, rb = self.geometry.ra, self.geometry.rb
        legs = []
        for i in range(3):
            phi = 2.0 * np.pi * i / 3.0
            c, s = np.cos(phi), np.sin(phi)
            # R @ (rb c, rb s, 0) uses only the first two columns of R.
            dx = rb * (R[0][0] * c + R[0][1] * s) + xe - ra * c
            dy = rb * (R[1][0] * c + R[1][1] * s) + ye - ra * s
            dz = rb * (R[2][0] * c + R[2][1] * s) + z
            legs.append(np.sqrt(dx * dx + dy * dy + dz * dz))
        return np.stack(legs, axis=-1)
