"""Regression check: rerun stored experiments from their recorded config and compare.

Comparison rules (documented tolerances that survive another machine's floating point):

* exact-by-construction numbers -- ``inputs.csv`` (inverse maps of printed poses), the
  ``target``/reference columns of ``values.csv``, counts (population, iterations, runs) and the
  printed values -- must agree to 1e-9 (relative) or exactly;
* results of the local exact methods (``nr``, ``lm``) are compared like swarm statistics below,
  because where they converge they converge to the same point: the values differ in the last bits
  at most;
* swarm statistics of ``summary.csv``: fitness columns in log10, both values below
  ``FITNESS_FLOOR`` count as equal (the noise floor of double precision), otherwise
  |log10 a - log10 b| <= ``LOG10_TOL`` decades; success rates within ``RATE_TOL``; medians of
  iterations/evaluations to the threshold within ``COUNT_RTOL`` (relative);
* ``values.csv`` median-run values within max(1e-6 * scale, 10 x the stored mean absolute error);
* single runs (``runs.csv``) and curves are not compared (medians, not single runs), and
  timing columns never are;
* the paper's claims recomputed with the rerun in place must keep the verdicts stored in
  ``<paper>/claims.csv`` (:func:`fkopt.reproduce.claims.rerun_verdict_drift`).

A mismatch names the experiment, the file, the row, the column and both values.
"""
from __future__ import annotations

import math
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from ..experiment.config import ExperimentConfig
from ..experiment.reports import write_tables
from ..experiment.runner import run_experiment
from .store import Experiment, Store

FITNESS_FLOOR = 1e-20
LOG10_TOL = 1.0
RATE_TOL = 0.1
COUNT_RTOL = 0.25
EXACT_RTOL = 1e-9

FITNESS_COLS = ("mean_fitness", "std_fitness", "best_fitness", "worst_fitness", "median_fitness")
RATE_COLS = ("success_rate",)
COUNT_COLS = ("median_iterations_to_threshold", "median_evaluations_to_threshold", "mean_evaluations")
KEY_COLS = ("case", "algorithm", "variable", "joint")


@dataclass
class Mismatch:
    experiment: str
    file: str
    row: str
    column: str
    stored: object
    rerun: object
    rule: str

    def __str__(self) -> str:
        return (f"{self.experiment}: {self.file} [{self.row}] column '{self.column}': stored {self.stored!r}, "
                f"rerun {self.rerun!r} ({self.rule})")


def _close_fitness(a: float, b: float) -> bool:
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if a < FITNESS_FLOOR and b < FITNESS_FLOOR:
        return True
    return abs(math.log10(max(a, 1e-300)) - math.log10(max(b, 1e-300))) <= LOG10_TOL


def _close_rel(a: float, b: float, rtol: float, atol: float = 0.0) -> bool:
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return abs(a - b) <= atol + rtol * max(abs(a), abs(b))


def compare_tables(name: str, file: str, stored: pd.DataFrame, rerun: pd.DataFrame) -> list[Mismatch]:
    out: list[Mismatch] = []
    if list(stored.columns) != list(rerun.columns) or len(stored) != len(rerun):
        return [Mismatch(name, file, "-", "shape", f"{len(stored)} rows {list(stored.columns)}",
                         f"{len(rerun)} rows {list(rerun.columns)}", "same rows and columns")]
    keys = [k for k in KEY_COLS if k in stored.columns]
    for i in range(len(stored)):
        s, r = stored.iloc[i], rerun.iloc[i]
        row = " / ".join(str(s[k]) for k in keys) or str(i)
        for col in stored.columns:
            a, b = s[col], r[col]
            if col in keys:
                ok, rule = a == b, "identical"
            elif col.endswith("_ms") or col in ("total_s",):
                continue
            elif col in FITNESS_COLS:
                ok, rule = _close_fitness(float(a), float(b)), f"log10 within {LOG10_TOL}, floor {FITNESS_FLOOR:g}"
            elif col in RATE_COLS:
                ok, rule = _close_rel(float(a), float(b), 0, RATE_TOL), f"within {RATE_TOL}"
            elif col in COUNT_COLS:
                ok, rule = _close_rel(float(a), float(b), COUNT_RTOL), f"relative {COUNT_RTOL}"
            elif file == "values.csv" and col in ("median_run_value", "best_run_value") or col.startswith("median_run_error_vs"):
                tol = max(1e-6 * max(1.0, abs(float(b))), 10 * float(s.get("mean_abs_error", 0) or 0))
                ok, rule = _close_rel(float(a), float(b), 0, tol), f"within {tol:.3g}"
            elif file == "values.csv" and col.endswith("_error") or col in ("median_run", "mean_abs_error"):
                continue   # errors of single runs follow from the values compared above
            elif pd.api.types.is_number(a) and pd.api.types.is_number(b):
                ok, rule = _close_rel(float(a), float(b), EXACT_RTOL, 1e-12), f"exact to {EXACT_RTOL:g}"
            else:
                ok, rule = (str(a) == str(b)) or (pd.isna(a) and pd.isna(b)), "identical"
            if not ok:
                out.append(Mismatch(name, file, row, col, _py(a), _py(b), rule))
    return out


def _py(v):
    return v.item() if hasattr(v, "item") else v


COMPARED = ("summary.csv", "values.csv", "inputs.csv")


def check_experiment(exp: Experiment, config: ExperimentConfig | None = None) -> list[Mismatch]:
    """Rerun ``exp`` from its recorded (or the given) config and compare the stored tables."""
    if exp.config.get("kind") == "assembly":  # all assembly modes (fkopt.experiment.assembly)
        from ..experiment.assembly import check_assembly
        return check_assembly(exp, config)
    if exp.config.get("kind") == "study":     # a workspace study (fkopt.study)
        from ..study.check import check_study
        return check_study(exp, config)
    config = config or ExperimentConfig(**exp.config)
    result = run_experiment(config, source=exp.meta.get("config_file"))
    tmp = Path(tempfile.mkdtemp(prefix="fkopt-check-"))
    try:
        write_tables(result, tmp)
        label = f"{exp.paper}/{exp.name}"
        out: list[Mismatch] = []
        for file in COMPARED:
            stored_exists, rerun_exists = exp.has(file), (tmp / file).exists()
            if stored_exists != rerun_exists:
                out.append(Mismatch(label, file, "-", "file", stored_exists, rerun_exists, "present in both"))
            elif stored_exists:
                out += compare_tables(label, file, exp.table(file), pd.read_csv(tmp / file))
        from .claims import rerun_verdict_drift   # a claim's verdict must not change either
        return out + rerun_verdict_drift(exp, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def select(store: Store, subset: str = "all") -> list[Experiment]:
    """Experiments to check: ``all``, or ``ci`` (those whose config has ``check: ci``, the default)."""
    exps = store.experiments()
    if subset == "ci":
        exps = [e for e in exps if e.config.get("check", "ci") == "ci"]
    return exps
