"""Comparison of stored and rerun result folders (floor 0; used by ``fkopt check`` for every kind).

What a rerun on another machine can change follows from what decides the bits
(:func:`fkopt.run.provenance.platform_tier` reads it off the stored ``env.json``):

* **exact** (same fingerprint): every deterministic file (all CSVs but the timing files, and
  ``meta.json``) must be byte-identical to the rerun's.
* **blas** (only the BLAS library, its kernel or thread count differ): a row that no BLAS call
  touched -- an algorithm with ``blas_free`` on a mechanism with ``blas_free_fitness`` (fkopt's
  swarms on its built-in mechanisms) -- is still compared cell by cell, as text, in every file:
  the same elementwise operations on the same inputs give the same bits. The other rows
  (Newton, LM, DLS, the hybrids, the assembly search, adapters, plug-ins) are *path-dependent*:
  one ulp of a BLAS kernel can move an iterate, and the path of a local solver amplifies it, so
  their outcomes are compared by the rules below.
* **any** (numpy, its SIMD targets, Python... differ too, or an older fingerprint): every row is
  path-dependent.

Rules for path-dependent rows (one table; ``Mismatch.rule`` names the rule that failed):

=============================================  ==================================================
quantity                                       rule
=============================================  ==================================================
keys, settings, targets, pose coordinates,      identical (as text): a platform cannot move them
printed values, counts of solutions found
final fitness of each run (``runs.csv``)        a fitness at or below the reach level (the
                                               config's threshold, else ``REACHED`` = 1e-12) is
                                               "reached" and ties with any other reached value;
                                               stored and rerun runs of an algorithm, pooled over
                                               cases/poses, compare by a two-sided Mann-Whitney
                                               rank test; the number reached by Fisher's exact
                                               test
path counts (``evaluations``, ``iterations_*``,  Mann-Whitney rank test over all runs and cases of
``evaluations_to_threshold``, assembly hits)    an algorithm (never a relative bound on a mean)
solutions (``x_*`` of runs at or below          the set of distinct solutions (clustered within
``SOLUTION_FITNESS``; assembly solutions)       ``SOLUTION_RTOL`` x max(1, |value|) per variable)
                                               must be the same set in stored and rerun (FK of
                                               parallel mechanisms; a serial arm's IK solutions
                                               are not isolated and are compared by fitness)
statistics derived from runs (summary means,    not compared to the rerun (they follow from the
medians, success rates; values.csv; curves;     runs above); their agreement with the stored runs
trace rows; ECDF; rank tests)                   is checked on every platform (below)
=============================================  ==================================================

The rank and Fisher tests of one experiment form one family: Holm's correction keeps the
family-wise false-alarm rate of one experiment at ``ALPHA`` = 0.001. Identical samples give p = 1.

Checks on every platform, whatever the tier (:func:`summary_consistency` here, and the
recomputed fitness of every stored run in :mod:`fkopt.reproduce.check`):

* every deterministic file must match the SHA-256 recorded for it in ``meta.json``;
* ``summary.csv``'s statistics must be those of the stored ``runs.csv`` (mean, std, best, worst
  and median fitness, mean evaluations, success rate, medians to the threshold) to the precision
  the CSV keeps, so an edited summary is caught even with re-signed digests;
* ``meta.json`` must equal the rerun's but for the file digests.

A mismatch names the experiment, the file, the row, the column, both values and the rule.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from fkopt.errors import FkoptError
from fkopt.run.writers import (ENV_FILE, RUNS, STEPS, TIMING, deterministic_files, file_digests, files_with,  # noqa: F401
                      files_with_rows, sha256)
from fkopt.run.provenance import ANY, BLAS, EXACT  # noqa: F401
from fkopt.files import csv_numbers, parse_csv, read_stored, read_stored_csv

#: Family-wise significance level of the rank and Fisher tests of one experiment (Holm-corrected):
#: over the 23 stored experiments a false alarm somewhere stays below 23 x 0.001 = 2.3 %.
ALPHA = 0.001
#: Fitness at or below which a run counts as reached when the config sets no threshold.
REACHED = 1e-12
#: Runs at or below this fitness are solutions, compared as a set.
SOLUTION_FITNESS = 1e-12
#: Two solutions are the same when every variable agrees within this times max(1, |value|).
SOLUTION_RTOL = 1e-3
#: summary.csv against runs.csv: runs.csv keeps 10 significant digits (``%.10g``).
SUMMARY_RTOL = 1e-8

KEY_COLS = ("case", "algorithm", "variable", "joint", "run", "iteration", "task_seed", "pose", "step",
            "trajectory", "metric", "algorithm_a", "algorithm_b", "solution", "problem", "set", "solver", "scope")
#: runs.csv columns holding path counts, compared as distributions.
COUNT_COLS = ("evaluations", "iterations_done", "iterations_to_best", "iterations_to_threshold",
              "evaluations_to_threshold")
#: Outcome columns of a path-dependent row (statistics of runs, single-run values): compared through
#: the runs they follow from, never cell by cell (names and prefixes).
OUTCOME_PREFIXES = ("x_", "start_", "pose_", "abs_error", "final_", "median", "mean", "std", "best", "worst",
                    "max_abs_error", "success", "q25", "q75", "min", "max", "position_error", "n_a", "n_b",
                    "U", "p_value", "p_holm", "significant", "better", "prob_a_lower", "evaluations", "solved",
                    "fraction", "pairs", "iterations_done", "iterations_to", "hits", "residual", "starts",
                    "outside_bounds", "solutions_found", "fitness", "evals_to", "score", "ci_", "rank", "ert",
                    "auc", "time", "wall", "ms_", "solves")
def path_rows() -> tuple[str, ...]:
    """Files whose rows exist per path step (a rerun may have more or fewer for a path-dependent
    run): the registered kinds' outputs with ``rows=STEPS``."""
    return files_with_rows(STEPS)


def run_files() -> tuple[str, ...]:
    """Files of single runs or solutions, whose path-dependent outcomes :func:`compare_runs`
    compares: the registered kinds' outputs with ``rows=RUNS``."""
    return files_with_rows(RUNS)


def timing_files() -> tuple[str, ...]:
    """Never deterministic: wall-clock measurements (every registered kind's ``TIMING`` outputs)
    and the environment."""
    return files_with(TIMING) + (ENV_FILE,)


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


@dataclass(frozen=True)
class Rules:
    """How one experiment compares: the tier, which rows are path-dependent, the reach level."""
    tier: str = EXACT
    #: algorithm label -> True when its rows are path-dependent in the "blas" tier
    path_dependent: Callable[[str], bool] = lambda label: True
    reach: float = REACHED
    #: Solutions are isolated points (forward kinematics of a parallel mechanism: finitely many
    #: assembly modes), so they compare as sets; a redundant arm's IK solutions form a manifold.
    isolated_solutions: bool = True

    def dependent(self, label) -> bool:
        return self.tier == ANY or bool(self.path_dependent(str(label)))


def _py(v):
    return v.item() if hasattr(v, "item") else v


def _read(path: Path) -> pd.DataFrame:
    """A CSV (or gzip'ed CSV) as text cells, so 'identical' means identical as written."""
    return parse_csv(_bytes(path), str(path), dtype=str, keep_default_na=False)


def _stored_csv(folder: Path, name: str) -> pd.DataFrame:
    return read_stored_csv(folder, name)


def _outcome(col: str) -> bool:
    return col.startswith(OUTCOME_PREFIXES)


def _row_label(row: pd.Series, keys: list[str], i: int) -> str:
    return " / ".join(str(row[k]) for k in keys) or str(i)


def _dependent_mask(df: pd.DataFrame, rules: Rules) -> np.ndarray:
    if rules.tier == ANY:
        return np.ones(len(df), dtype=bool)
    cols = [c for c in ("algorithm", "solver", "algorithm_a", "algorithm_b") if c in df.columns]
    if not cols:                       # a file with no algorithm column: dependent if any algorithm is
        return np.full(len(df), bool(rules.path_dependent("")))
    out = np.zeros(len(df), dtype=bool)
    for c in cols:
        out |= df[c].map(lambda a: rules.dependent(a)).to_numpy(dtype=bool)
    return out


def compare_tables(name: str, file: str, stored: pd.DataFrame, rerun: pd.DataFrame,
                   rules: Rules) -> list[Mismatch]:
    """Cross-platform comparison of one table's cells (text tables): rows no BLAS call touched
    identically; path-dependent rows by keys and settings only (their outcomes: :func:`compare_runs`)."""
    if list(stored.columns) != list(rerun.columns):
        return [Mismatch(name, file, "-", "columns", list(stored.columns), list(rerun.columns), "same columns")]
    keys = [k for k in KEY_COLS if k in stored.columns]
    ds, dr = _dependent_mask(stored, rules), _dependent_mask(rerun, rules)
    out: list[Mismatch] = []
    for part, (s, r) in (("exact", (stored[~ds], rerun[~dr])), ("dependent", (stored[ds], rerun[dr]))):
        if part == "dependent" and file in path_rows():
            continue                    # rows per path step: the runs' counts are compared instead
        if len(s) != len(r):
            rule = ("same rows (BLAS-free rows are identical on every platform)" if part == "exact"
                    else "same rows")
            out.append(Mismatch(name, file, part + " rows", "rows", len(s), len(r), rule))
            continue
        if part == "exact":
            cols = list(s.columns)
        elif file in run_files():        # their outcomes are compared by compare_runs
            cols = keys
        else:
            cols = [c for c in s.columns if c in keys or not _outcome(c)]
        rule = ("identical: no BLAS call on this row's path" if part == "exact"
                else "identical: keys and settings do not depend on the platform")
        for i, ((_, a), (_, b)) in enumerate(zip(s.iterrows(), r.iterrows())):
            for col in cols:
                if a[col] != b[col]:
                    out.append(Mismatch(name, file, _row_label(a, keys, i), col, a[col], b[col], rule))
                    break
            if len(out) > 20:
                return out
    return out


# -- distributions of path-dependent runs --------------------------------------------------------
def _numbers(series: pd.Series) -> np.ndarray:
    return csv_numbers(series)           # never raises (a 400-digit integer is inf)


def _rank_test(a: np.ndarray, b: np.ndarray) -> float:
    """Two-sided Mann-Whitney p-value (1 for identical samples or when either is empty)."""
    a, b = a[~np.isnan(a)], b[~np.isnan(b)]
    if len(a) == 0 or len(b) == 0 or (len(a) == len(b) and np.array_equal(np.sort(a), np.sort(b))):
        return 1.0
    if np.all(a == a[0]) and np.all(b == a[0]):
        return 1.0
    from scipy.stats import mannwhitneyu
    return float(mannwhitneyu(a, b, alternative="two-sided").pvalue)


def _fisher(k1: int, n1: int, k2: int, n2: int) -> float:
    if k1 * n2 == k2 * n1:
        return 1.0
    from scipy.stats import fisher_exact
    return float(fisher_exact([[k1, n1 - k1], [k2, n2 - k2]]).pvalue)


def holm(pvalues: list[float]) -> list[float]:
    """Holm-Bonferroni adjusted p-values (monotone, capped at 1)."""
    m = len(pvalues)
    order = np.argsort(pvalues)
    adjusted = np.empty(m)
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * pvalues[i]))
        adjusted[i] = running
    return adjusted.tolist()


def _clusters(points: np.ndarray) -> list[np.ndarray]:
    """Distinct points: greedy clusters within SOLUTION_RTOL x max(1, |value|) per variable."""
    reps: list[np.ndarray] = []
    for p in points:
        if not any(_same(p, q) for q in reps):
            reps.append(p)
    return reps


def _same(p: np.ndarray, q: np.ndarray) -> bool:
    return bool(np.all(np.abs(p - q) <= SOLUTION_RTOL * np.maximum(1.0, np.maximum(np.abs(p), np.abs(q)))))


def _solution_sets(label: str, file: str, group: str, s: np.ndarray, r: np.ndarray) -> list[Mismatch]:
    a, b = _clusters(s), _clusters(r)
    only_a = [p for p in a if not any(_same(p, q) for q in b)]
    only_b = [q for q in b if not any(_same(q, p) for p in a)]
    if not only_a and not only_b:
        return []
    fmt = (lambda ps: "; ".join("(" + ", ".join(f"{v:.6g}" for v in p) + ")" for p in ps[:2])
           + (" ..." if len(ps) > 2 else ""))
    return [Mismatch(label, file, group, "solutions", f"{len(a)} distinct, only here: {fmt(only_a)}",
                     f"{len(b)} distinct, only here: {fmt(only_b)}",
                     f"same set of solutions within {SOLUTION_RTOL:g} x max(1, |value|)")]


def compare_runs(name: str, file: str, stored: pd.DataFrame, rerun: pd.DataFrame, rules: Rules) -> list[Mismatch]:
    """Outcomes of path-dependent runs (``runs.csv`` of an experiment or study, or an assembly's
    ``solutions.csv``): distributions per algorithm, reached counts, solution sets (module docstring)."""
    tests: list[tuple[str, str, float, object, object, str]] = []
    out: list[Mismatch] = []
    algo_col = next((c for c in ("algorithm", "solver") if c in stored.columns), None)
    fit_col = next((c for c in ("final_fitness", "fitness") if c in stored.columns), None)
    if algo_col is None or fit_col is None:         # solutions.csv: one path-dependent search
        xs = [c for c in ("x", "y", "z", "alpha", "beta", "gamma") if c in stored.columns]
        if xs and rules.dependent(""):
            out += _solution_sets(name, file, "all", stored[xs].apply(pd.to_numeric).to_numpy(float),
                                  rerun[xs].apply(pd.to_numeric).to_numpy(float))
            if "hits" in stored.columns:
                a, b = _numbers(stored["hits"]), _numbers(rerun["hits"])
                tests.append(("all", "hits", _rank_test(a, b), np.median(a), np.median(b), "rank test"))
        return out + _judge(name, file, tests)
    group_of = "pose" if "pose" in stored.columns and "case" not in stored.columns else "case"
    for algo in sorted(set(stored[algo_col]) | set(rerun[algo_col])):
        if not rules.dependent(algo):
            continue
        s, r = stored[stored[algo_col] == algo], rerun[rerun[algo_col] == algo]
        if len(s) != len(r):
            out.append(Mismatch(name, file, algo, "runs", len(s), len(r), "same runs"))
            continue
        fs, fr = _numbers(s[fit_col]), _numbers(r[fit_col])
        ks, kr = int(np.sum(fs <= rules.reach)), int(np.sum(fr <= rules.reach))
        tests.append((algo, f"{fit_col} reached", _fisher(ks, len(fs), kr, len(fr)),
                      f"{ks}/{len(fs)} reached", f"{kr}/{len(fr)} reached", "Fisher's exact test"))
        tests.append((algo, fit_col, _rank_test(np.maximum(fs, rules.reach), np.maximum(fr, rules.reach)),
                      float(np.median(fs)), float(np.median(fr)),
                      f"rank test, values <= {rules.reach:g} reached (tied)"))
        for col in [*COUNT_COLS, *(c for c in s.columns if c.startswith("evals_to_"))]:
            if col in s.columns:
                a, b = _numbers(s[col]), _numbers(r[col])
                tests.append((algo, col, _rank_test(a, b), float(np.nanmedian(a)) if np.any(~np.isnan(a)) else None,
                              float(np.nanmedian(b)) if np.any(~np.isnan(b)) else None, "rank test"))
        xs = [c for c in s.columns if c.startswith("x_")]
        if xs and group_of in s.columns and rules.isolated_solutions:
            for g in sorted(set(s[group_of])):
                a = s[(s[group_of] == g) & (fs <= SOLUTION_FITNESS)]
                b = r[(r[group_of] == g) & (fr <= SOLUTION_FITNESS)]
                out += _solution_sets(name, file, f"{g} / {algo}", a[xs].apply(pd.to_numeric).to_numpy(float),
                                      b[xs].apply(pd.to_numeric).to_numpy(float))
    return out + _judge(name, file, tests)


def _judge(name: str, file: str, tests) -> list[Mismatch]:
    if not tests:
        return []
    adjusted = holm([t[2] for t in tests])
    rule = f"same distribution: %s, Holm-corrected over {len(tests)} tests, family-wise alpha {ALPHA}"
    return [Mismatch(name, file, algo, col, _py(a), _py(b), (rule % kind) + f"; p = {p:.2g}")
            for (algo, col, _, a, b, kind), p in zip(tests, adjusted) if p < ALPHA]


# -- on every platform: the stored summary is the stored runs' ------------------------------------
def summary_consistency(name: str, folder: Path) -> list[Mismatch]:
    """``summary.csv``'s statistics recomputed from the stored ``runs.csv`` (module docstring)."""
    folder = Path(folder)
    if not (folder / "summary.csv").is_file() or not (folder / "runs.csv").is_file():
        return []
    try:
        summary, runs = _stored_csv(folder, "summary.csv"), _stored_csv(folder, "runs.csv")
    except (OSError, ValueError, pd.errors.ParserError, UnicodeDecodeError, FkoptError) as err:
        return [Mismatch(name, "summary.csv", "-", "file", f"unreadable ({err})", "readable", "readable CSV")]
    if "final_fitness" not in runs.columns or "algorithm" not in runs.columns:
        return [Mismatch(name, "runs.csv", "-", "columns", list(runs.columns), "final_fitness, algorithm",
                         "runs.csv has the run columns")]
    by_case = "case" in runs.columns
    out: list[Mismatch] = []
    for _, row in summary.iterrows():
        sel = runs["algorithm"].astype(str) == str(row["algorithm"])
        if by_case:
            sel &= runs["case"].astype(str) == str(row["case"])
        g = runs[sel]
        label = f"{row.get('case')} / {row['algorithm']}"
        if g.empty:
            out.append(Mismatch(name, "summary.csv", label, "runs", "a summary row", "no runs in runs.csv",
                                "every summary row has its runs"))
            continue
        f = g["final_fitness"].to_numpy(float)
        scale = float(np.max(np.abs(f))) if len(f) else 0.0
        expect = {"mean_fitness": np.mean(f), "std_fitness": np.std(f, ddof=1) if len(f) > 1 else 0.0,
                  "best_fitness": np.min(f), "worst_fitness": np.max(f), "median_fitness": np.median(f)}
        if "evaluations" in g.columns:
            expect["mean_evaluations"] = float(np.mean(g["evaluations"].to_numpy(float)))
        if "iterations_to_threshold" in g.columns and "success_rate" in summary.columns:
            it = g["iterations_to_threshold"].to_numpy(float)
            expect["success_rate"] = float(np.mean(~np.isnan(it)))
            for col, src in (("median_iterations_to_threshold", "iterations_to_threshold"),
                             ("median_evaluations_to_threshold", "evaluations_to_threshold")):
                v = g[src].to_numpy(float)
                expect[col] = float(np.median(v[~np.isnan(v)])) if np.any(~np.isnan(v)) else math.nan
        for col, want in expect.items():
            if col not in summary.columns:
                continue
            have = float(row[col])
            tol = SUMMARY_RTOL * max(abs(want), scale if col.endswith("fitness") else 0.0) + 1e-300
            if (math.isnan(have) != math.isnan(want)) or (not math.isnan(want) and abs(have - want) > tol):
                out.append(Mismatch(name, "summary.csv", label, col, have, _py(want),
                                    "the statistic of the stored runs.csv (on every platform)"))
    return out


# -- folders ---------------------------------------------------------------------------------------
def first_difference(name: str, file: str, stored: bytes, rerun: bytes) -> Mismatch:
    """Name the first differing line of two byte strings (exact mode)."""
    a, b = stored.decode("utf-8", "replace").splitlines(), rerun.decode("utf-8", "replace").splitlines()
    header = a[0].split(",") if a and ".csv" in file else []
    for i, (x, y) in enumerate(zip(a, b)):
        if x != y:
            col = "-"
            xs, ys = x.split(","), y.split(",")
            for j, (u, v) in enumerate(zip(xs, ys)):
                if u != v:
                    col = header[j] if j < len(header) else str(j)
                    x, y = u, v
                    break
            return Mismatch(name, file, f"line {i + 1}", col, x, y, "byte-identical (same platform fingerprint)")
    return Mismatch(name, file, f"line {min(len(a), len(b)) + 1}", "-", f"{len(a)} lines", f"{len(b)} lines",
                    "byte-identical (same platform fingerprint)")


def _bytes(path: Path) -> bytes:
    """The (unpacked) bytes of a result file, bounded: inside its folder, a regular file, a gzip
    bomb one line, not the memory (:func:`fkopt.files.read_stored`)."""
    return read_stored(path.parent, path.name)


def compare_folders(name: str, stored: Path, rerun: Path, rules: Rules | bool,
                    files: list[str] | None = None) -> list[Mismatch]:
    """Compare the deterministic files of two result folders by ``rules`` (a :class:`Rules`, or
    True/False for the exact / the any-platform rules)."""
    if isinstance(rules, bool):
        rules = Rules(EXACT if rules else ANY)
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
        if rules.tier == EXACT:
            a, b = _bytes(s), _bytes(r)
            # meta.json: byte-identical but for the machine's load during the run (META_RUN)
            if a != b and not (file == "meta.json" and not compare_meta(name, s, r, variable=META_RUN)):
                out.append(first_difference(name, file, a, b))
        elif file == "meta.json":
            out += compare_meta(name, s, r)
        elif ".csv" in file:
            try:
                table = _read(s)
            except (OSError, ValueError, pd.errors.ParserError, UnicodeDecodeError, EOFError, FkoptError) as err:
                out.append(Mismatch(name, file, "-", "file", f"unreadable ({err})", "readable", "readable"))
                continue
            other = _read(r)
            out += compare_tables(name, file, table, other, rules)
            if file in run_files():
                out += compare_runs(name, file, table, other, rules)
    return out


#: meta.json keys that depend on the machine's state during the run (a per-robot board's load
#: averages at its start and end, issue 37): never compared.
META_RUN = ("load_avg",)
#: meta.json keys that depend on the platform (digests of the files) or the invocation.
META_VARIABLE = ("files", "config_file") + META_RUN


def compare_meta(name: str, stored: Path, rerun: Path, variable: tuple[str, ...] = META_VARIABLE) -> list[Mismatch]:
    """meta.json on another platform: everything but the file digests (``variable``) must be equal."""
    import json
    try:
        a = json.loads(_bytes(Path(stored)).decode("utf-8"))
    except (OSError, ValueError, FkoptError) as err:
        return [Mismatch(name, "meta.json", "-", "file", f"unreadable ({err})", "readable", "valid JSON")]
    b = json.loads(_bytes(Path(rerun)).decode("utf-8"))
    out = []
    for key in sorted(set(a) | set(b)):
        if key not in variable and a.get(key) != b.get(key):
            out.append(Mismatch(name, "meta.json", "-", key, a.get(key), b.get(key), "identical"))
    return out
