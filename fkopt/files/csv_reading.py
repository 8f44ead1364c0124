"""CSV files fkopt did not write in this run, parsed with memory bounded whatever the bytes:
:func:`check_csv_shape` before pandas sees them, :func:`parse_csv` the one way such a CSV is
parsed, :func:`read_csv` / :func:`read_stored_csv` on top of the bounded reader.

pandas is imported inside :func:`parse_csv` and :func:`csv_numbers`: the command line imports this package at start-up
and ``fkopt ik`` / ``fkopt --help`` never read a CSV (docs/design.md, "Start-up")."""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from fkopt.errors import FkoptError
from fkopt.files.reading import MAX_INPUT_BYTES, read_input, read_stored, where_named
from fkopt.files.text import one_line

#: Most columns of a CSV fkopt reads (the header's fields and any row's): pandas spends ~4.5 kB per
#: header column before it reads a row, so a 256 KiB line of commas took ~1.3 GB (issue 42). fkopt's
#: widest CSV has 36 columns.
MAX_CSV_COLUMNS = 1024
#: Longest line of a CSV fkopt reads (bytes); fkopt's longest is 590 bytes.
MAX_CSV_LINE = 64 * 1024
#: Most cells (fields over all rows) of a CSV fkopt reads: bounds pandas' memory (8 bytes per
#: number, one object per distinct text cell) whatever the bytes; kinbench v3's trace, the
#: largest fkopt writes, holds 8.7 million.
MAX_CSV_CELLS = 24_000_000


def check_csv_shape(data: bytes, where: str) -> None:
    """Refuse, with one line naming ``where``, CSV bytes whose parsing would take memory out of
    proportion to their size, before pandas sees them: a line longer than :data:`MAX_CSV_LINE`
    bytes, a line (the header or a row: pandas turns a row wider than the header into index
    levels, 4.6 GB for 2,000 rows of 65,000 commas) of more than :data:`MAX_CSV_COLUMNS` fields,
    a quoted field spanning lines (a row of many lines would escape both bounds), more than
    :data:`MAX_CSV_CELLS` cells. Scanned with numpy in blocks of whole lines (a few bytes of
    scratch per byte of a block, never of the whole file)."""
    arr = np.frombuffer(data, dtype=np.uint8)
    size = len(arr)
    start, line_no, cells = 0, 1, 0      # first byte of the block (a line start), its line number
    block = 1 << 23
    while start < size:
        stop = min(size, start + block)
        if stop < size:                  # end the block after a newline (a line is at most MAX_CSV_LINE)
            cut = np.flatnonzero(arr[stop: min(size, stop + MAX_CSV_LINE + 1)] == 10)
            if not len(cut):
                raise FkoptError(f"{where}: line near {line_no}: longer than {MAX_CSV_LINE} bytes, the longest "
                                 "accepted in a CSV; refused (memory stays bounded)")
            stop += int(cut[0]) + 1
        chunk = arr[start:stop]
        ends = np.flatnonzero(chunk == 10)
        if not len(ends) or ends[-1] != len(chunk) - 1:
            ends = np.append(ends, len(chunk))          # the last line has no newline
        starts = np.concatenate(([0], ends[:-1] + 1))
        lengths = ends - starts
        too_long = np.flatnonzero(lengths > MAX_CSV_LINE)
        if len(too_long):
            raise FkoptError(f"{where}: line {line_no + int(too_long[0])}: {int(lengths[too_long[0]])} bytes, longer "
                             f"than the {MAX_CSV_LINE} accepted in a CSV; refused (memory stays bounded)")
        # only a line of at least MAX_CSV_COLUMNS - 1 bytes can hold that many commas: count those alone
        for k in np.flatnonzero(lengths >= MAX_CSV_COLUMNS - 1):
            fields = int(np.count_nonzero(chunk[starts[k]:ends[k]] == 44)) + 1
            if fields > MAX_CSV_COLUMNS:
                what = "header" if line_no + k == 1 else f"line {line_no + int(k)}"
                raise FkoptError(f"{where}: {what}: {fields} fields, more than the {MAX_CSV_COLUMNS} columns "
                                 "accepted in a CSV; refused (memory stays bounded)")
        quotes = np.flatnonzero(chunk == 34)
        if len(quotes):                                 # none may leave a field open across lines
            per_line = np.bincount(np.searchsorted(ends, quotes), minlength=len(ends))
            odd = np.flatnonzero(per_line % 2)
            if len(odd):
                raise FkoptError(f"{where}: unreadable CSV (line {line_no + int(odd[0])}: a quoted field spans "
                                 "lines, which fkopt does not accept)")
        cells += int(np.count_nonzero(chunk == 44)) + int(np.count_nonzero(lengths))
        if cells > MAX_CSV_CELLS:
            raise FkoptError(f"{where}: more than {MAX_CSV_CELLS} cells, the most accepted in a CSV; refused "
                             "(memory stays bounded)")
        line_no += len(ends)
        start = stop


def parse_csv(data: bytes, where: str, **options):
    """A pandas DataFrame of the CSV bytes of a file fkopt did not write in this run (``where``
    names it), after :func:`check_csv_shape`: the one way fkopt parses such a CSV. Empty or
    malformed CSV is one line naming ``where``; ``options`` go to ``pandas.read_csv``."""
    import pandas as pd
    check_csv_shape(data, where)
    try:
        return pd.read_csv(io.BytesIO(data), **options)
    except pd.errors.EmptyDataError:
        raise FkoptError(f"{where}: unreadable CSV (empty: no header)") from None
    except (ValueError, OverflowError, pd.errors.ParserError, UnicodeDecodeError) as err:
        raise FkoptError(f"{where}: unreadable CSV ({type(err).__name__}: {one_line(str(err), 120)})") from None


def read_csv(path: str | Path, max_bytes: int = MAX_INPUT_BYTES, *, field: str | None = None,
             within: str | Path | None = None, unpacked: int | None = None, **options):
    """A CSV (``.csv`` or ``.csv.gz``) fkopt did not write in this run, bounded in bytes
    (:func:`read_input`) and in memory (:func:`parse_csv`); every refusal one line naming it."""
    data = read_input(path, max_bytes, field=field, within=within, unpacked=unpacked)
    return parse_csv(data, where_named(Path(path), field), **options)


def read_stored_csv(folder: str | Path, name: str | Path, **options):
    """A CSV of a stored result (``folder/name``) read back: :func:`read_stored`'s bounds, then
    :func:`parse_csv`'s."""
    return parse_csv(read_stored(folder, name), str(Path(folder) / name), **options)



def csv_numbers(column) -> np.ndarray:
    """A CSV column as float64, never raising: text and empty cells become NaN, an integer too
    long for a double (400 digits) +-inf -- so the caller's range check refuses it with one line
    (``pd.to_numeric`` raises OverflowError on such an integer once pandas made it a Python int)."""
    import pandas as pd
    s = column if isinstance(column, pd.Series) else pd.Series(column)
    if s.dtype == object:
        s = s.map(lambda v: v if isinstance(v, str) or v is None or isinstance(v, float) else str(v))
    try:
        return pd.to_numeric(s, errors="coerce").to_numpy(dtype=float)
    except (OverflowError, TypeError, ValueError):
        return np.array([_to_float(v) for v in s], dtype=float)


def _to_float(value) -> float:
    try:
        return float(value)
    except OverflowError:
        return float("inf") if value > 0 else float("-inf")
    except (TypeError, ValueError):
        return float("nan")
