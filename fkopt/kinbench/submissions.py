"""Outside results on the clock track: a solver run on someone else's machine, submitted per
query as its returned joints (IK of a serial arm) or pose (FK of a parallel mechanism) and wall
times, verified and ranked here.

A suite's ``tracks.clock.submissions`` names, per solver, a CSV file (relative to the suite
file), the machine it ran on and the reference solver timed beside it::

    tracks:
      clock:
        problems: [ur5, panda, dietmaier-6sps]
        solvers: [fkopt.inverse, tracik]
        submissions:
          - {solver: my-ik, file: my-ik.csv, machine: "i7-1185G7, 1 thread, Ubuntu 24.04", reference: rtb-ik_LM}
          - {solver: my-fk, file: my-fk.csv, machine: "i7-1185G7, 1 thread", reference: scipy-least_squares}

**CSV**: one row per query of every robot the submission answers (a robot of ``problems``; a
robot it names needs every one of the track's queries 0 .. n-1 of the track's ``set``: the
frozen poses; IK targets are their tip frames by fkopt's FK, FK targets their leg lengths by the
mechanism's inverse map), columns

=====================  ==============================================================================
robot                  a problem name of ``tracks.clock.problems`` (e.g. ``ur5``, ``dietmaier-6sps``)
query                  the pose's index in the set file (0-based)
q0, q1, ...            IK: the returned joints in fkopt's units (deg, m for prismatic), in the order of
                       the arm's moving joints from base to tip. Columns beyond the arm's joint count
                       stay empty
x0 .. x5               FK of a 6-DOF parallel mechanism: the returned pose in the mechanism's public
                       units: x, y, z in its length unit (``pose_units``: mm for Dietmaier's
                       platform), then alpha, beta, gamma in deg (R = Rz(gamma) Ry(beta) Rx(alpha))
                       -- all of a row's answer columns empty: no answer
seconds                the query's wall time on the submitter's machine (s)
reference_seconds      the reference solver's wall time on the same query, measured beside it on
                       the same machine (s); the board ranks seconds / reference_seconds. The
                       reference is the track's: ``reference`` (rtb ``ik_LM``) for IK,
                       ``fk_reference`` (scipy ``least_squares``) for FK
claimed                optional: what the solver said of its answer (true/false/1/0/empty; stored,
                       never counted)
given_timeout_ms       optional: the timeout the solver was given; then one row per query and per
                       timeout of the track (``timeouts_ms`` for IK, ``fk_timeouts_ms`` for FK),
                       else the one time is judged at every timeout
=====================  ==============================================================================

kinbench verifies every answer itself (:func:`fkopt.kinbench.clock.verdicts`): IK with fkopt's
FK and the arm's joint limits (:func:`fkopt.kinbench.physical.ik_verdicts`); FK with the
mechanism's own inverse map -- the leg residual |L(x) - L| / L relative to each leg's length,
the pose error against the generating pose in m and rad, and an answer whose legs solve the
equations in another assembly mode counted apart (``other_mode``,
:func:`fkopt.kinbench.physical.fk_verdicts`), exactly as the clock track judges fkopt's and
scipy's answers. A row that claims success on a wrong answer (or on joints outside the limits)
is a failure. The file's SHA-256 is recorded in meta.json and its rows join answers.csv.gz
(``source`` = ``submitted``), so the board can be re-verified.

Every number of the file is checked before anything is judged: query an integer of the
track, times positive, finite and at most :data:`MAX_SECONDS`, answers finite and within
:data:`MAX_ANSWER` (a value beyond it is no joint or pose of any mechanism here, and would only
reach the verdicts as an overflow); a bad one is one line naming the file, the line, the field
and what is allowed.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.errors import FkoptError
from fkopt.run.config_base import files_folder
from fkopt.files import MAX_INPUT_BYTES, csv_numbers, read_input
from fkopt.kinbench.clock import answer_prefix, answer_rows, is_ik, targets_of, track_settings
from fkopt.kinbench.outside import read_csv_columns

REQUIRED = ("robot", "query", "seconds", "reference_seconds")
#: The optional columns; with REQUIRED and the answers' q0, q1, ... / x0..x5 the only ones allowed.
OPTIONAL = ("claimed", "given_timeout_ms")
#: The largest given_timeout_ms: the tracks' own bound on a timeout (``timeouts_ms`` in (0, 10000]).
MAX_TIMEOUT_MS = 10_000.0
#: A wall time beyond an hour per query is no clock-track answer (the longest timeout is 10 s).
MAX_SECONDS = 3600.0
#: The largest |joint| (deg / m) or |pose component| (length unit / deg) a submission may give.
MAX_ANSWER = 1e6


def submission_path(config, entry, files: Path | None = None) -> Path:
    """A submission's file, in ``files`` (default: the suite file's folder)."""
    base = files if files is not None else files_folder(config)
    return Path(base if base is not None else ".") / entry.file


def submission_digest(config, entry, files: Path | None = None) -> str:
    """SHA-256 of a submission's file, read bounded (:func:`fkopt.files.read_input`)."""
    path = submission_path(config, entry, files)
    return hashlib.sha256(read_input(path, MAX_INPUT_BYTES, unpack=False,
                                     field=f"tracks.clock.submissions[{entry.solver}]")).hexdigest()


def _line(g: pd.DataFrame, k: int) -> int:
    """The CSV line of row k of ``g`` (line 1 is the header)."""
    return int(g.index[k]) + 2


def _check_numbers(g: pd.DataFrame, where: str, n: int, timed: bool) -> None:
    for col in ("query", "seconds", "reference_seconds") + (("given_timeout_ms",) if timed else ()):
        v = csv_numbers(g[col])       # never raises: a 400-digit integer is inf, refused here
        with np.errstate(invalid="ignore"):
            if col == "query":
                bad = ~np.isfinite(v) | (v < 0) | (v != np.round(v)) | (v >= n)
                allowed = f"an integer 0..{n - 1}"
            else:
                top = MAX_TIMEOUT_MS if col == "given_timeout_ms" else MAX_SECONDS
                bad = ~np.isfinite(v) | (v <= 0) | (v > top)
                allowed = f"a positive number of {'ms' if col == 'given_timeout_ms' else 's'} up to {top:g}"
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise FkoptError(f"{where}: line {_line(g, k)}: {col} = {g[col].astype(str).iloc[k]}; allowed: {allowed}")


_CLAIMS = {"true": True, "1": True, "1.0": True, "false": False, "0": False, "0.0": False, "nan": False, "": False}


def _claims(g: pd.DataFrame, where: str) -> np.ndarray:
    """The optional ``claimed`` column as booleans (empty: no claim)."""
    text = g["claimed"].astype(str).str.strip().str.lower()
    bad = ~text.isin(list(_CLAIMS))
    if bad.any():
        k = int(np.flatnonzero(bad.to_numpy())[0])
        raise FkoptError(f"{where}: line {_line(g, k)}: claimed = {g['claimed'].astype(str).iloc[k]}; "
                         "allowed: true, false, 1, 0 or empty")
    return text.map(_CLAIMS).to_numpy(bool)


def _answers(g: pd.DataFrame, where: str, robot: str, mech, dim: int) -> np.ndarray:
    """The (rows, dim) answers of one robot: joints ``q..`` (IK) or pose ``x..`` (FK), NaN rows
    for no answer."""
    prefix = answer_prefix(mech)
    what = f"{dim} joints" if is_ik(mech) else "a 6-DOF pose x, y, z, alpha, beta, gamma"
    cols = [f"{prefix}{d}" for d in range(dim)]
    absent = [c for c in cols if c not in g.columns]
    if absent:
        raise FkoptError(f"{where}: missing column '{absent[0]}' ({robot} answers with {what}: "
                         f"columns {cols[0]}..{cols[-1]})")
    extra = [c for c in g.columns if c[:1] in "qx" and c[1:].isdigit()
             and (c[:1] != prefix or int(c[1:]) >= dim) and g[c].notna().any()]
    if extra:
        raise FkoptError(f"{where}: robot {robot}: column {extra[0]} must be empty ({robot} answers with "
                         f"{what}: columns {cols[0]}..{cols[-1]})")
    raw = g[cols]
    values = np.stack([csv_numbers(raw[c]) for c in cols], axis=-1) if len(raw) else np.zeros((0, dim))
    with np.errstate(invalid="ignore"):
        bad = (raw.notna().to_numpy() & ~np.isfinite(values)) | (np.abs(values) > MAX_ANSWER)
    if bad.any():
        k, d = (int(i[0]) for i in np.nonzero(bad))
        raise FkoptError(f"{where}: line {_line(g, k)}: {cols[d]} = {raw.iloc[k, d]}; allowed: a finite "
                         f"number within +-{MAX_ANSWER:g}, or empty (no answer)")
    partial = np.isnan(values).any(axis=1) & ~np.isnan(values).all(axis=1)
    if partial.any():
        raise FkoptError(f"{where}: line {_line(g, int(np.flatnonzero(partial)[0]))}: answer partly empty; "
                         f"give all of {cols[0]}..{cols[-1]} or none (no answer)")
    return values


def read_submission(config, k: int, arms: dict, files: Path | None = None) -> pd.DataFrame:
    """Submission ``k`` of the clock track as answers rows (the columns of
    :func:`fkopt.kinbench.clock.run_clock`, ``source`` = ``submitted``), every answer judged by
    kinbench (:func:`fkopt.kinbench.clock.verdicts`: fkopt's FK for IK, the mechanism's inverse
    map for FK). ``arms``: robot -> (arm or parallel mechanism, queries (n, dim): the frozen
    joints or generating poses). Anything malformed is one line naming the file, the row, the
    field and what is allowed."""
    clock = config.tracks.clock
    entry = clock.submissions[k]
    path = submission_path(config, entry, files)
    where = f"tracks.clock.submissions[{entry.solver}]: {path}"
    df = read_csv_columns(path, where, REQUIRED, {"robot": str},
                          f"{', '.join(REQUIRED)}, q0, q1, ... (IK) or x0..x5 (FK)")
    stray = [c for c in df.columns if c not in (*REQUIRED, *OPTIONAL)
             and not (str(c)[:1] in "qx" and str(c)[1:].isdigit() and str(c)[1:] == str(int(str(c)[1:])))]
    if stray:      # a typo ('given_timeout', 'clamed') would otherwise be ignored without a word
        raise FkoptError(f"{where}: stray column '{str(stray[0])[:40]}'; allowed: {', '.join(REQUIRED + OPTIONAL)}, "
                         "q0, q1, ... (IK) or x0..x5 (FK)")
    if df.empty:
        raise FkoptError(f"{where}: no rows; needs one per query of each robot it answers "
                         f"(robots: {', '.join(arms)})")
    timed = "given_timeout_ms" in df.columns
    names = df["robot"].to_numpy()
    for robot in pd.unique(names):
        if robot not in arms:
            row = int(np.flatnonzero(names == robot)[0]) + 2 if isinstance(robot, str) else \
                int(np.flatnonzero(pd.isna(names))[0]) + 2
            if robot in clock.problems:     # a problem of the track whose answers the caller did not pass
                raise FkoptError(f"{where}: line {row}: robot '{robot}': this run takes submitted answers for "
                                 f"{', '.join(arms) or 'no robot'} only")
            raise FkoptError(f"{where}: line {row}: robot '{robot}' is not one of tracks.clock.problems "
                             f"({', '.join(clock.problems)})")
    frames = []
    for robot, (mech, queries) in arms.items():
        g = df[df["robot"] == robot]
        if g.empty:                 # a robot it does not answer (an IK solver has no FK answers)
            continue
        n, dim = len(queries), queries.shape[1]
        _, _, timeouts = track_settings(clock, mech)
        _check_numbers(g, where, n, timed)
        query = csv_numbers(g["query"]).astype(int)          # range-checked above
        given = csv_numbers(g["given_timeout_ms"]) if timed else np.zeros(len(g))
        have = list(zip(query, given))
        seen: set = set()
        for key in have:
            if key in seen:
                raise FkoptError(f"{where}: robot {robot}: query {key[0]}"
                                 + (f" at given_timeout_ms {key[1]:g}" if timed else "") + " appears twice")
            seen.add(key)
        listed = ", ".join(f"{t:g}" for t in timeouts)
        stray = [t for _, t in have if timed and t not in timeouts]
        if stray:
            raise FkoptError(f"{where}: robot {robot}: given_timeout_ms = {stray[0]:g} is not a timeout of the "
                             f"track; allowed: {listed}")
        want = [(i, float(t)) for i in range(n) for t in (timeouts if timed else (0.0,))]
        lost = [key for key in want if key not in seen]
        if lost:
            raise FkoptError(f"{where}: robot {robot}: no row for query {lost[0][0]}"
                             + (f" at given_timeout_ms {lost[0][1]:g}; every query of the track at every "
                                f"timeout ({listed} ms)" if timed else "; every query of the track")
                             + f" ({n} queries) needs one")
        answers = _answers(g, where, robot, mech, dim)
        frame = answer_rows(mech, robot, entry.solver, "outside", "submitted", query,
                            given if timed else np.nan,
                            csv_numbers(g["seconds"]), csv_numbers(g["reference_seconds"]),
                            _claims(g, where) if "claimed" in g else False, answers, queries[query],
                            targets_of(mech, queries[query]))
        frame.insert(1, "set", clock.set)
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)
