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
Its ratio to the reference's wall time on the same query (whatever the reference's outcome;
the fastest of :data:`REFERENCE_REPEATS` calls from the same start) is what the board ranks:
median and p95 over the queries, so that it means the same on another machine.

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

from fkopt.errors import FkoptError
from fkopt.files.host import installed_version
from fkopt.kinbench.physical import LADDER, fk_verdicts, ik_verdicts, rung_label
from fkopt.kinbench.posesets import load_pose_sets, problem_mechanism
from fkopt.run.config_base import files_folder
from fkopt.registry import FK_SOLVERS, clock_solver, solver_entry  # noqa: F401 (FK_SOLVERS: the FK solvers on the clock)
from fkopt.adapters.field import NotApplicable
from fkopt.adapters.field.cores import pinned

#: Timeouts of the clock track (ms): IK of serial arms, FK of parallel mechanisms.
TIMEOUTS_MS = (1.0, 5.0, 20.0)
FK_TIMEOUTS_MS = (20.0, 100.0, 500.0)
#: Batch sizes of the throughput track.
BATCHES = (1, 10, 100, 1000)
#: The IK solver every time is divided by (measured in the same job, query by query).
REFERENCE = "rtb-ik_LM"
#: The reference of FK of parallel mechanisms: scipy's least_squares from random starts.
FK_REFERENCE = "scipy-least_squares"
#: The reference's time on a query (the ratios' denominator) is the fastest of this many calls
#: with the same start, spread over the query's rotation of solvers (so none is a warm repeat
#: of the one before: back to back, rtb's second call was ~3x faster than its first): measured
#: here, the same rtb call (same answer, same search) took 0.19 ms in one run and 1.35 ms in
#: another on this shared 2-core machine. Its board row keeps its first call.
REFERENCE_REPEATS = 3
#: fkopt's own solvers: the organiser's entries on a board; everything else is an outside entry.
ORGANISER = ("fkopt.inverse", "fkopt.forward")


def is_ik(mechanism) -> bool:
    """IK of a serial arm (targets: tip frames) or FK of a parallel mechanism (targets: legs)."""
    return getattr(mechanism, "kind", None) == "serial"


def make_solver(name: str, mechanism, *, timeout: float, rng: np.random.Generator):
    """The organiser's solver or a field wrapper, from the one solver registry
    (:func:`fkopt.registry.clock_solver`)."""
    return clock_solver(name, mechanism, timeout=timeout, rng=rng)


def track_settings(clock, mechanism) -> tuple[list[str], str, tuple[float, ...]]:
    """(solvers, reference, timeouts in ms) of the clock-track config ``clock`` on ``mechanism``:
    the IK ones for a serial arm, the ``fk_`` ones for a parallel mechanism."""
    if is_ik(mechanism):
        return list(clock.solvers), clock.reference, tuple(clock.timeouts_ms)
    return list(clock.fk_solvers), clock.fk_reference, tuple(clock.fk_timeouts_ms)


def targets_of(mechanism, queries: np.ndarray) -> np.ndarray:
    """What the solvers get per query: the tip frame (IK) or the leg lengths (FK)."""
    return mechanism.fk_matrix(queries) if is_ik(mechanism) else mechanism.ik(queries)


def verdicts(mechanism, answers: np.ndarray, queries: np.ndarray, targets: np.ndarray) -> dict:
    """kinbench's verdict on answers (n, dim): ``position_m``, ``rotation_rad``, ``in_limits``
    (IK: joints inside the limits; FK: answered), ``leg_residual`` (FK; NaN for IK) and
    ``success`` (n, rungs) (:mod:`fkopt.kinbench.physical`)."""
    if is_ik(mechanism):
        v = ik_verdicts(mechanism, answers, targets)
        return {**v, "leg_residual": np.full(len(answers), np.nan)}
    v = fk_verdicts(mechanism, answers, queries, targets)
    return {**v, "in_limits": np.all(np.isfinite(answers), axis=-1)}


def answer_prefix(mechanism) -> str:
    """Column prefix of an answer's components: q (joints) for IK, x (pose) for FK."""
    return "q" if is_ik(mechanism) else "x"


def entry_of(name: str) -> str:
    return "organiser" if name in ORGANISER else "outside"


def package_of(name: str) -> str:
    """The PyPI package a clock entry runs through and its installed version ("pytracik 0.0.3"),
    recorded with the entry's settings in meta.json: which release of an outside solver a board
    measured is part of what it measured."""
    entry = solver_entry(name)
    package = entry.package if entry is not None else "fkopt"
    got = installed_version(package)
    return f"{package} {got}" if got is not None else f"{package} (version unknown)"


def query_rng(seed: int, robot: str, solver: str, timeout_ms: float | None, query: int) -> np.random.Generator:
    key = zlib.crc32(f"{robot}/{solver}/{timeout_ms}".encode())
    return np.random.default_rng(np.random.SeedSequence([int(seed), key, int(query)]))


def timed(call, *args):
    """``call(*args)`` with its wall time (``perf_counter``) and the CPU time of the whole process
    (``process_time``: every thread a package starts): (result, wall s, CPU s). The one stopwatch
    of the clock, all-solutions and paths tracks."""
    c0 = time.process_time()
    t0 = time.perf_counter()
    out = call(*args)
    dt = time.perf_counter() - t0
    return out, dt, time.process_time() - c0


def rotated(names: list, i: int) -> np.ndarray:
    """``names`` rotated by ``i`` places: query i's order, so no entry always runs first."""
    return np.roll(np.array(names, dtype=object), -(i % max(len(names), 1)))


def _uses_timeout(solver) -> bool:
    return solver.settings.get("wall_clock_limit", True) is not False


def run_clock(mechanism, robot: str, queries: np.ndarray, solvers: list[str], *, timeouts_ms=TIMEOUTS_MS,
              reference: str = REFERENCE, seed: int = 0, reference_repeats: int = REFERENCE_REPEATS,
              settings: dict | None = None) -> pd.DataFrame:
    """Every answer of the clock track on one arm (IK) or parallel mechanism (FK): one row per
    (query, solver, timeout given) with the answer (joints ``q0..`` or pose ``x0..``), the wall
    time, the reference's wall time on the same query (``reference_seconds``), the claim and the
    verdict (``position_m``, ``rotation_rad``, ``in_limits``, ``leg_residual``). ``queries``:
    joints (IK) or poses (FK) in public units, the frozen pose set's points;
    ``given_timeout_ms`` is NaN for a solver without a wall-clock limit (run once); a solver that
    cannot take the mechanism by design (:class:`fkopt.adapters.field.NotApplicable`) gets rows
    without answers that say why (``not_applicable``). ``settings``, when given, is filled with
    each solver's settings (its wrapper at the largest timeout)."""
    targets = targets_of(mechanism, queries)
    runs: list[tuple[str, float | None, object]] = []         # (solver name, timeout given, wrapper)
    not_applicable: dict[str, str] = {}                       # solver -> why (a cell, never a zero)
    for name in dict.fromkeys([reference, *solvers]):
        try:
            first = make_solver(name, mechanism, timeout=max(timeouts_ms) / 1e3, rng=np.random.default_rng(0))
        except NotApplicable as why:
            not_applicable[name] = str(why)
            if settings is not None:
                settings[name] = {"not_applicable": str(why)}
            continue
        if _uses_timeout(first):
            runs += [(name, t, make_solver(name, mechanism, timeout=t / 1e3, rng=np.random.default_rng(0)))
                     for t in timeouts_ms]
        else:
            runs.append((name, None, first))
        if settings is not None:
            settings[name] = {"package": package_of(name), **dict(runs[-1][2].settings)}
    n, k, dim = len(queries), len(runs), queries.shape[1]
    answers = np.full((n, k, dim), np.nan)
    seconds, cpu_seconds, claimed = np.zeros((n, k)), np.zeros((n, k)), np.zeros((n, k), bool)
    # a reference with a wall-clock limit is timed by its run at the largest timeout
    j_ref = [j for j, r in enumerate(runs) if r[0] == reference][-1]
    ref_seconds = np.full(n, np.inf)
    with pinned():                      # every entry on the same single core (fkopt/adapters/field/cores.py)
        _clock_loop(runs, targets, seed, robot, j_ref, reference_repeats, answers, seconds, cpu_seconds, claimed,
                    ref_seconds)
    rows = [answer_rows(mechanism, robot, name, entry_of(name), "run", np.arange(n), np.nan if t is None else t,
                        seconds[:, j], ref_seconds, claimed[:, j], answers[:, j], queries, targets,
                        cpu_seconds=cpu_seconds[:, j])
            for j, (name, t, solver) in enumerate(runs)]
    rows += [answer_rows(mechanism, robot, name, entry_of(name), "run", np.arange(n), np.nan, np.full(n, np.nan),
                         ref_seconds, np.zeros(n, bool), np.full((n, dim), np.nan), queries, targets,
                         not_applicable=why)
             for name, why in not_applicable.items()]
    return pd.concat(rows, ignore_index=True)


def _clock_loop(runs, targets, seed, robot, j_ref, reference_repeats, answers, seconds, cpu_seconds, claimed,
                ref_seconds) -> None:
    """The interleaved queries of :func:`run_clock`, filling its arrays: wall time by
    ``perf_counter``, CPU time of the whole process (every thread a package starts) by
    ``process_time``."""
    n, k = seconds.shape
    for i in range(n):
        order = [(int(j), 0) for j in np.roll(np.arange(k), -(i % k))]     # interleaved, rotated
        at = order.index((j_ref, 0))
        for rep in range(1, reference_repeats):       # the reference's repeats spread over the rotation
            order.insert((at + rep * (k + rep) // reference_repeats) % (len(order) + 1), (j_ref, rep))
        for j, rep in order:
            name, t, solver = runs[j]
            solver.rng = query_rng(seed, robot, name, t, i)                # the reference: the same start
            (q, ok), dt, dc = timed(solver.solve1, targets[i])
            if rep == 0:
                seconds[i, j], cpu_seconds[i, j], claimed[i, j] = dt, dc, bool(ok)
                if q is not None:
                    answers[i, j] = q
            if j == j_ref:
                ref_seconds[i] = min(ref_seconds[i], dt)


#: The columns of every answers row (``answers.csv.gz``, a clock-track task file), before the
#: answer's own ``q0..`` / ``x0..``: the run record's names where they mean the same thing
#: (``problem``: the arm or parallel mechanism, ``pose``: the query's index in the set, from 0;
#: :mod:`fkopt.run.record`). ``set`` is added by the suite's track task
#: (:func:`fkopt.kinbench.runner.solve_track`) and by a submission's reader.
ANSWER_COLUMNS = ("problem", "set", "pose", "solver", "entry", "source", "given_timeout_ms", "seconds",
                  "cpu_seconds", "reference_seconds", "claimed", "position_m", "rotation_rad", "in_limits",
                  "leg_residual", "not_applicable")
#: What those columns were called before issue 39 (an answers file written then: re-store the board).
OLD_ANSWER_COLUMNS = {"robot": "problem", "query": "pose"}


def answer_rows(mechanism, problem: str, solver: str, entry: str, source: str, pose, given_timeout_ms, seconds,
                reference_seconds, claimed, answers: np.ndarray, queries: np.ndarray,
                targets: np.ndarray, *, cpu_seconds=np.nan, not_applicable: str = "") -> pd.DataFrame:
    """One solver's answers on one arm (IK) or parallel mechanism (FK) ``problem`` as answers
    rows (:data:`ANSWER_COLUMNS`; ``pose``: the queries' indices), each judged by kinbench
    (:func:`verdicts`), never by what the solver says: the rows of :func:`run_clock` (``source``
    = run) and of a submission (``source`` = submitted). ``cpu_seconds``: the call's CPU time
    (NaN for a submission); ``not_applicable``: why the package cannot take this arm (its rows
    hold no answer, and the board a "not applicable" cell)."""
    v = verdicts(mechanism, answers, queries, targets)
    frame = pd.DataFrame({"problem": problem, "pose": pose, "solver": solver, "entry": entry, "source": source,
                          "given_timeout_ms": given_timeout_ms, "seconds": seconds, "cpu_seconds": cpu_seconds,
                          "reference_seconds": reference_seconds, "claimed": claimed,
                          "position_m": v["position_m"], "rotation_rad": v["rotation_rad"],
                          "in_limits": v["in_limits"], "leg_residual": v["leg_residual"],
                          "not_applicable": not_applicable})
    prefix = answer_prefix(mechanism)
    for d in range(answers.shape[1]):
        frame[f"{prefix}{d}"] = answers[:, d]
    return frame


def _not_applicable(rows: pd.DataFrame) -> str:
    """The "not applicable: why" of a solver's rows on one arm ('' when it ran there)."""
    if "not_applicable" not in rows:
        return ""
    why = rows["not_applicable"].dropna().astype(str)
    why = why[why != ""]
    return f"not applicable: {why.iloc[0]}" if len(why) else ""


def rung_success(answers: pd.DataFrame, ladder=LADDER) -> np.ndarray:
    """(rows, rungs): the verdict at each rung of the ladder (errors within it, in limits)."""
    pe, re = answers["position_m"].to_numpy(), answers["rotation_rad"].to_numpy()
    lim = answers["in_limits"].to_numpy(bool)
    return np.stack([(pe <= p) & (re <= r) & lim for p, r in ladder], axis=-1)


def clock_board(answers: pd.DataFrame, *, timeouts_ms=TIMEOUTS_MS, reference: str | dict = REFERENCE,
                rung: int = 2, ladder=LADDER) -> pd.DataFrame:
    """Per (robot, solver, timeout): success share at every rung within the timeout, and the
    time to an answer at rung ``rung`` (ms and as a ratio to the reference's time on the same
    query, each row's ``reference_seconds``: measured in this job for the solvers run here, on
    the submitter's machine for a submission): median and p95, a failure counted at the
    timeout. ``reference_ms_median``: the reference's own median here. ``reference``: one name,
    or robot -> name (IK arms and parallel mechanisms have different references). FK rows (a
    ``leg_residual``) also get ``other_mode``: the share of answers within the timeout whose legs
    solve the equations to the rung's tolerance in another assembly mode."""
    rows = []
    for robot, a in answers.groupby("problem", sort=False):     # the board's rows are per robot
        ref_name = reference.get(robot, REFERENCE) if isinstance(reference, dict) else reference
        ref = a[a["solver"] == ref_name]
        ref_ms = 1e3 * float(ref.groupby("pose")["seconds"].first().median()) if len(ref) else np.nan
        for name, s in a.groupby("solver", sort=False):
            why = _not_applicable(s)
            for t in timeouts_ms:
                if why:
                    rows.append({"solver": name, "robot": robot, "timeout_ms": t, "entry": entry_of(name),
                                 "queries": int(s["pose"].nunique()), "not_applicable": why, "reference": ref_name,
                                 "reference_ms_median": ref_ms, "source": s["source"].iloc[0] if "source" in s else "run"})
                    continue
                g = s[s["given_timeout_ms"].isna() | (s["given_timeout_ms"] == t)].sort_values("pose")
                ok = rung_success(g, ladder) & (g["seconds"].to_numpy() <= t / 1e3)[:, None]
                tta = np.where(ok[:, rung], g["seconds"].to_numpy(), t / 1e3)
                ratio = tta / g["reference_seconds"].to_numpy()
                row = {"solver": name, "robot": robot, "timeout_ms": t, "entry": entry_of(name),
                       "queries": len(g)}
                leg = g["leg_residual"].to_numpy(float) if "leg_residual" in g else np.full(len(g), np.nan)
                if (~np.isnan(leg)).any():
                    solved = (leg <= ladder[rung][0]) & (g["seconds"].to_numpy() <= t / 1e3)
                    row["other_mode"] = float((solved & ~ok[:, rung]).mean())
                row.update({f"success_{rung_label(r)}": float(ok[:, k].mean()) for k, r in enumerate(ladder)})
                cpu = g["cpu_seconds"].to_numpy(float) if "cpu_seconds" in g else np.full(len(g), np.nan)
                row.update({"time_ms_median": 1e3 * float(np.median(tta)),
                            "cpu_ms_median": 1e3 * float(np.median(cpu)) if np.isfinite(cpu).all() else np.nan,
                            "time_ms_p95": 1e3 * float(np.percentile(tta, 95)),
                            "time_ratio_median": float(np.median(ratio)), "time_ratio_p95": float(np.percentile(ratio, 95)),
                            "reference": ref_name, "reference_ms_median": ref_ms,
                            "source": g["source"].iloc[0] if "source" in g else "run"})
                rows.append(row)
    return pd.DataFrame(rows)


def run_throughput(arm, robot: str, queries: np.ndarray, solvers: list[str], *, batches=BATCHES, repeats: int = 3,
                   reference: str = REFERENCE, seed: int = 0, reference_queries: int = 100,
                   optional=()) -> pd.DataFrame:
    """Queries per second of every batch-taking solver at each batch size (best of ``repeats``
    calls), beside the reference's rate one query per call on the first ``reference_queries``
    queries (timed right after each batch size), and the share of answers passing each
    rung (fkopt's verdict)."""
    targets = targets_of(arm, queries)
    ref = make_solver(reference, arm, timeout=max(TIMEOUTS_MS) / 1e3, rng=query_rng(seed, robot, reference, -1, 0))
    rows = []
    m = min(reference_queries, len(targets))
    for name in solvers:
        try:
            solver = make_solver(name, arm, timeout=max(TIMEOUTS_MS) / 1e3, rng=query_rng(seed, robot, name, -1, 0))
        except NotApplicable:           # the clock track's rows say why
            continue
        except FkoptError:
            # a throughput-only entry whose package is an extra of its own (pytorch-kinematics: .[torch])
            # is left out where it is not installed (fkopt check's rerun in a test install; the
            # throughput table is a timing file, never compared); any other entry's failure stands
            if name not in optional:
                raise
            continue
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
            v = verdicts(arm, q, queries[idx], targets[idx])
            row = {"solver": name, "robot": robot, "entry": entry_of(name), "batch": b, "queries_per_s": b / best,
                   "reference": reference, "reference_queries_per_s": ref_qps, "ratio": (b / best) / ref_qps}
            row.update({f"success_{rung_label(r)}": float(v["success"][:, k].mean()) for k, r in enumerate(LADDER)})
            rows.append(row)
    return pd.DataFrame(rows)


# -- the track's arms and queries ----------------------------------------------------------------
def track_cases(config, sets: dict, files=None) -> list[tuple[int, np.ndarray]]:
    """(problem index, queries: joints of the clock set's first ``queries`` poses) of every
    clock-track arm; the suite's ``poses`` (how many poses the swarms get) does not cut them."""
    clock = config.tracks.clock if config.tracks is not None else None
    if clock is None:
        return []
    if config.poses is not None:
        sets, _ = load_pose_sets(config.model_copy(update={"poses": None}), files)
    index = {p.name: k for k, p in enumerate(config.problems)}
    for name in clock.problems:     # never silently fewer queries than asked for
        have = len(sets[(name, clock.set)])
        if clock.queries is not None and clock.queries > have:
            raise FkoptError(f"tracks.clock.queries: {clock.queries}, but set '{clock.set}' of problem {name} holds "
                             f"{have} poses; allowed: 1 to {have} (or omit it: every pose of the set)")
    return [(index[name], np.asarray(sets[(name, clock.set)][:clock.queries], dtype=float)) for name in clock.problems]


def track_arm(config, p: int, files=None):
    """The URDF arm of clock-track problem ``p`` (the field's packages read URDF only)."""
    problem = config.problems[p]
    mech, _ = problem_mechanism(problem, files if files is not None else files_folder(config))
    if getattr(mech, "kind", None) == "parallel":
        if len(mech.unknown_names) != 6 or tuple(mech.pose_units[3:]) != ("deg",) * 3:
            raise FkoptError(f"tracks.clock.problems: '{problem.name}' is not a 6-DOF parallel mechanism "
                             "(x, y, z, three angles): the FK clock judges poses in m and rad")
        return mech
    if getattr(mech, "kind", None) != "serial" or not hasattr(mech, "path") or not hasattr(mech, "tip_link"):
        raise FkoptError(f"tracks.clock.problems: '{problem.name}' is not a URDF arm (mechanism: urdf) or a "
                         "6-DOF parallel mechanism; the clock track's IK solvers read URDF files")
    return mech
