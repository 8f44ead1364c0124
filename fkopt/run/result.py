"""The one result of a run: what every kind's merge returns and every writer reads.

A config of any kind (experiment, study, assembly search, suite) runs as tasks
(:mod:`fkopt.run.tasks`) whose records its kind merges into one :class:`RunResult`:

=========  ===========================================================================================
field      what it holds
=========  ===========================================================================================
config     the validated config (its ``folder_parts`` name the results folder)
record     the run record (:mod:`fkopt.run.record`): one row per run of a solver on one case, one
           JSON-able shape for every kind (an assembly search has none: ``None``)
timing     the timing record (:data:`fkopt.run.record.TIMING_COLUMNS`): measured times, beside it
trace      each run's best-so-far fitness where it improved (``trace.csv.gz``: an experiment's,
           :mod:`fkopt.run.trace`; a suite's, :mod:`fkopt.kinbench.traces`); None where a kind keeps none
own        **the one slot for what a kind alone has**, a small dataclass of that kind: an experiment's
           mechanism, cases and per-iteration curves (:class:`fkopt.kinds.experiment.runner.ExperimentOwn`),
           a study's mechanism and pose set (:class:`fkopt.kinds.study.runner.StudyOwn`), an assembly
           search's solutions (:class:`fkopt.kinds.assembly.kind.AssemblyOwn`), a suite's pose-set
           manifest and clock-track answers (:class:`fkopt.kinbench.runner.SuiteOwn`)
wall_s     the run's wall time (planning, tasks, merge; tasks computed elsewhere at their own time)
source     the config file it came from (meta.json's ``config_file``)
computed   ids of the tasks this invocation computed (the rest were resumed or given)
folder     the results folder it was written to (None: kept in memory)
=========  ===========================================================================================

Shared files (``runs.csv``, ``trace.csv.gz``, ``timing_runs.csv``, ``meta.json``, ``env.json``) are
made from the first four fields alone, by one maker each in :mod:`fkopt.run.writers`; a kind's own
files read ``own`` too.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd


@dataclass
class RunResult:
    config: Any
    record: pd.DataFrame | None
    timing: pd.DataFrame | None = None
    trace: pd.DataFrame | None = None
    own: Any = None
    wall_s: float = 0.0
    source: str | None = None
    computed: list[str] = field(default_factory=list)
    folder: Path | None = None

    @property
    def kind(self) -> str:
        """The config's kind (``experiment`` for a file without one)."""
        return getattr(self.config, "kind", None) or "experiment"


# -- a worker's arrays as JSON (task files) ---------------------------------------------------------
def to_json(value):
    """``value`` (arrays, dicts with any keys, tuples, numpy scalars, dataclass fields) as JSON-able
    data that :func:`from_json` turns back into the same values, bit for bit: a float64 is written
    by :func:`json.dumps` as its shortest round-tripping repr (NaN and infinities included), an
    array keeps its dtype and shape, a dict its key types (a snapshot's iteration is an int)."""
    if isinstance(value, np.ndarray):
        return {"array": value.dtype.str, "shape": list(value.shape), "data": value.ravel().tolist()}
    if isinstance(value, dict):
        return {"dict": [[to_json(k), to_json(v)] for k, v in value.items()]}
    if isinstance(value, tuple):
        return {"tuple": [to_json(v) for v in value]}
    if isinstance(value, list):
        return [to_json(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def from_json(data):
    """The values :func:`to_json` wrote."""
    if isinstance(data, list):
        return [from_json(v) for v in data]
    if not isinstance(data, dict):
        return data
    if "array" in data:
        return np.asarray(data["data"], dtype=np.dtype(data["array"])).reshape(data["shape"])
    if "dict" in data:
        return {from_json(k): from_json(v) for k, v in data["dict"]}
    if "tuple" in data:
        return tuple(from_json(v) for v in data["tuple"])
    raise ValueError(f"not an encoded value: keys {sorted(data)[:4]}")


def dataclass_to_json(obj) -> dict:
    """A dataclass's fields, each :func:`to_json`."""
    return {f.name: to_json(getattr(obj, f.name)) for f in fields(obj)}


def dataclass_from_json(cls, data: dict):
    """``cls`` rebuilt from :func:`dataclass_to_json` data (only its own fields)."""
    names = {f.name for f in fields(cls)}
    return cls(**{k: from_json(v) for k, v in data.items() if k in names})
