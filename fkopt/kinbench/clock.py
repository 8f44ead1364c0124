"""kinbench v3's clock and throughput tracks: IK solvers ranked on wall time, in ratios to a
reference solver measured in the same job.

**Clock track** (:func:`run_clock`). Per robot, every query (a frozen in-limit configuration
of the suite's pose set; the target is its tip frame by fkopt's FK) goes through every solver
at every timeout of :data:`TIMEOUTS_MS`, and through the reference solver (roboticstoolbox's
``ik_LM``, :data:`REFERENCE`), *interleaved*: query by query, the solvers in an order rotated by
one per query, so slow drifts of the machine's load reach every solver alike. A solver with a
wall-clock limit (its ``settings["wall_clock_limit"]`` is not False: TRAC-IK, pinocchio's
CLIK, ikpy, the black-box optimisers) runs once per timeout with that timeout; one without
(rtb, ``fkopt.inverse``) runs once per query and is judged at each timeout by its one time.
Every answer is judged by :func:`fkopt.kinbench.physical.ik_verdicts` (fkopt's FK, joint
limits), never by what the solver claims; at timeout t an answer is a success at a rung when
the verdict says so *and* it came within t. Time to an answer at rung r and timeout t: the
query's wall time when it is a success there, t otherwise (a failure counted at the timeout).
Its ratio to the reference's wall time on the same query (whatever the reference's outcome)
is what the board ranks: median and p95 over the queries, so that it means the same on
another machine.

**Throughput track** (:func:`run_throughput`). Solvers that take batches (``solve_batch``:
``fkopt.inverse``) answer the first b queries (repeated when fewer) in one call at each batch
size of :data:`BATCHES`, best of ``repeats`` calls; queries per second, beside the reference's
one-query-per-call rate over (at most 100 of) the same queries, timed right after each batch
size (``ratio``), and the share of
answers that pass each rung.

Seeds: each (robot, solver, timeout, query) draws its starts from its own generator,
``SeedSequence([seed, crc32("robot/solver/timeout"), query])``; no global RNG. TRAC-IK's and
rtb's internal restarts use their own unseeded RNGs and every timing varies, so these files are
timing files (never compared byte for byte by ``fkopt check``).
"""
from __future__ import annotations

import time
import zlib

import numpy as np
import pandas as pd

from .physical import LADDER, ik_verdicts, rung_label

#: Timeouts of the clock track (ms).
TIMEOUTS_MS = (1.0, 5.0, 20.0)
#: Batch sizes of the throughput track.
BATCHES = (1, 10, 100, 1000)
#: The IK solver every time is divided by (measured in the same job, query by query).
REFERENCE = "rtb-ik_LM"
#: fkopt's own solvers: the organiser's entries on a board; everything else is an outside entry.
ORGANISER = ("fkopt.inverse",)


class FkoptInverse:
    """The organiser's entry: :func:`fkopt.kinematics.inverse` with its defaults and
    ``tol`` = (1e-9 m, 1e-9 rad), tight enough for every rung of the ladder. The start table
    (4096 FK evaluations and its k-d tree) is built when the wrapper is made, outside the clock,
    as the field's packages parse their URDF outside it. No wall-clock limit (it runs to its
    restart limit); its seed per query comes from the wrapper's generator."""

    name = "fkopt.inverse"
    package = "fkopt"
    TOL = (1e-9, 1e-9)

    def __init__(self, arm, *, timeout: float, rng: np.random.Generator):
        from ..kinematics import inverse
        self.arm, self.timeout, self.rng, self._inverse = arm, float(timeout), rng, inverse
        inverse(arm, arm.fk(arm.bounds.mean(axis=1)), tol=self.TOL)          # start table, outside the clock
        self.settings = {"timeout_s": self.timeout, "tol": list(self.TOL), "wall_clock_limit": False,
                         "seed": "per query from the wrapper's generator", "defaults": "fkopt.inverse's"}

    def _poses(self, T: np.ndarray) -> np.ndarray:
        from ..rotations import zyz_angles
        R = T[..., :3, :3]
        a, b, g = zyz_angles(tuple(tuple(R[..., i, j] for j in range(3)) for i in range(3)))
        return np.concatenate([T[..., :3, 3], np.degrees(np.stack([a, b, g], axis=-1))], axis=-1)

    def solve1(self, T):
        r = self._inverse(self.arm, self._poses(T), tol=self.TOL, seed=int(self.rng.integers(2**31 - 1)))
        return np.asarray(r.joints, dtype=float), bool(r.solved)

    def solve_batch(self, T: np.ndarray) -> np.ndarray:
        r = self._inverse(self.arm, self._poses(T), tol=self.TOL, seed=int(self.rng.integers(2**31 - 1)))
        return np.asarray(r.joints, dtype=float)


def make_solver(name: str, arm, *, timeout: float, rng: np.random.Generator):
    """The organiser's solver or a field wrapper (:func:`fkopt.adapters.field.make_ik`)."""
    if name == FkoptInverse.name:
        return FkoptInverse(arm, timeout=timeout, rng=rng)
    from ..adapters.field import make_ik
    return make_ik(name, arm, timeout=timeout, rng=rng)


def entry_of(name: str) -> str:
    return "organiser" if name in ORGANISER else "outside"


def query_rng(seed: int, robot: str, solver: str, timeout_ms: float | None, query: int) -> np.random.Generator:
    key = zlib.crc32(f"{robot}/{solver}/{timeout_ms}".encode())
    return np.random.default_rng(np.random.SeedSequence([int(seed), key, int(query)]))


def _uses_timeout(solver) -> bool:
    return solver.settings.get("wall_clock_limit", True) is not False


def run_clock(arm, robot: str, queries: np.ndarray, solvers: list[str], *, timeouts_ms=TIMEOUTS_MS,
              reference: str = REFERENCE, seed: int = 0) -> pd.DataFrame:
    """Every answer of the clock track on one robot: one row per (query, solver, timeout given)
    with the joints, the wall time, the reference's wall time on the same query
    (``reference_seconds``), the claim and the verdict (``position_m``, ``rotation_rad``,
    ``in_limits``). ``queries``: joints (n, dof) in public units (deg, m) inside the limits;
    ``given_timeout_ms`` is NaN for a solver without a wall-clock limit (run once)."""
    targets = arm.fk_matrix(queries)
    runs: list[tuple[str, float | None, object]] = []         # (solver name, timeout given, wrapper)
    for name in dict.fromkeys([reference, *solvers]):
        first = make_solver(name, arm, timeout=max(timeouts_ms) / 1e3, rng=np.random.default_rng(0))
        if _uses_timeout(first):
            runs += [(name, t, make_solver(name, arm, timeout=t / 1e3, rng=np.random.default_rng(0)))
                     for t in timeouts_ms]
        else:
            runs.append((name, None, first))
    n, k = len(queries), len(runs)
    joints = np.full((n, k, arm.dof), np.nan)
    seconds, claimed = np.zeros((n, k)), np.zeros((n, k), bool)
    for i in range(n):
        for j in np.roll(np.arange(k), -(i % k)):                          # interleaved, rotated
            name, t, solver = runs[j]
            solver.rng = query_rng(seed, robot, name, t, i)
            t0 = time.perf_counter()
            q, ok = solver.solve1(targets[i])
            seconds[i, j] = time.perf_counter() - t0
            claimed[i, j] = bool(ok)
            if q is not None:
                joints[i, j] = q
    frames = []
    ref_seconds = seconds[:, [j for j, r in enumerate(runs) if r[0] == reference][0]]
    for j, (name, t, solver) in enumerate(runs):
        v = ik_verdicts(arm, joints[:, j], targets)
        frame = pd.DataFrame({"robot": robot, "query": np.arange(n), "solver": name, "entry": entry_of(name),
                              "source": "run", "given_timeout_ms": np.nan if t is None else t,
                              "seconds": seconds[:, j], "reference_seconds": ref_seconds,
                              "claimed": claimed[:, j], "position_m": v["position_m"],
                              "rotation_rad": v["rotation_rad"], "in_limits": v["in_limits"]})
        for d in range(arm.dof):
            frame[f"q{d}"] = joints[:, j, d]
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def rung_success(answers: pd.DataFrame, ladder=LADDER) -> np.ndarray:
    """(rows, rungs): the verdict at each rung of the ladder (errors within it, in limits)."""
    pe, re = answers["position_m"].to_numpy(), answers["rotation_rad"].to_numpy()
    lim = answers["in_limits"].to_numpy(bool)
    return np.stack([(pe <= p) & (re <= r) & lim for p, r in ladder], axis=-1)


def clock_board(answers: pd.DataFrame, *, timeouts_ms=TIMEOUTS_MS, reference: str = REFERENCE,
                rung: int = 2, ladder=LADDER) -> pd.DataFrame:
    """Per (robot, solver, timeout): success share at every rung within the timeout, and the
    time to an answer at rung ``rung`` (ms and as a ratio to the reference's time on the same
    query, each row's ``reference_seconds``: measured in this job for the solvers run here, on
    the submitter's machine for a submission): median and p95, a failure counted at the
    timeout. ``reference_ms_median``: the reference's own median here."""
    rows = []
    for robot, a in answers.groupby("robot", sort=False):
        ref = a[a["solver"] == reference]
        ref_ms = 1e3 * float(ref.groupby("query")["seconds"].first().median()) if len(ref) else np.nan
        for name, s in a.groupby("solver", sort=False):
            for t in timeouts_ms:
                g = s[s["given_timeout_ms"].isna() | (s["given_timeout_ms"] == t)].sort_values("query")
                ok = rung_success(g, ladder) & (g["seconds"].to_numpy() <= t / 1e3)[:, None]
                tta = np.where(ok[:, rung], g["seconds"].to_numpy(), t / 1e3)
                ratio = tta / g["reference_seconds"].to_numpy()
                row = {"solver": name, "robot": robot, "timeout_ms": t, "entry": entry_of(name),
                       "queries": len(g)}
                row.update({f"success_{rung_label(r)}": float(ok[:, k].mean()) for k, r in enumerate(ladder)})
                row.update({"time_ms_median": 1e3 * float(np.median(tta)), "time_ms_p95": 1e3 * float(np.percentile(tta, 95)),
                            "time_ratio_median": float(np.median(ratio)), "time_ratio_p95": float(np.percentile(ratio, 95)),
                            "reference": reference, "reference_ms_median": ref_ms,
                            "source": g["source"].iloc[0] if "source" in g else "run"})
                rows.append(row)
    return pd.DataFrame(rows)


def run_throughput(arm, robot: str, queries: np.ndarray, solvers: list[str], *, batches=BATCHES, repeats: int = 3,
                   reference: str = REFERENCE, seed: int = 0, reference_queries: int = 100) -> pd.DataFrame:
    """Queries per second of every batch-taking solver at each batch size (best of ``repeats``
    calls), beside the reference's rate one query per call on the first ``reference_queries``
    queries (timed right after each batch size), and the share of answers passing each
    rung (fkopt's verdict)."""
    targets = arm.fk_matrix(queries)
    ref = make_solver(reference, arm, timeout=max(TIMEOUTS_MS) / 1e3, rng=query_rng(seed, robot, reference, -1, 0))
    rows = []
    m = min(reference_queries, len(targets))
    for name in solvers:
        solver = make_solver(name, arm, timeout=max(TIMEOUTS_MS) / 1e3, rng=query_rng(seed, robot, name, -1, 0))
        if not hasattr(solver, "solve_batch"):
            continue
        for b in batches:
            idx = np.arange(b) % len(targets)
            best = np.inf
            for _ in range(repeats):
                t0 = time.perf_counter()
                q = solver.solve_batch(targets[idx])
                best = min(best, time.perf_counter() - t0)
            t0 = time.perf_counter()
            for i in range(m):
                ref.solve1(targets[i])
            ref_qps = m / (time.perf_counter() - t0)
            v = ik_verdicts(arm, q, targets[idx])
            row = {"solver": name, "robot": robot, "entry": entry_of(name), "batch": b, "queries_per_s": b / best,
                   "reference": reference, "reference_queries_per_s": ref_qps, "ratio": (b / best) / ref_qps}
            row.update({f"success_{rung_label(r)}": float(v["success"][:, k].mean()) for k, r in enumerate(LADDER)})
            rows.append(row)
    return pd.DataFrame(rows)
