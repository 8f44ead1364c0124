"""Each run's best-so-far trace, compactly: ``trace.csv.gz`` in every experiment folder (the
:attr:`~fkopt.run.result.RunResult.trace` of its result, computed by each task).

One row per improvement of a run's best-so-far fitness, at the exact evaluation at which it
happened -- the data IOHanalyzer's ``.dat`` files hold (see :mod:`fkopt.tools.export`):

=============  ==========================================================================
case           case label
algorithm      algorithm label
run            run id (its stream, :mod:`fkopt.numerics.streams`)
iteration      iteration in which the evaluation happened (0: the initial population)
evaluations    the evaluation's number, counted from 1 (points of a population in order)
best_fitness   best-so-far fitness from then on
=============  ==========================================================================

Exactness: the algorithms report the fitness of every point they evaluate, in order
(:class:`fkopt.algorithms.base.EvaluationLog`); the library adapters count every point they
hand to the library (:mod:`fkopt.adapters.base`). So an improvement carries its own evaluation
number, not the count at the end of its iteration. The exception are steps that do not report
their points -- the local methods' (``lm``, ``nr``, ``dls`` and a hybrid's LM phase) iterations,
whose counts include Jacobian evaluations: their improvements carry the count at the end of the
iteration. Row 1 of a run is always its first evaluation (evaluation 1, whatever its value, as
IOH readers split runs there); its last row is the evaluations used in all (the best value
repeated if the last evaluation did not improve), so a reader knows the run's budget. Runs that
stopped at the threshold end at their stop, and their final fitness is in the trace.
:func:`fkopt.run.writers.write_outputs` gzips it with a fixed timestamp, so the same results give
the same bytes.
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.files import MAX_UNPACKED, check_csv_shape, csv_numbers, read_input
from fkopt.errors import FkoptError

FILE = "trace.csv.gz"
COLUMNS = ("case", "algorithm", "run", "iteration", "evaluations", "best_fitness")


def history_events(history: np.ndarray, evaluations: np.ndarray):
    """Events (row, evaluation, fitness) at the resolution of the records: each improvement of
    ``history`` at the count that ends its iteration (for results without exact events)."""
    keep = np.ones(history.shape, dtype=bool)
    keep[:, 1:] = history[:, 1:] < history[:, :-1]
    r, c = np.nonzero(keep)
    return r, evaluations[r, c].astype(np.int64), history[r, c]


def run_trace(events, evaluations: np.ndarray, done: np.ndarray | None = None):
    """The trace rows of each run: (row, iteration, evaluation, best fitness) arrays.

    ``events`` are (row, evaluation, fitness) improvements sorted by row and evaluation
    (:attr:`fkopt.solve.Result.events`); ``evaluations`` (runs, iterations + 1) the cumulative
    counts, ``done`` (runs,) the last iteration that counts per run (default: the last one).
    A run's last row is its final count.
    """
    evaluations = np.asarray(evaluations, dtype=np.int64)
    runs, n = evaluations.shape
    done = np.full(runs, n - 1) if done is None else np.asarray(done, dtype=int)
    final = evaluations[np.arange(runs), done]
    r, e, f = (np.asarray(a) for a in events)
    keep = e <= final[r]
    r, e, f = r[keep], e[keep].astype(np.int64), f[keep]
    last = np.flatnonzero(np.r_[r[1:] != r[:-1], True]) if r.size else np.empty(0, np.intp)
    close = last[e[last] < final[r[last]]]
    r = np.concatenate([r, r[close]])
    f = np.concatenate([f, f[close]])
    e = np.concatenate([e, final[r[len(r) - len(close):]]])
    order = np.lexsort((e, r))
    r, e, f = r[order], e[order], f[order]
    big = int(evaluations.max(initial=0)) + 1
    flat = (np.arange(runs, dtype=np.int64)[:, None] * big + evaluations).ravel()
    it = np.searchsorted(flat, r * big + e, side="left") - r * n
    return r, np.minimum(it, n - 1), e, f


def case_trace(case: str, algorithm: str, res) -> pd.DataFrame:
    """The trace rows of one algorithm's runs on one case (a single-target
    :class:`~fkopt.solve.Result`): computed by the task that solved them (:func:`run_trace`)."""
    ev = np.asarray(res.evaluation_history).reshape(-1, res.evaluation_history.shape[-1])
    events = res.events if res.events is not None else history_events(np.asarray(res.history).reshape(ev.shape), ev)
    r, it, e, f = run_trace(events, ev, np.asarray(res.iterations_done).reshape(-1))
    return pd.DataFrame({"case": case, "algorithm": algorithm, "run": np.asarray(res.run_ids)[r % len(res.run_ids)],
                         "iteration": it, "evaluations": e, "best_fitness": f})


#: dtypes of a trace's columns (a task file's lists read back).
DTYPES = {"case": object, "algorithm": object, "run": np.int64, "iteration": np.int64, "evaluations": np.int64,
          "best_fitness": np.float64}


def trace_frame(columns: dict) -> pd.DataFrame:
    """A task file's trace (column -> list) as trace rows, dtypes restored."""
    return pd.DataFrame({c: np.asarray(columns[c], dtype=DTYPES[c]) for c in COLUMNS})


def concat_traces(frames: list[pd.DataFrame]) -> pd.DataFrame:
    """The traces of several tasks as one (``trace.csv.gz``), in the order given."""
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=list(COLUMNS))


#: Largest decompressed ``trace.csv.gz`` :func:`read_trace` accepts (:data:`fkopt.files.MAX_UNPACKED`).
MAX_BYTES = MAX_UNPACKED


#: Integer columns of a trace (of an experiment's, or a suite's: :mod:`fkopt.kinbench.traces`);
#: ``best_fitness`` is a number, every other column a non-empty label.
INTEGER_COLUMNS = ("pose", "run", "iteration", "evaluations")


def read_trace(folder: Path, limit: int = MAX_BYTES, columns: tuple[str, ...] = COLUMNS) -> pd.DataFrame:
    """``folder/trace.csv.gz``, checked: a readable gzip of at most ``limit`` bytes unpacked
    (measured before parsing, so memory stays bounded), the ``columns`` (an experiment's
    :data:`COLUMNS` by default; a suite's trace has others), integer counts (evaluations >= 1)
    and numeric fitness values. Anything else is an FkoptError naming the file and what is wrong."""
    path = Path(folder) / FILE
    labels = [c for c in columns if c not in INTEGER_COLUMNS and c != "best_fitness"]
    # bounded: a regular file inside the folder, unpacked size measured by streaming before parsing
    data = read_input(path, MAX_UNPACKED, within=folder, unpacked=MAX_UNPACKED if limit is None else limit)
    check_csv_shape(data, str(path))
    try:
        table = pd.read_csv(io.BytesIO(data), dtype=dict.fromkeys(labels, "category"))
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError, ValueError) as err:
        text = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise FkoptError(f"{path}: not a CSV table ({text})") from None
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise FkoptError(f"{path}: missing column(s) {', '.join(missing)}; a trace has {', '.join(columns)}")
    for col in labels:
        if table[col].isna().any():
            i = int(np.flatnonzero(table[col].isna().to_numpy())[0])
            raise FkoptError(f"{path}: row {i + 1} column {col}: empty")
    for col in (c for c in INTEGER_COLUMNS if c in columns):
        num = pd.Series(csv_numbers(table[col]), index=table.index)   # a 400-digit integer: inf, refused here
        low = 1 if col == "evaluations" else 0
        bad = (num.isna() | (num != np.floor(num)) | (num < low) | (num > 2 ** 53)).to_numpy()
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise FkoptError(f"{path}: row {i + 1} column {col}: {table[col].iloc[i]!r} is not an integer >= {low}")
        table[col] = num.astype(np.int64)
    num = pd.Series(csv_numbers(table["best_fitness"]), index=table.index)
    bad = num.isna().to_numpy()
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise FkoptError(f"{path}: row {i + 1} column best_fitness: {table['best_fitness'].iloc[i]!r} "
                         "is not a number")
    table["best_fitness"] = num.astype(float)
    return table
