"""Every file a results folder can hold, in one table, and the one writer that writes them.

:data:`OUTPUTS` lists, per config kind (``experiment``, ``study``, ``assembly``; see
:mod:`fkopt.experiment.kinds`), each file of its folder: its name, the function that makes it
(a ``"module:function"`` string, imported on first use like :mod:`fkopt.registry`'s entries, so
this floor imports no report module) and its *role*, which is all :mod:`fkopt.compare` and
``fkopt check`` need to know about it:

=========  ===================================================================================
role       meaning
=========  ===================================================================================
table      deterministic statistics: byte-identical on the same platform fingerprint, compared
           by the cross-platform rules of :mod:`fkopt.compare` on another
curves     deterministic single runs or curves: compared like tables (on another platform their
           BLAS-free rows cell by cell, their path-dependent rows through the runs they follow from)
timing     wall-clock measurements: never compared, skipped when ``fkopt check`` reruns
figure     a figure (PNG + PDF twin); never compared
=========  ===================================================================================

A table or curves file also says what one of its rows is (``rows``), which is how ``fkopt
check`` compares a path-dependent row on another platform:

=========  ===================================================================================
rows       meaning
=========  ===================================================================================
stats      statistics over runs (the default): keys and settings cell by cell, outcomes through
           the runs they follow from
runs       one row per run or solution: its outcomes compared run by run
           (:func:`fkopt.compare.compare_runs`)
steps      one row per step of a run's path (a rerun may have more or fewer): compared through
           the runs' counts, never row by row
=========  ===================================================================================

A table maker is ``make(result) -> DataFrame | None`` (None: the file does not apply to this
result, e.g. ``inputs.csv`` when no case gives both joints and a pose); a ``.csv.gz`` is gzip'ed
with a fixed timestamp, so the same numbers give the same bytes. A figure maker is
``make(result, folder, tables) -> list[str]`` (the names it wrote, ``[]`` when it does not
apply), where ``tables`` maps the file names written so far to their tables. Every folder ends
with ``meta.json`` (the kind's :data:`META` maker, plus the SHA-256 of every deterministic file)
and ``env.json`` (:func:`fkopt.provenance.environment`).

Adding an output is one maker function in the kind's report module plus one line here.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

TABLE, CURVES, TIMING, FIGURE = "table", "curves", "timing", "figure"
STATS, RUNS, STEPS = "stats", "runs", "steps"
FLOAT = "%.10g"
META_FILE = "meta.json"
ENV_FILE = "env.json"


@dataclass(frozen=True)
class Output:
    file: str                 # name in the folder; a figure's entry names what it draws
    make: str                 # "module:function"
    role: str                 # TABLE, CURVES, TIMING or FIGURE
    float_format: str = FLOAT
    rows: str = STATS         # STATS, RUNS or STEPS: what one row is


_EXP = "fkopt.experiment.reports"
_STUDY = "fkopt.study.reports"
_ASM = "fkopt.experiment.assembly"
_SUITE = "fkopt.kinbench.reports"

#: kind -> its files, in the order they are written (tables before the figures drawn from them).
OUTPUTS: dict[str, tuple[Output, ...]] = {
    "experiment": (
        Output("summary.csv", f"{_EXP}:summary_table", TABLE),
        Output("timing.csv", f"{_EXP}:timing_table", TIMING),
        Output("timing_runs.csv", f"{_EXP}:timing_runs_table", TIMING),
        Output("values.csv", f"{_EXP}:values_table", TABLE),
        Output("inputs.csv", f"{_EXP}:inputs_table", TABLE),
        Output("runs.csv", f"{_EXP}:runs_table", CURVES, rows=RUNS),
        Output("trace.csv.gz", "fkopt.experiment.traces:trace_table", CURVES, rows=STEPS),
        Output("convergence.csv", f"{_EXP}:convergence_table", CURVES, rows=STEPS),
        Output("convergence", f"{_EXP}:convergence_figure", FIGURE),
        Output("variables", f"{_EXP}:variables_figure", FIGURE),
        Output("snapshots", f"{_EXP}:snapshot_figures", FIGURE),
        Output("extras", f"{_EXP}:extras_figure", FIGURE),
        Output("cases", f"{_EXP}:cases_figures", FIGURE),
        Output("time", f"{_EXP}:time_figure", FIGURE),
        Output("position_error", f"{_EXP}:position_error_figure", FIGURE),
    ),
    "study": (
        Output("summary.csv", f"{_STUDY}:summary_table", TABLE),
        Output("timing.csv", f"{_STUDY}:timing_table", TIMING),
        Output("poses.csv", f"{_STUDY}:poses_table", CURVES),
        Output("runs.csv", f"{_STUDY}:runs_table", CURVES, rows=RUNS),
        Output("ecdf.csv", f"{_STUDY}:ecdf_of", CURVES, rows=STEPS),
        Output("stats.csv", f"{_STUDY}:stats_of", CURVES),
        Output("heatmap.csv", f"{_STUDY}:heatmap_table", CURVES),
        Output("tracking.csv", f"{_STUDY}:tracking_table", CURVES),
        Output("tracking_timing.csv", f"{_STUDY}:tracking_timing_table", TIMING),
        Output("ecdf", f"{_STUDY}:ecdf_figure", FIGURE),
        Output("heatmap", f"{_STUDY}:heatmap_figure", FIGURE),
        Output("tracking", f"{_STUDY}:tracking_figure", FIGURE),
        Output("tracking_time", f"{_STUDY}:tracking_time_figure", FIGURE),
    ),
    "assembly": (
        Output("summary.csv", f"{_ASM}:summary_table", TABLE),
        Output("solutions.csv", f"{_ASM}:solutions_table", CURVES, float_format="%.12g", rows=RUNS),
        Output("timing.csv", f"{_ASM}:timing_table", TIMING),
    ),
    "suite": (
        Output("leaderboard.csv", f"{_SUITE}:leaderboard_table", TABLE),
        Output("measures.csv", f"{_SUITE}:measures_table", TABLE),
        Output("scaling.csv", f"{_SUITE}:scaling_table", TABLE),      # classes of several dimensions only
        Output("ert_ratio.csv", f"{_SUITE}:ert_ratio_table", TABLE),  # suites with subsets (v3) only
        Output("ecdf.csv", f"{_SUITE}:ecdf_table", CURVES, rows=STEPS),
        Output("runs.csv", f"{_SUITE}:runs_table", CURVES, rows=RUNS),
        Output("trace.csv.gz", "fkopt.kinbench.traces:trace_table", CURVES, rows=STEPS),
        Output("timing.csv", f"{_SUITE}:timing_table", TIMING),
        # kinbench v3's tracks on the clock: wall times (and TRAC-IK's wall-clock outcomes) vary
        Output("answers.csv.gz", f"{_SUITE}:answers_table", TIMING, float_format="%.17g"),
        Output("throughput.csv", f"{_SUITE}:throughput_table", TIMING),
        Output("leaderboard-robots.csv", f"{_SUITE}:robots_board_table", TIMING),
        Output("ecdf", f"{_SUITE}:ecdf_figures", FIGURE),
        Output("scaling", f"{_SUITE}:scaling_figures", FIGURE),
        Output("clock", f"{_SUITE}:clock_figures", FIGURE),
        Output("leaderboard.md", f"{_SUITE}:leaderboard_markdown", FIGURE),   # never compared
        Output("index.html", f"{_SUITE}:html_page", FIGURE),                  # inlines the figures
    ),
}
#: kind -> "module:function" making the content of meta.json (without the file digests).
META: dict[str, str] = {
    "experiment": f"{_EXP}:meta",
    "study": f"{_STUDY}:meta",
    "assembly": f"{_ASM}:meta",
    "suite": f"{_SUITE}:meta",
}


def files_with(role: str) -> tuple[str, ...]:
    """Names of the files of any kind that have ``role`` (sorted, each once)."""
    return tuple(sorted({o.file for outs in OUTPUTS.values() for o in outs if o.role == role}))


def files_with_rows(rows: str) -> tuple[str, ...]:
    """Names of the table/curves files of any kind whose rows are ``rows`` (sorted, each once)."""
    return tuple(sorted({o.file for outs in OUTPUTS.values() for o in outs
                         if o.role in (TABLE, CURVES) and o.rows == rows}))


def deterministic_files(folder: Path) -> list[str]:
    """Names of the files ``fkopt check`` compares: CSVs (and gzip'ed CSVs: trace.csv.gz) and
    meta.json, not timing files. A gzip'ed CSV is compared byte for byte on the same platform and
    only through its recorded digest on another."""
    timing = set(files_with(TIMING)) | {ENV_FILE}
    return sorted(p.name for p in Path(folder).iterdir()
                  if p.is_file() and (p.name.endswith((".csv", ".csv.gz")) or p.name == META_FILE)
                  and p.name not in timing)


def sha256(path: Path) -> str:
    """SHA-256 of a results file, read bounded (:func:`fkopt.files.stored_sha256`)."""
    from .files import stored_sha256
    return stored_sha256(path)


def file_digests(folder: Path) -> dict[str, str]:
    """SHA-256 of every deterministic CSV of a folder (recorded in its meta.json as ``files``)."""
    return {name: sha256(Path(folder) / name) for name in deterministic_files(folder) if name != META_FILE}


def _load(ref: str) -> Callable:
    module, attr = ref.split(":")
    return getattr(importlib.import_module(module), attr)


def write_outputs(kind: str, result: Any, folder: str | Path, *, figures: bool = True,
                  timing: bool = True) -> list[str]:
    """Write every file of ``kind`` for ``result`` into ``folder`` (which must exist); returns
    the names written. ``figures=False`` / ``timing=False`` leave out the figures / the timing
    files (what ``fkopt check`` reruns for: only deterministic files are compared)."""
    from .files import naming_the_file, write_json
    from .provenance import environment

    folder = Path(folder)
    written: list[str] = []
    tables: dict[str, Any] = {}
    for out in OUTPUTS[kind]:
        if (out.role == FIGURE and not figures) or (out.role == TIMING and not timing):
            continue
        make = _load(out.make)
        with naming_the_file(folder / out.file):
            if out.role == FIGURE:
                written += make(result, folder, tables)
                continue
            df = make(result)
            if df is None:
                continue
            gz = {"compression": {"method": "gzip", "mtime": 0}} if out.file.endswith(".gz") else {}
            df.to_csv(folder / out.file, index=False, float_format=out.float_format, **gz)
        tables[out.file] = df
        written.append(out.file)
    with naming_the_file(folder / META_FILE):
        write_json(folder / META_FILE, {**_load(META[kind])(result), "files": file_digests(folder)})
    with naming_the_file(folder / ENV_FILE):
        write_json(folder / ENV_FILE, environment())
    return written + [META_FILE, ENV_FILE]


def write_result(kind: str, result: Any, out: str | Path, check=None) -> Path:
    """Write ``result``'s folder ``OUT/<paper>/<name>/`` aside and swap it into place
    (:func:`fkopt.files.write_atomically`: a failed or interrupted write never leaves a
    half-written folder and never loses the previous one)."""
    from .files import output_folder, write_atomically
    folder = output_folder(out, *result.config.folder_parts)
    return write_atomically(folder, lambda tmp: write_outputs(kind, result, tmp), check)
