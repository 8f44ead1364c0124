"""Each run's best-so-far trace, compactly: ``trace.csv.gz`` in every experiment folder.

One row per improvement of a run's best-so-far fitness, with the cumulative fitness
evaluations at that point -- the data IOHanalyzer's ``.dat`` files hold (see
:mod:`fkopt.export`):

=============  ==========================================================================
case           case label
algorithm      algorithm label
run            run id (its stream, :mod:`fkopt.streams`)
iteration      iteration at which the improvement was recorded (0: the initial population)
evaluations    evaluations used when the improvement was recorded
best_fitness   best-so-far fitness from then on
=============  ==========================================================================

Resolution: fkopt's algorithms record once per iteration, so an improvement carries the
evaluation count at the end of the iteration in which it happened (for the library adapters,
at the checkpoint of :mod:`fkopt.adapters.base`). Row 0 of a run is its initial population;
its last row is always the evaluations used in all (the best value repeated if the last
iteration did not improve), so a reader knows the run's budget. Runs that stopped at the
threshold end at their stop. :func:`fkopt.outputs.write_outputs` gzips it with a fixed
timestamp, so the same results give the same bytes.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

FILE = "trace.csv.gz"
COLUMNS = ("case", "algorithm", "run", "iteration", "evaluations", "best_fitness")


def run_trace(history: np.ndarray, evaluations: np.ndarray, done: np.ndarray | None = None):
    """Improvements of each run: (run index, iteration, evaluations, best fitness) arrays.

    ``history`` and ``evaluations`` are shaped (runs, iterations + 1); ``done`` (runs,) is the
    last iteration that counts per run (default: the last one).
    """
    runs, n = history.shape
    done = np.full(runs, n - 1) if done is None else np.asarray(done, dtype=int)
    t = np.arange(n)
    keep = np.ones((runs, n), dtype=bool)
    keep[:, 1:] = history[:, 1:] < history[:, :-1]
    keep[np.arange(runs), done] = True          # the run's final evaluation count
    keep &= t[None, :] <= done[:, None]
    r, c = np.nonzero(keep)
    return r, c, evaluations[r, c], history[r, c]


def trace_table(er) -> pd.DataFrame:
    """The trace of every run of an :class:`~fkopt.experiment.runner.ExperimentResult`."""
    frames = []
    for rec in er.records:
        res = rec.result
        r, it, e, f = run_trace(np.asarray(res.history), np.asarray(res.evaluation_history),
                            np.asarray(res.iterations_done))
        frames.append(pd.DataFrame({"case": rec.case.label, "algorithm": rec.spec.key,
                                    "run": np.asarray(res.run_ids)[r], "iteration": it,
                                    "evaluations": e.astype(np.int64),
                                    "best_fitness": f}))
    if not frames:
        return pd.DataFrame(columns=list(COLUMNS))
    return pd.concat(frames, ignore_index=True)


def read_trace(folder: Path) -> pd.DataFrame:
    return pd.read_csv(Path(folder) / FILE, compression="gzip")
