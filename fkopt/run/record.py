"""The one run record: a flat table, one row per run of a solver on one case, that every kind of
config (experiment, study, suite) produces from its tasks, and the writers of the files read
from it (``runs.csv``, ``summary.csv``).

Every kind's merge builds its record with :func:`run_record` (columns checked and cast to the
dtypes below, put in the order below); a writer never looks at a kind's own result objects.
The columns (``kind`` first) in their file order:

==========================  ========  =============================================================
column                      dtype     meaning
==========================  ========  =============================================================
kind                        str       ``experiment``, ``study`` or ``suite``
problem                     str       the experiment's/study's name, a suite's problem
class                       str       a suite problem's class (``parallel-fk-3dof``, ...)
set                         str       a suite's pose set (``uniform``, ``near-singular``, ...)
case                        str       an experiment's case label (``case-1``, ``random-3``, ...)
pose                        int64     index of the pose in its pose set or case list, **from 0**
                                      (the index the seed rule :func:`~fkopt.run.solving.task_seed` takes)
solver                      str       the algorithm/solver entry's label (its key)
track                       str       a suite solver's track (``black-box``, ``jacobian``, ``exact``)
run                         int64     run index, from 0 (the run's stream: :mod:`fkopt.numerics.streams`)
dim                         int64     a suite problem's dimension
budget                      int64     a suite run's evaluation budget
task_seed                   Int64     the case's seed (run k draws from its k-th child stream; NA: an imported outside run)
final_fitness               float64   best fitness at the end of the run
evaluations                 int64     fitness evaluations used (a suite: within its budget)
fitness                     float64   a suite run's best fitness within the budget
evals_to_<target>           float64   a suite: evaluations when the target was first reached (NaN: never)
iterations_done             int64     iterations the run made (fewer when it stopped at the threshold)
iterations_to_best          int64     first iteration at which the final best fitness was reached
iterations_to_threshold     float64   first iteration below the threshold (NaN: never)
evaluations_to_threshold    float64   the evaluation at which it went below the threshold (NaN: never)
start_<unknown>             float64   a tracking step's start point (NaN: a cold swarm)
x_<unknown>                 float64   the answer in the unknowns
pose_<pose variable>        float64   the pose the answer reaches (serial arms: fk of the joints)
position_error              float64   a serial arm's final position error
abs_error_<pose variable>   float64   |answer - target| per pose variable (angles wrapped)
final_<extra>               float64   an algorithm's own record at the last iteration (pheromone, ...)
==========================  ========  =============================================================

Index columns count from 0 everywhere (``pose``, ``run``, ``trajectory``, ``step``,
``iteration``); labels (``case-1``, ``pose-1``) are names, not indices.

``runs.csv`` is the record with the columns its folder fixes left out and ``solver`` under the
name its kind's readers know (the kind's ``not_in_runs`` and ``file_names``); ``summary.csv``
(experiments, studies) is :func:`summary_table` over it; a study's ``ecdf.csv`` and
``stats.csv`` pool its columns per solver, a suite's measures, ECDF and leaderboard are computed
from it (:mod:`fkopt.kinbench.measures`). Measured times are a second table next to it, the
timing record (:data:`TIMING_COLUMNS`), which :func:`timing_table` and
:func:`timing_runs_table` write for every kind.

Every worker returns JSON (a task file): an experiment's, a study's and a suite's solve task its
rows of the record (columns of lists; a study's and an experiment's also their rows of the timing
record, an experiment's and a suite's their trace), a clock-track task its answers, an assembly
search its solutions; every kind's merge puts the record in one :class:`~fkopt.run.result.RunResult`, so a study's
poses/heatmap/tracking tables are read from the record too. Still read from a kind's own slot
(``RunResult.own``): an experiment's inputs, its values, convergence table and figures (the
per-iteration curves of each (case, algorithm), which the flat record does not hold, and its
median and best runs' points), a study's pose set (points, grid, trajectories), an assembly's
solutions, a suite's clock-track answers.
"""
from __future__ import annotations

from types import MappingProxyType
from typing import Mapping

import numpy as np
import pandas as pd

from fkopt.files import nanmedian
from fkopt.run.kinds import kind_of

KINDS = ("experiment", "study", "suite")

#: (name, dtype) of the fixed columns, in file order; a name ending in "_" is a family of
#: columns (``x_`` -> ``x_alpha``, ``x_beta``, ...), all float64, at that place.
COLUMNS: tuple[tuple[str, str], ...] = (
    ("kind", "str"), ("problem", "str"), ("class", "str"), ("set", "str"), ("case", "str"),
    ("pose", "int64"), ("solver", "str"), ("track", "str"), ("run", "int64"), ("dim", "int64"),
    ("budget", "int64"), ("task_seed", "Int64"), ("final_fitness", "float64"), ("evaluations", "int64"),
    ("fitness", "float64"), ("evals_to_", "float64"), ("iterations_done", "int64"),
    ("iterations_to_best", "int64"), ("iterations_to_threshold", "float64"),
    ("evaluations_to_threshold", "float64"), ("start_", "float64"), ("x_", "float64"), ("pose_", "float64"),
    ("position_error", "float64"), ("abs_error_", "float64"), ("final_", "float64"),
)
FAMILIES = tuple(name for name, _ in COLUMNS if name.endswith("_"))

#: The names experiment and study folders (and the claims, reports and checks that read them) give
#: a record column: the solver is their ``algorithm``. Which names a kind's files use, and which
#: columns its runs.csv leaves out, are fields of its :class:`~fkopt.run.tasks.Kind`
#: (``file_names``, ``not_in_runs``).
ALGORITHM_NAMES: Mapping[str, str] = MappingProxyType({"solver": "algorithm"})


def _place(name: str) -> int:
    """Index into :data:`COLUMNS` of a column (its family's, for ``x_alpha``); -1: not in the schema."""
    for k, (col, _) in enumerate(COLUMNS):
        if name == col or (col.endswith("_") and name.startswith(col) and len(name) > len(col)):
            return k
    return -1


def _dtype(name: str) -> str:
    return COLUMNS[_place(name)][1]


def run_record(kind: str, columns: Mapping[str, object], rows: int | None = None) -> pd.DataFrame:
    """The run record of ``columns`` (name -> one value for every row, or one per row): checked
    against the schema, cast to its dtypes and put in its order (a family keeps the order
    given, e.g. the unknowns' order). ``kind`` is added as the first column."""
    if kind not in KINDS:
        raise ValueError(f"run record: kind {kind!r}, expected one of {', '.join(KINDS)}")
    unknown = [name for name in columns if _place(name) < 0]
    if unknown:
        raise ValueError(f"run record: columns {unknown} are not in the schema (fkopt.run.record.COLUMNS)")
    lengths = {len(v) for v in columns.values() if np.ndim(v) > 0}
    if len(lengths) > 1:
        raise ValueError(f"run record: columns of different lengths {sorted(lengths)}")
    n = lengths.pop() if lengths else (rows or 0)
    ordered = sorted(columns, key=_place)      # stable: a family keeps the order given
    data = {"kind": np.full(n, kind, dtype=object)}
    for name in ordered:
        value = columns[name]
        dtype = _dtype(name)
        arr = np.full(n, value, dtype=object) if np.ndim(value) == 0 else np.asarray(value)
        if dtype == "str":
            data[name] = arr.astype(object) if np.ndim(value) else arr
        elif dtype[0].isupper():            # a pandas nullable dtype (Int64: NA where a row has none)
            data[name] = pd.array(arr, dtype=dtype)
        else:
            data[name] = arr.astype(dtype)
    return pd.DataFrame(data)


def concat(records: list[pd.DataFrame]) -> pd.DataFrame:
    """Records of several tasks as one, with the columns in schema order (a column some rows
    lack is NaN there, e.g. an outside import's ``evals_to_`` targets)."""
    df = pd.concat(records, ignore_index=True)
    return df[sorted(df.columns, key=_place)]


# -- writers -------------------------------------------------------------------------------------
def runs_table(record: pd.DataFrame) -> pd.DataFrame:
    """``runs.csv`` of any kind: one row per run, the record's columns in schema order without
    those the kind's folder fixes, under the kind's file names (its ``Kind.not_in_runs`` and
    ``Kind.file_names``: the registry's kind named in the record's ``kind`` column)."""
    kind = kind_of(str(record["kind"].iloc[0]))
    keep = [c for c in record.columns if c not in kind.not_in_runs]
    return record[keep].rename(columns=dict(kind.file_names))


def summary_table(record: pd.DataFrame, settings: Mapping[str, Mapping], threshold: float | None,
                  by: tuple[str, ...] = ("case", "solver"), case: str | None = None,
                  extra: Mapping[str, object] | None = None) -> pd.DataFrame:
    """``summary.csv`` (experiments and studies): one row per group of runs (``by``: an
    experiment's (case, solver), a study's solver over every (pose, run)), in record order.

    Final fitness statistics (mean, std with ddof=1 over more than one run, best, worst,
    median), mean evaluations and, given a ``threshold``, the success rate (final fitness below
    it) and the medians of iterations and evaluations to it over the runs that reached it.
    ``settings[solver]`` gives the leading columns (method, population, iterations, runs) and
    the trailing ones (the paper's printed values); ``case`` names the ``case`` column of a
    record without one; ``extra`` adds columns before the printed ones (a study's ``poses``)."""
    rows = []
    for key, g in record.groupby(list(by), sort=False):
        key = key if isinstance(key, tuple) else (key,)
        group = dict(zip(by, key))
        solver = group["solver"]
        s = settings[solver]
        f = g["final_fitness"].to_numpy(float)
        row = {"case": group.get("case", case), "algorithm": solver, "method": s["method"],
               "population": s["population"], "iterations": s["iterations"], "runs": s["runs"],
               "mean_fitness": float(np.mean(f)), "std_fitness": float(np.std(f, ddof=1)) if f.size > 1 else 0.0,
               "best_fitness": float(np.min(f)), "worst_fitness": float(np.max(f)),
               "median_fitness": float(np.median(f)),
               "mean_evaluations": float(np.mean(g["evaluations"].to_numpy())), "threshold": threshold}
        if threshold is not None:
            row["success_rate"] = float(np.mean(f < threshold))
            row["median_iterations_to_threshold"] = nanmedian(g["iterations_to_threshold"].to_numpy(float))
            row["median_evaluations_to_threshold"] = nanmedian(g["evaluations_to_threshold"].to_numpy(float))
        row.update(extra or {})
        row.update(s.get("printed", {}))
        rows.append(row)
    return pd.DataFrame(rows)


# -- timing ----------------------------------------------------------------------------------------
#: The timing record: one row per timed sample of a solver on one case, next to the run record
#: (timings are measurements of the machine, never part of the deterministic record).
TIMING_COLUMNS: tuple[tuple[str, str], ...] = (
    ("kind", "str"),          # experiment, study, suite or assembly
    ("problem", "str"),       # as in the run record
    ("case", "str"),          # an experiment's case label; a study's "all"/"trajectory"
    ("pose", "int64"),        # the pose (from 0) the sample timed (a suite's task: -1, all of them)
    ("solver", "str"),
    ("run", "int64"),         # the run timed alone; -1: a batch of runs
    ("runs", "int64"),        # how many runs the sample's seconds cover
    ("seconds", "float64"),   # wall time (time.perf_counter) of the sample
    ("mode", "str"),          # "alone": one run solved by itself (the papers' mode, fkopt.run.timing);
                              # "batch": a batch's wall time over the runs it solved (amortised)
)
ALONE, BATCH = "alone", "batch"


def timing_record(kind: str, columns: Mapping[str, object]) -> pd.DataFrame:
    """The timing record of ``columns`` (name -> one value or one per row), cast and ordered
    (``kind`` may also be ``assembly``: a search's wall time, one batch)."""
    unknown = [c for c in columns if c not in dict(TIMING_COLUMNS)]
    if unknown or kind not in (*KINDS, "assembly"):
        raise ValueError(f"timing record: columns {unknown} / kind {kind!r} not in fkopt.run.record.TIMING_COLUMNS")
    n = max([len(v) for v in columns.values() if np.ndim(v) > 0] or [1])
    data = {}
    for name, dtype in TIMING_COLUMNS:
        value = kind if name == "kind" else columns.get(name, -1 if dtype == "int64" else "")
        arr = np.full(n, value, dtype=object) if np.ndim(value) == 0 else np.asarray(value)
        data[name] = arr.astype(object) if dtype == "str" else arr.astype(dtype)
    return pd.DataFrame(data)


def timing_table(timing: pd.DataFrame, settings: Mapping[tuple, Mapping], by: tuple[str, ...] = ("case", "solver"),
                 names: Mapping[str, str] | None = None, timed_alone: bool = False) -> pd.DataFrame:
    """``timing.csv`` of any kind: one row per group of samples (``by``), in record order.

    ``runs`` (the task's runs, from ``settings[group]``), ``timed_runs`` (the runs covered by
    the samples the statistics are over: the runs timed alone if the group has any, else its
    batches), mean, median and quartiles of the ms per run of those samples, ``amortised_ms_per_run`` (the
    batches' ms per run, averaged), ``total_s`` (the task's wall time, from ``settings``), then
    the rest of ``settings[group]`` (a study's ``poses``, the paper's printed times). ``names``
    renames the key columns (``solver`` -> ``algorithm`` in experiment and study folders);
    ``timed_alone``: only the groups with runs timed alone (an experiment's timed cases)."""
    rows = []
    if timed_alone:
        keys = set(map(tuple, timing.loc[timing["mode"] == ALONE, list(by)].to_numpy().tolist()))
        timing = timing[[tuple(k) in keys for k in timing[list(by)].to_numpy().tolist()]]
    for key, g in timing.groupby(list(by), sort=False):
        key = key if isinstance(key, tuple) else (key,)
        s = dict(settings[key])
        alone = g[g["mode"] == ALONE]
        batch = g[g["mode"] == BATCH]
        sample = alone if len(alone) else batch
        ms = sample["seconds"].to_numpy(float) / sample["runs"].to_numpy(float) * 1e3
        q25, med, q75 = np.percentile(ms, [25, 50, 75])
        row = dict(zip(by, key))
        row["runs"] = s.pop("runs")
        row.update({k: s.pop(k) for k in list(s) if k in ("poses",)})
        row.update({"timed_runs": int(sample["runs"].sum()), "mean_ms_per_run": float(np.mean(ms)), "median_ms_per_run": float(med),
                    "q25_ms_per_run": float(q25), "q75_ms_per_run": float(q75),
                    "amortised_ms_per_run": float(np.mean(batch["seconds"].to_numpy(float)
                                                          / batch["runs"].to_numpy(float)) * 1e3) if len(batch) else np.nan,
                    "total_s": s.pop("total_s")})
        row.update(s)
        rows.append(row)
    return pd.DataFrame(rows, columns=None if rows else [*by, "runs"]).rename(columns=dict(names or {}))


def timing_runs_table(timing: pd.DataFrame, names: Mapping[str, str] | None = None) -> pd.DataFrame:
    """``timing_runs.csv``: every run timed alone (ms), what timing claims test for a difference."""
    alone = timing[timing["mode"] == ALONE]
    return pd.DataFrame({"case": alone["case"].to_numpy(), "solver": alone["solver"].to_numpy(),
                         "run": alone["run"].to_numpy(), "ms": alone["seconds"].to_numpy(float) * 1e3}
                        ).rename(columns=dict(names or {}))
