"""Section ``ik-one-pose`` of ``fkopt bench``: one pose per call on the arms of :mod:`.ik_arms`,
fkopt (a prepared ``fkopt.InverseSolver(arm, tol=...)`` called per pose -- ``fkopt.inverse(arm,
pose)``'s answers bit for bit with its per-call set-up done once; the compiled one-pose loop unless
``FKOPT_NUMERICS=numpy``) and rtb alternating query by query in this process (which of the two
goes first alternates too), after one warm-up call each (making the solver, numba's cache load and
the arm's start table happen there, reported as "first call"). ``fkopt.inverse(arm, pose)``
itself is timed in the same rotation (three callers, each first in turn), reported per arm and as
the row "prepared / fkopt.inverse" (the median over arms of the ratio of their median times), with
the count of poses where both gave the same joints; and the three again on the first arm with
cold caches (16 MB of other memory summed before every call), the row "cold: prepared /
fkopt.inverse". Per arm: median ms of each, the ratio of the medians fkopt/rtb, solved fraction
of each; then the median ratio over arms and the largest (targets <= 1 and <= 2, issue 29)."""
from __future__ import annotations

import time

import numpy as np

from fkopt.tools.bench.ik_arms import ARMS, QUICK_ARMS, arms as bench_arms, ratio_summary
from fkopt.tools.bench.measuring import load_average
from fkopt.kinematics import solvers as kinematics
from fkopt.numerics import path

#: Issue 38: one-pose fkopt.inverse over rtb ik_LM, median over arms and largest.
ONE_POSE_TARGET = (0.5, 1.0)


def bench_ik_one_pose(rows, quick: bool, messages: list[str]) -> None:
    sec = "ik-one-pose"
    n = 20 if quick else 100
    arms = bench_arms(QUICK_ARMS if quick else ARMS, n, messages)
    if not arms:
        return
    fast = path.compiled()
    ratios, unprepared = {}, {}
    for a in arms:
        t = time.perf_counter()
        solver = kinematics.InverseSolver(a.m, tol=a.tol)     # set-up once, as a control loop would
        solver(a.P[0])
        t_first = time.perf_counter() - t
        a.rtb(0)
        tf, tr, ti, okf, okr, same = [], [], [], 0, 0, 0
        for k in range(n):
            for who in np.roll((0, 1, 2), k % 3):     # solver, rtb, fkopt.inverse: each goes first in turn
                if who == 0:
                    t = time.perf_counter()
                    res = solver(a.P[k])
                    tf.append(time.perf_counter() - t)
                    okf += a.verified(res.joints, k)
                elif who == 1:
                    t = time.perf_counter()
                    q = a.rtb(k)
                    tr.append(time.perf_counter() - t)
                    okr += a.verified(q, k)
                else:
                    t = time.perf_counter()
                    plain = kinematics.inverse(a.m, a.P[k], tol=a.tol)
                    ti.append(time.perf_counter() - t)
            same += bool(np.array_equal(plain.joints, res.joints))
        f_ms, r_ms, i_ms = float(np.median(tf)) * 1e3, float(np.median(tr)) * 1e3, float(np.median(ti)) * 1e3
        ratios[a.name] = f_ms / r_ms
        unprepared[a.name] = i_ms / r_ms
        rows.add(sec, a.name, f_ms / r_ms, "x rtb",
                 f"{a.m.dof} joints; fkopt median {f_ms:.3f} ms (mean {np.mean(tf) * 1e3:.3f}), rtb median "
                 f"{r_ms:.3f} ms (mean {np.mean(tr) * 1e3:.3f}); solved ({a.check.name}, 1e-6 m, 1e-6 rad, limits) "
                 f"fkopt {okf}/{n}, rtb {okr}/{n}; first call {t_first * 1e3:.0f} ms; fkopt.inverse per call "
                 f"{i_ms:.3f} ms ({i_ms / r_ms:.2f} x rtb), same joints as the solver {same}/{n}")
    what = (f"{n} poses per arm, fkopt path {'compiled' if fast is not None else 'numpy'}, rtb "
            f"{arms[0].rtb_version}; load average {load_average()}")
    ratio_summary(rows, sec, unprepared, ONE_POSE_TARGET[0], ONE_POSE_TARGET[1],
                  f"fkopt.inverse(arm, pose) per call: ratio of median times per pose, {what}")
    ratio_summary(rows, sec, ratios, ONE_POSE_TARGET[0], ONE_POSE_TARGET[1],
                  f"prepared fkopt.InverseSolver: ratio of median times per pose, {what}",
                  label="prepared solver: ")
    _cold_one_pose(rows, sec, arms[0], min(n, 50))
    r = np.array([ratios[k] / unprepared[k] for k in ratios])
    rows.add(sec, "prepared / fkopt.inverse", float(np.median(r)), "x",
             f"median over arms of the solver's median time per pose over fkopt.inverse's (the same calls, "
             f"interleaved; range {r.min():.2f}-{r.max():.2f}); fkopt.inverse alone: median "
             f"{float(np.median(list(unprepared.values()))):.2f} x rtb")


#: Bytes summed before each call of the cold measurement: several times a last-level cache.
EVICT_BYTES = 16 << 20


def _cold_one_pose(rows, sec, a, n) -> None:
    """The three callers of ``ik-one-pose`` on arm ``a`` when the caches are cold, as in a control
    loop that does other work between its IK calls: before every call a sum over
    :data:`EVICT_BYTES` of other memory; the three alternate pose by pose, each first in turn.
    One row: the solver's median time over ``fkopt.inverse``'s, both in ms and over rtb's."""
    junk = np.ones(EVICT_BYTES // 8)
    solver = kinematics.InverseSolver(a.m, tol=a.tol)
    calls = (lambda k: solver(a.P[k]), lambda k: kinematics.inverse(a.m, a.P[k], tol=a.tol), a.rtb)
    times = ([], [], [])
    for k in range(n):
        for who in np.roll((0, 1, 2), k % 3):
            junk.sum()
            t = time.perf_counter()
            calls[who](k)
            times[who].append(time.perf_counter() - t)
    s_ms, i_ms, r_ms = (float(np.median(t)) * 1e3 for t in times)
    rows.add(sec, "cold: prepared / fkopt.inverse", s_ms / i_ms, "x",
             f"{a.name}, {n} poses, {EVICT_BYTES >> 20} MB of other memory summed before every call: solver "
             f"median {s_ms:.3f} ms ({s_ms / r_ms:.2f} x rtb), fkopt.inverse {i_ms:.3f} ms ({i_ms / r_ms:.2f} x rtb), "
             f"rtb {r_ms:.3f} ms")
