"""Comparison of stored and rerun result tables (floor 0; used by ``fkopt check`` for every kind).

Two modes (:mod:`fkopt.provenance` explains the platform fingerprint):

* **exact** -- the stored ``env.json`` fingerprint equals this machine's: every deterministic
  file (all CSVs except timing files, and ``meta.json``) must be byte-identical to the rerun's;
* **tolerant** -- another platform: distribution-level tolerances that a change of the last
  bits of floating point can cause, yet tight enough to catch a real change:

  ========================================  =====================================================
  column                                    rule
  ========================================  =====================================================
  fitness statistics (mean, std, ...)       |log10 a - log10 b| <= ``LOG10_TOL`` (0.5 decades, so
                                            a factor 5 is caught); both below ``FITNESS_FLOOR``
                                            (1e-20, double precision noise) count as equal
  success rates                             within ``RATE_TOL`` (0.04: 1 -> 0.95 is caught)
  medians of iterations/evaluations to      relative ``COUNT_RTOL`` (0.1: +18 % is caught)
  the threshold
  mean evaluations                          relative ``EVALUATIONS_RTOL`` (0.01: +2 % is caught)
  values.csv median/best run values         within max(1e-6 x scale, 10 x stored mean abs. error)
  everything else (counts, targets,         exact to ``EXACT_RTOL`` (1e-9 relative)
  inputs, keys, printed values)
  single runs (runs.csv), curves            same rows, columns and keys (case, algorithm, run,
  (convergence.csv)                         seeds, iteration) exactly; values are single runs and
                                            follow the platform's floating point
  ========================================  =====================================================

Independently of the mode, every stored deterministic file must match the SHA-256 recorded for
it in ``meta.json`` when it was written (:func:`file_digests`), so any edit of a stored file --
``runs.csv`` and ``convergence.csv`` included -- is caught on any platform.

A mismatch names the experiment, the file, the row, the column and both values.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from .outputs import CURVES, ENV_FILE, TIMING, deterministic_files, file_digests, files_with, sha256  # noqa: F401

FITNESS_FLOOR = 1e-20
LOG10_TOL = 0.5
RATE_TOL = 0.04
COUNT_RTOL = 0.1
EVALUATIONS_RTOL = 0.01
EXACT_RTOL = 1e-9

FITNESS_COLS = ("mean_fitness", "std_fitness", "best_fitness", "worst_fitness", "median_fitness")
RATE_COLS = ("success_rate",)
COUNT_COLS = ("median_iterations_to_threshold", "median_evaluations_to_threshold")
EVALUATION_COLS = ("mean_evaluations",)
KEY_COLS = ("case", "algorithm", "variable", "joint", "run", "iteration", "task_seed", "pose", "step")
#: Files whose values are single runs or curves: compared in shape and keys only (tolerant mode).
SHAPE_ONLY = files_with(CURVES)
#: Never deterministic: wall-clock measurements and the environment.
TIMING_FILES = files_with(TIMING) + (ENV_FILE,)


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


def _py(v):
    return v.item() if hasattr(v, "item") else v


def compare_tables(name: str, file: str, stored: pd.DataFrame, rerun: pd.DataFrame) -> list[Mismatch]:
    """Tolerant comparison of one table (rules in the module docstring)."""
    out: list[Mismatch] = []
    if list(stored.columns) != list(rerun.columns) or len(stored) != len(rerun):
        return [Mismatch(name, file, "-", "shape", f"{len(stored)} rows {list(stored.columns)}",
                         f"{len(rerun)} rows {list(rerun.columns)}", "same rows and columns")]
    keys = [k for k in KEY_COLS if k in stored.columns]
    shape_only = file in SHAPE_ONLY
    for i in range(len(stored)):
        s, r = stored.iloc[i], rerun.iloc[i]
        row = " / ".join(str(s[k]) for k in keys) or str(i)
        for col in stored.columns:
            a, b = s[col], r[col]
            if col in keys:
                ok, rule = (a == b) or (pd.isna(a) and pd.isna(b)), "identical"
            elif shape_only or col.endswith("_ms") or col in ("total_s",):
                continue
            elif col in FITNESS_COLS:
                ok, rule = _close_fitness(float(a), float(b)), f"log10 within {LOG10_TOL}, floor {FITNESS_FLOOR:g}"
            elif col in RATE_COLS:
                ok, rule = _close_rel(float(a), float(b), 0, RATE_TOL), f"within {RATE_TOL}"
            elif col in COUNT_COLS:
                ok, rule = _close_rel(float(a), float(b), COUNT_RTOL), f"relative {COUNT_RTOL}"
            elif col in EVALUATION_COLS:
                ok, rule = _close_rel(float(a), float(b), EVALUATIONS_RTOL), f"relative {EVALUATIONS_RTOL}"
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


def first_difference(name: str, file: str, stored: bytes, rerun: bytes) -> Mismatch:
    """Name the first differing line of two byte strings (exact mode)."""
    a, b = stored.decode("utf-8", "replace").splitlines(), rerun.decode("utf-8", "replace").splitlines()
    header = a[0].split(",") if a and file.endswith(".csv") else []
    for i, (x, y) in enumerate(zip(a, b)):
        if x != y:
            col = "-"
            xs, ys = x.split(","), y.split(",")
            for j, (u, v) in enumerate(zip(xs, ys)):
                if u != v:
                    col = header[j] if j < len(header) else str(j)
                    x, y = u, v
                    break
            return Mismatch(name, file, f"line {i + 1}", col, x, y, "byte-identical (same platform)")
    return Mismatch(name, file, f"line {min(len(a), len(b)) + 1}", "-", f"{len(a)} lines", f"{len(b)} lines",
                    "byte-identical (same platform)")


def compare_folders(name: str, stored: Path, rerun: Path, exact: bool,
                    files: list[str] | None = None) -> list[Mismatch]:
    """Compare the deterministic files of two result folders (exactly, or by the tolerances)."""
    stored, rerun = Path(stored), Path(rerun)
    names = files if files is not None else sorted(set(deterministic_files(stored)) | set(deterministic_files(rerun)))
    out: list[Mismatch] = []
    for file in names:
        s, r = stored / file, rerun / file
        if s.exists() != r.exists():
            out.append(Mismatch(name, file, "-", "file", "present" if s.exists() else "missing",
                                "present" if r.exists() else "missing", "present in both"))
            continue
        if not s.exists():
            continue
        if file == "meta.json" and not exact:
            out += compare_meta(name, s, r)
        elif exact:
            a, b = s.read_bytes(), r.read_bytes()
            if a != b:
                out.append(first_difference(name, file, a, b))
        elif file.endswith(".csv"):
            try:
                table = pd.read_csv(s)
            except (OSError, ValueError, pd.errors.ParserError) as err:
                out.append(Mismatch(name, file, "-", "file", f"unreadable ({err})", "readable", "readable"))
                continue
            out += compare_tables(name, file, table, pd.read_csv(r))
    return out


#: meta.json keys that depend on the platform (digests of the files) or the invocation.
META_VARIABLE = ("files", "config_file")


def compare_meta(name: str, stored: Path, rerun: Path) -> list[Mismatch]:
    """meta.json on another platform: everything but the file digests must be equal."""
    import json
    try:
        a = json.loads(Path(stored).read_text())
    except (OSError, ValueError) as err:
        return [Mismatch(name, "meta.json", "-", "file", f"unreadable ({err})", "readable", "valid JSON")]
    b = json.loads(Path(rerun).read_text())
    out = []
    for key in sorted(set(a) | set(b)):
        if key not in META_VARIABLE and a.get(key) != b.get(key):
            out.append(Mismatch(name, "meta.json", "-", key, a.get(key), b.get(key), "identical"))
    return out
