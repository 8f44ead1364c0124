"""Outside results on the clock track: a solver run on someone else's machine, submitted per
query as its returned joints and wall times, verified and ranked here.

A suite's ``tracks.clock.submissions`` names, per solver, a CSV file (relative to the suite
file), the machine it ran on and the reference solver timed beside it::

    tracks:
      clock:
        problems: [ur5, panda]
        solvers: [fkopt.inverse, tracik]
        submissions:
          - {solver: my-ik, file: my-ik.csv, machine: "i7-1185G7, 1 thread, Ubuntu 24.04", reference: rtb-ik_LM}

**CSV**: one row per query of the track (every robot of ``problems``, queries 0 .. n-1 of the
track's ``set``: the frozen poses, whose targets are their tip frames by fkopt's FK), columns

=====================  ==============================================================================
robot                  a problem name of ``tracks.clock.problems`` (e.g. ``ur5``)
query                  the pose's index in the set file (0-based)
q0, q1, ...            the returned joints in fkopt's units (deg, m for prismatic), in the order of
                       the arm's moving joints from base to tip; all empty: no answer. Columns beyond
                       the arm's joint count stay empty
seconds                the query's wall time on the submitter's machine (s)
reference_seconds      the reference solver's wall time on the same query, measured beside it on
                       the same machine (s); the board ranks seconds / reference_seconds
claimed                optional: what the solver said of its answer (stored, never counted)
given_timeout_ms       optional: the timeout the solver was given; then one row per query and per
                       timeout of the track, else the one time is judged at every timeout
=====================  ==============================================================================

kinbench verifies every answer with its own FK and the arm's joint limits
(:func:`fkopt.kinbench.physical.ik_verdicts`): a row that claims success on a wrong answer, or
on joints outside the limits, is a failure. The file's SHA-256 is recorded in meta.json and its
rows join answers.csv.gz (``source`` = ``submitted``), so the board can be re-verified.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import FkoptError
from ..experiment.config import files_folder
from ..files import MAX_INPUT_BYTES, read_input
from .outside import read_csv_columns
from .physical import ik_verdicts

REQUIRED = ("robot", "query", "seconds", "reference_seconds")


def submission_path(config, entry, files: Path | None = None) -> Path:
    """A submission's file, in ``files`` (default: the suite file's folder)."""
    base = files if files is not None else files_folder(config)
    return Path(base if base is not None else ".") / entry.file


def submission_digest(config, entry, files: Path | None = None) -> str:
    """SHA-256 of a submission's file, read bounded (:func:`fkopt.files.read_input`)."""
    path = submission_path(config, entry, files)
    return hashlib.sha256(read_input(path, MAX_INPUT_BYTES, unpack=False,
                                     field=f"tracks.clock.submissions[{entry.solver}]")).hexdigest()


def read_submission(config, k: int, arms: dict, files: Path | None = None) -> pd.DataFrame:
    """Submission ``k`` of the clock track as answers rows (the columns of
    :func:`fkopt.kinbench.clock.run_clock`, ``source`` = ``submitted``), every answer judged by
    fkopt's FK. ``arms``: robot -> (arm, queries (n, dof)). Anything malformed is one line
    naming the file, the row and the field."""
    clock = config.tracks.clock
    entry = clock.submissions[k]
    path = submission_path(config, entry, files)
    where = f"tracks.clock.submissions[{entry.solver}]: {path}"
    df = read_csv_columns(path, where, REQUIRED, {"robot": str}, f"{', '.join(REQUIRED)}, q0, q1, ...")
    timeouts = clock.timeouts_ms
    timed = "given_timeout_ms" in df.columns
    frames = []
    for robot in df["robot"].unique():
        if robot not in arms:
            row = int(np.flatnonzero(df["robot"].to_numpy() == robot)[0]) + 2
            raise FkoptError(f"{where}: line {row}: robot '{robot}' is not one of tracks.clock.problems "
                             f"({', '.join(arms)})")
    for robot, (arm, queries) in arms.items():
        g = df[df["robot"] == robot]
        n = len(queries)
        for col in ("query", "seconds", "reference_seconds") + (("given_timeout_ms",) if timed else ()):
            v = pd.to_numeric(g[col], errors="coerce").to_numpy(float)
            bad = ~np.isfinite(v) | (v < 0 if col == "query" else v <= 0)
            if col == "query":
                bad |= (v != np.round(v)) | (v >= n)
            if bad.any():
                line = int(g.index[np.flatnonzero(bad)[0]]) + 2
                allowed = f"an integer 0..{n - 1}" if col == "query" else "a positive number"
                raise FkoptError(f"{where}: line {line}: {col} = {g[col].astype(str).iloc[np.flatnonzero(bad)[0]]}; "
                                 f"allowed: {allowed}")
        keys = ["query", "given_timeout_ms"] if timed else ["query"]
        want = pd.MultiIndex.from_product([range(n), timeouts]) if timed else pd.Index(range(n))
        have = pd.MultiIndex.from_frame(g[keys].astype(float)) if timed else pd.Index(g["query"].astype(int))
        if have.has_duplicates:
            raise FkoptError(f"{where}: robot {robot}: query {have[have.duplicated()][0]} appears twice")
        lost = want.difference(have.astype(float) if timed else have)
        if len(lost):
            raise FkoptError(f"{where}: robot {robot}: no row for query {lost[0]}; every query of the track "
                             + ("at every timeout " if timed else "") + f"({n} queries) needs one")
        cols = [f"q{d}" for d in range(arm.dof)]
        absent = [c for c in cols if c not in g.columns]
        if absent:
            raise FkoptError(f"{where}: missing column '{absent[0]}' ({robot} has {arm.dof} joints)")
        extra = [c for c in g.columns if c.startswith("q") and c[1:].isdigit() and int(c[1:]) >= arm.dof
                 and g[c].notna().any()]
        if extra:
            raise FkoptError(f"{where}: robot {robot}: column {extra[0]} must be empty ({arm.dof} joints)")
        joints = g[cols].apply(pd.to_numeric, errors="coerce").to_numpy(float)
        partial = np.isnan(joints).any(axis=1) & ~np.isnan(joints).all(axis=1)
        if partial.any():
            raise FkoptError(f"{where}: line {int(g.index[np.flatnonzero(partial)[0]]) + 2}: joints partly empty; "
                             "give all of them or none (no answer)")
        query = g["query"].to_numpy(int)
        v = ik_verdicts(arm, joints, arm.fk_matrix(queries[query]))
        frame = pd.DataFrame({"robot": robot, "set": clock.set, "query": query, "solver": entry.solver,
                              "entry": "outside", "source": "submitted",
                              "given_timeout_ms": g["given_timeout_ms"].to_numpy(float) if timed else np.nan,
                              "seconds": g["seconds"].to_numpy(float),
                              "reference_seconds": g["reference_seconds"].to_numpy(float),
                              "claimed": g["claimed"].astype(bool).to_numpy() if "claimed" in g else False,
                              "position_m": v["position_m"], "rotation_rad": v["rotation_rad"],
                              "in_limits": v["in_limits"]})
        for d in range(arm.dof):
            frame[f"q{d}"] = joints[:, d]
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)
