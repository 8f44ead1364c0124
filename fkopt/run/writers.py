"""Every file a results folder can hold, in one table, and the one writer that writes them.

Every kind (:class:`~fkopt.run.tasks.Kind`, registered in :data:`fkopt.run.kinds.KINDS`) lists each
file of its folder as an :class:`Output`: its name, the function object that makes it and its
*role*, which is all :mod:`fkopt.run.compare` and ``fkopt check`` need to know about it:

=========  ===================================================================================
role       meaning
=========  ===================================================================================
table      deterministic statistics: byte-identical on the same platform fingerprint, compared
           by the cross-platform rules of :mod:`fkopt.run.compare` on another
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
           (:func:`fkopt.run.compare.compare_runs`)
steps      one row per step of a run's path (a rerun may have more or fewer): compared through
           the runs' counts, never row by row
=========  ===================================================================================

A table maker is ``make(result) -> DataFrame | None`` (None: the file does not apply to this
result, e.g. ``inputs.csv`` when no case gives both joints and a pose); a ``.csv.gz`` is gzip'ed
with a fixed timestamp, so the same numbers give the same bytes. A figure maker is
``make(result, folder, tables) -> list[str]`` (the names it wrote, ``[]`` when it does not
apply), where ``tables`` maps the file names written so far to their tables. Every folder ends
with ``meta.json`` (the kind's ``meta`` maker, plus the SHA-256 of every deterministic file)
and ``env.json`` (:func:`fkopt.run.provenance.environment`).

Adding an output is one maker function in the kind's report module plus one :class:`Output` line
in its kind's list.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from fkopt.files import naming_the_file, output_folder, stored_sha256, write_atomically, write_json
from fkopt.run import record
from fkopt.run.kinds import KINDS, config_kind
from fkopt.run.provenance import environment

TABLE, CURVES, TIMING, FIGURE = "table", "curves", "timing", "figure"
STATS, RUNS, STEPS = "stats", "runs", "steps"
FLOAT = "%.10g"
META_FILE = "meta.json"
ENV_FILE = "env.json"


@dataclass(frozen=True)
class Output:
    file: str                 # name in the folder; a figure's entry names what it draws
    make: Callable            # the maker (a function object of the kind's report module)
    role: str                 # TABLE, CURVES, TIMING or FIGURE
    float_format: str = FLOAT
    rows: str = STATS         # STATS, RUNS or STEPS: what one row is


# -- the files every kind's result makes the same way (from RunResult's record, timing, trace) --------
def runs_file(result):
    """``runs.csv``: the run record, one row per run (:func:`fkopt.run.record.runs_table`)."""
    return None if result.record is None else record.runs_table(result.record)


def trace_file(result):
    """``trace.csv.gz``: each run's best-so-far where it improved (the result's trace)."""
    return result.trace


def timing_runs_file(result):
    """``timing_runs.csv``: every run timed alone (ms), what timing claims test for a difference
    (:func:`fkopt.run.record.timing_runs_table`); None when the result has no timing record."""
    if result.timing is None:
        return None
    return record.timing_runs_table(result.timing, names=config_kind(result.config).file_names)


#: The shared files, each made by one function for every kind whose result has what it reads;
#: a kind lists them among its outputs where they belong in its folder.
RUNS_FILE = Output("runs.csv", runs_file, CURVES, rows=RUNS)
TRACE_FILE = Output("trace.csv.gz", trace_file, CURVES, rows=STEPS)
TIMING_RUNS_FILE = Output("timing_runs.csv", timing_runs_file, TIMING)


def outputs_of(kind) -> tuple[Output, ...]:
    """The files of a kind (a :class:`~fkopt.run.tasks.Kind` or a registered kind's name)."""
    return (KINDS[kind] if isinstance(kind, str) else kind).outputs


def files_with(role: str) -> tuple[str, ...]:
    """Names of the files of any kind that have ``role`` (sorted, each once)."""
    return tuple(sorted({o.file for k in KINDS.values() for o in k.outputs if o.role == role}))


def files_with_rows(rows: str) -> tuple[str, ...]:
    """Names of the table/curves files of any kind whose rows are ``rows`` (sorted, each once)."""
    return tuple(sorted({o.file for k in KINDS.values() for o in k.outputs
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
    return stored_sha256(path)


def file_digests(folder: Path) -> dict[str, str]:
    """SHA-256 of every deterministic CSV of a folder (recorded in its meta.json as ``files``)."""
    return {name: sha256(Path(folder) / name) for name in deterministic_files(folder) if name != META_FILE}


def write_outputs(kind, result: Any, folder: str | Path, *, figures: bool = True,
                  timing: bool = True) -> list[str]:
    """Write every file of ``kind`` (a :class:`~fkopt.run.tasks.Kind` or a registered kind's name)
    for ``result`` into ``folder`` (which must exist); returns
    the names written. ``figures=False`` / ``timing=False`` leave out the figures / the timing
    files (what ``fkopt check`` reruns for: only deterministic files are compared)."""
    kind = KINDS[kind] if isinstance(kind, str) else kind
    folder = Path(folder)
    written: list[str] = []
    tables: dict[str, Any] = {}
    for out in kind.outputs:
        if (out.role == FIGURE and not figures) or (out.role == TIMING and not timing):
            continue
        make = out.make
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
        write_json(folder / META_FILE, {**kind.meta(result), "files": file_digests(folder)})
    with naming_the_file(folder / ENV_FILE):
        write_json(folder / ENV_FILE, environment())
    return written + [META_FILE, ENV_FILE]


def write_result(kind, result: Any, out: str | Path, check=None) -> Path:
    """Write ``result``'s folder ``OUT/<paper>/<name>/`` aside and swap it into place
    (:func:`fkopt.files.write_atomically`: a failed or interrupted write never leaves a
    half-written folder and never loses the previous one)."""
    folder = output_folder(out, *result.config.folder_parts)
    return write_atomically(folder, lambda tmp: write_outputs(kind, result, tmp), check)
