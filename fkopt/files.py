"""Shared file helpers (floor 0): safe YAML, safe output paths, write-aside-then-swap, error lines.

Every config file, geometry file and results folder of fkopt goes through this module, once:

* :func:`load_yaml` -- the one YAML reader. Refused with a one-line :class:`FkoptError`: files
  larger than :data:`MAX_YAML_BYTES`, bytes that are not UTF-8, YAML aliases (``*name``; anchors
  and aliases are refused altogether, so a tiny file cannot expand into gigabytes -- fkopt's
  configs never need them), duplicate keys (the error names the key and its line), nesting deeper
  than :data:`MAX_YAML_DEPTH`, NaN and infinite numbers (``.nan``, ``.inf``, ``1e400``: no
  field of any fkopt file takes them), and malformed YAML (line and column). Only plain data is built
  (``yaml.SafeLoader``): no tag ever runs code.
* :func:`check_component` -- ``paper`` and ``name`` are single safe path components:
  :data:`COMPONENT_PATTERN` (a letter or digit first, then letters, digits, ``_ . + -``, at most
  :data:`MAX_COMPONENT` characters), so never ``.``, ``..``, a separator or a hidden name.
* :func:`output_folder` -- resolves ``OUT/<paper>/<name>`` (symbolic links included) and refuses it
  unless it lies inside ``OUT``; checks that ``OUT`` is (or can be made) a writable folder, not a
  file, before any computation starts. Every command that writes (run, study, reproduce, assembly
  searches, bench, export) calls it first: ``output_folder(out)`` checks the folder itself,
  ``output_folder(out, "a", "b")`` a folder below it.
* :func:`inside` -- the one output-path guard: a file or folder fkopt writes, reads back to
  merge, or swaps is refused with one line unless it resolves (symbolic links included) inside
  the root it belongs to. Every writer calls it on every path, not only on the folder: a link
  planted inside ``--out`` (``.partial/tasks``, ``REPORT.md``, ``bench.csv``) cannot redirect
  a write outside.
* :func:`write_atomically` -- write a folder aside (a hidden temporary sibling), then swap it into
  place with one ``renameat2(RENAME_EXCHANGE)`` system call (two renames with signals blocked
  where that call does not exist). The previous result stays complete until the new one is.
* :func:`write_file_atomically` -- the same for one file (task files, JSON, CSV).
* :func:`read_input` -- the one bounded reader of every file fkopt did not write in this run
  (configs, URDF, pose sets, outside results, IOH data; :func:`read_stored` for stored results):
  regular files only, inside the folder they were named from, a size cap checked before
  reading, ``.gz`` streamed with a cap on the unpacked size; :func:`read_text`,
  :func:`parse_json` / :func:`read_json` (strict JSON) on top. :func:`odd_entries` lists what a
  results folder must not hold (links, FIFOs, devices).
* :func:`parse_xml` -- the one XML reader of robot files (URDF, MJCF): nesting bounded by
  :data:`MAX_XML_DEPTH` while parsing.
* :func:`file_names` -- collision-free file-name stems for user-given names.
* :func:`strict_json` and :func:`md_text` -- strict JSON output and Markdown-escaped text.
* :func:`error_line` -- one line from a pydantic ``ValidationError`` (field path and message).
* :func:`nanmedian` -- median over the non-NaN values (NaN if there are none).
"""
from __future__ import annotations

import contextlib
import ctypes
import errno
import io
import json
import os
import re
import shutil
import signal
import stat
import tempfile
from pathlib import Path
from typing import Any, Callable

import numpy as np

from fkopt.errors import FkoptError

#: Largest config or geometry file read (bytes).
MAX_YAML_BYTES = 1 << 20
#: Deepest nesting of YAML collections accepted.
MAX_YAML_DEPTH = 32
#: ``paper`` and ``name``: one path component, letter or digit first.
MAX_COMPONENT = 64
COMPONENT_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9_.+-]{0,63}$"
_COMPONENT = re.compile(COMPONENT_PATTERN)


# -- YAML ------------------------------------------------------------------------------------------
def _loader():
    import yaml

    class Loader(yaml.SafeLoader):
        """SafeLoader without aliases, without duplicate keys, with bounded depth."""

        depth = 0

        def compose_node(self, parent, index):
            if self.check_event(yaml.AliasEvent):
                event = self.peek_event()
                raise yaml.composer.ComposerError(None, None, "YAML anchors and aliases (&name, *name) "
                                                  "are not accepted in fkopt files; write the values out", event.start_mark)
            event = self.peek_event()
            if getattr(event, "anchor", None):
                raise yaml.composer.ComposerError(None, None, "YAML anchors and aliases (&name, *name) "
                                                  "are not accepted in fkopt files; write the values out", event.start_mark)
            self.depth += 1
            try:
                if self.depth > MAX_YAML_DEPTH:
                    raise yaml.composer.ComposerError(None, None, f"nested deeper than {MAX_YAML_DEPTH} "
                                                      "levels", event.start_mark)
                return super().compose_node(parent, index)
            finally:
                self.depth -= 1

        def construct_yaml_float(self, node):
            value = super().construct_yaml_float(node)
            if value != value or value in (float("inf"), float("-inf")):
                raise yaml.constructor.ConstructorError(None, None, f"'{node.value}' is not a finite "
                                                        "number (NaN and inf are not accepted)",
                                                        node.start_mark)
            return value

        def construct_mapping(self, node, deep=False):
            seen = {}
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=True)
                try:
                    hash(key)
                except TypeError:
                    raise yaml.constructor.ConstructorError(None, None, "a mapping key must be a plain "
                                                            "value", key_node.start_mark) from None
                if key in seen:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"duplicate key '{key}' (first at line {seen[key] + 1})",
                        key_node.start_mark)
                seen[key] = key_node.start_mark.line
            for key_node, value_node in node.value:      # a non-finite number names its field
                if value_node.tag == "tag:yaml.org,2002:float":
                    try:
                        self.construct_yaml_float(value_node)
                    except yaml.constructor.ConstructorError as err:
                        raise yaml.constructor.ConstructorError(
                            None, None, f"{self.construct_object(key_node, deep=True)}: {err.problem}",
                            value_node.start_mark) from None
            return super().construct_mapping(node, deep=deep)

    Loader.add_constructor("tag:yaml.org,2002:float", Loader.construct_yaml_float)
    # YAML 1.2's floats without a dot (1e-10, 2E5), which PyYAML (YAML 1.1) reads as text: a file
    # writes `threshold: 1e-10` and means a number, and text is refused where a number belongs
    # (no_quoted_numbers), so a quoted "300" stays text and is refused with one line
    import re as _re
    Loader.add_implicit_resolver("tag:yaml.org,2002:float", _re.compile(r"^[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+$"),
                                 list("-+0123456789"))
    return Loader


#: Largest magnitude of a number fkopt takes from a user's file or command line where no
#: schema bounds it (URDF lengths and angles, --joints/--pose values), in the file's own units:
#: 1e9 m is six times the Earth-Sun distance, 1e9 deg 2.8 million turns. Past it a value is a
#: typo or an attack, and its square in FK or a Jacobian overflows to inf (docs/reliability.md).
MAX_MAGNITUDE = 1e9


# -- reading files fkopt did not write -------------------------------------------------------------
#: Largest file of another tool read (bytes): an outside CSV, an IOH ``.dat`` or index, a pose-set
#: CSV, a stored result's table. Checked on the file's size before a byte is read; a compressed
#: file (``.gz``) is also refused once it unpacks to more than ``unpacked`` bytes.
MAX_INPUT_BYTES = 64 << 20
#: Largest decompressed ``.csv.gz`` fkopt reads (bytes), and the largest file of a stored result
#: read back (:func:`read_stored`). The largest it writes, kinbench v2's ``trace.csv.gz``, unpacks
#: to ~64 MB; the cap keeps a hostile file (a small gzip that unpacks to gigabytes) from taking
#: the memory: :func:`read_input` streams the decompression and stops past it.
MAX_UNPACKED = 256 * 1024 ** 2


def _file_kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def _size(n: int) -> str:
    return f"{n >> 20} MB" if n >= 1 << 20 and n % (1 << 20) == 0 else f"{n} bytes"


def _where(path: Path, field: str | None) -> str:
    return f"{field}: {path}" if field else str(path)


def check_within(path: str | Path, root: str | Path, field: str | None = None) -> Path:
    """``path`` unchanged after checking that it resolves (symbolic links included) inside the
    folder ``root`` it was named from; else one line naming the file and the folder."""
    path = Path(path)
    try:
        base, resolved = Path(root).resolve(), path.resolve()
    except (OSError, RuntimeError) as err:       # a loop of links
        raise FkoptError(f"{_where(path, field)}: cannot resolve ({getattr(err, 'strerror', None) or err})") from None
    if resolved != base and base not in resolved.parents:
        raise FkoptError(f"{_where(path, field)}: resolves outside {root}; only files inside that folder are read")
    return path


def open_input(path: str | Path, max_bytes: int, field: str | None = None,
               within: str | Path | None = None) -> int:
    """A read-only descriptor of the regular file ``path`` (the caller closes it), after every
    check a file of another tool gets: inside ``within`` (when given), a regular file (not a
    folder, FIFO or device: a FIFO would block, ``/dev/zero`` never ends; checked on the opened
    file, so a link swapped meanwhile changes nothing) and at most ``max_bytes`` by its size."""
    path = Path(path)
    where = _where(path, field)
    if within is not None:
        check_within(path, within, field)
    try:    # O_NONBLOCK: opening a FIFO does not wait for a writer; no effect on regular files
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as err:
        raise FkoptError(f"{where}: cannot read ({err.strerror or err})") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise FkoptError(f"{where}: is {_file_kind(info.st_mode)}; only regular files are read")
        if info.st_size > max_bytes:
            raise FkoptError(f"{where}: {info.st_size} bytes, larger than the {_size(max_bytes)} accepted "
                             "for this file")
    except BaseException:
        os.close(fd)
        raise
    return fd


def read_input(path: str | Path, max_bytes: int = MAX_INPUT_BYTES, *, field: str | None = None,
               within: str | Path | None = None, unpacked: int | None = None, unpack: bool = True) -> bytes:
    """The bytes of a file fkopt did not write in this run (configs, URDF, pose sets, outside
    results, IOH data, stored results), read with a bound: :func:`open_input`'s checks, then at
    most ``max_bytes`` read (a file growing meanwhile is refused too). A ``.gz`` file is
    decompressed as a stream and refused past ``unpacked`` bytes (default ``max_bytes``) --
    a 3 MB gzip cannot unpack into gigabytes (``unpack=False``: the file's own bytes, e.g. for
    a digest). Every refusal is one line naming ``field`` and the file."""
    import gzip
    import zlib
    path = Path(path)
    where = _where(path, field)
    fd = open_input(path, max_bytes, field, within)
    with os.fdopen(fd, "rb") as fh:
        try:
            data = fh.read(max_bytes + 1)
        except OSError as err:
            raise FkoptError(f"{where}: cannot read ({err.strerror or err})") from None
        if len(data) > max_bytes:
            raise FkoptError(f"{where}: larger than the {_size(max_bytes)} accepted for this file")
    if not unpack or not path.name.endswith(".gz"):
        return data
    limit = max_bytes if unpacked is None else unpacked
    chunks, size = [], 0
    try:
        with gzip.GzipFile(fileobj=io.BytesIO(data)) as gz:
            while chunk := gz.read(1 << 20):
                size += len(chunk)
                if size > limit:
                    raise FkoptError(f"{where}: unpacks to more than {_size(limit)}, the most accepted for this "
                                     "file; refused (memory stays bounded)")
                chunks.append(chunk)
    except (EOFError, gzip.BadGzipFile, zlib.error) as err:
        what = "truncated gzip (ends early)" if isinstance(err, EOFError) else "not a valid gzip file"
        raise FkoptError(f"{where}: {what}") from None
    return b"".join(chunks)


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
    return parse_csv(data, _where(Path(path), field), **options)


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


def read_text(path: str | Path, max_bytes: int = MAX_YAML_BYTES, *, field: str | None = None,
              within: str | Path | None = None, unpacked: int | None = None) -> str:
    """The UTF-8 text of a user file (:func:`read_input`'s bounds); every failure is one line."""
    data = read_input(path, max_bytes, field=field, within=within, unpacked=unpacked)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise FkoptError(f"{_where(Path(path), field)}: not UTF-8 text (byte 0x{data[err.start]:02x} at offset "
                         f"{err.start})") from None


#: Deepest element nesting of an XML robot file (URDF, MJCF and every file an MJCF includes):
#: URDF is 3-4 deep, MJCF nests one body per link (real arms and humanoids: under 40). Checked
#: while parsing, before any outside library reads the file: TRAC-IK's parser crashed (exit 139)
#: on a URDF nested 100,000 deep outside the chain.
MAX_XML_DEPTH = 256


def parse_xml(data: bytes | str, where: str, max_depth: int = MAX_XML_DEPTH):
    """The root element of an XML document (the standard library's parser, streamed), refused
    with one line naming ``where`` once an element lies deeper than ``max_depth`` (the rest is
    never parsed) or the XML is malformed."""
    import xml.etree.ElementTree as ET
    parser = ET.XMLPullParser(events=("start", "end"))
    depth, root, step = 0, None, 1 << 16

    def events():
        nonlocal depth, root
        for event, element in parser.read_events():
            if root is None:
                root = element
            depth += 1 if event == "start" else -1
            if depth > max_depth:
                raise FkoptError(f"{where}: elements nested deeper than {max_depth} levels; refused "
                                 "before any parser of an outside package reads it")
    try:
        for i in range(0, len(data), step):
            parser.feed(data[i:i + step])
            events()
        parser.close()
        events()
    except ET.ParseError as err:
        raise FkoptError(f"{where}: malformed XML ({err})") from None
    if root is None:
        raise FkoptError(f"{where}: malformed XML (no element)")
    return root


def parse_json(data: bytes, where: str) -> Any:
    """Strict JSON from the bytes of a file fkopt did not write (``where`` names it): UTF-8,
    ``NaN``/``Infinity`` refused, nesting bounded; every failure is one line."""
    def constant(name):
        raise ValueError(f"{name} is not JSON")
    try:
        return json.loads(data.decode("utf-8"), parse_constant=constant)
    except UnicodeDecodeError as err:
        raise FkoptError(f"{where}: not UTF-8 text (offset {err.start})") from None
    except RecursionError:
        raise FkoptError(f"{where}: nested too deeply") from None
    except ValueError as err:
        raise FkoptError(f"{where}: not valid JSON ({one_line(str(err), 80)})") from None


def read_json(path: str | Path, max_bytes: int = MAX_INPUT_BYTES, *, field: str | None = None,
              within: str | Path | None = None) -> Any:
    """A JSON file fkopt did not write in this run: bounded (:func:`read_input`), then
    :func:`parse_json`."""
    return parse_json(read_input(path, max_bytes, field=field, within=within), _where(Path(path), field))


def read_stored(folder: str | Path, name: str | Path, unpack: bool = True) -> bytes:
    """A file of a stored result (``folder/name``), read back by ``check``, ``report``,
    ``export`` or ``compare``: inside ``folder`` (a link out of it is refused), a regular file,
    at most :data:`MAX_UNPACKED` bytes, unpacked too."""
    return read_input(Path(folder) / name, MAX_UNPACKED, within=folder, unpacked=MAX_UNPACKED, unpack=unpack)


def stored_sha256(path: str | Path, max_bytes: int = MAX_UNPACKED) -> str:
    """SHA-256 of a stored file's own bytes (not unpacked), read bounded: a regular file inside
    its folder, at most ``max_bytes`` (default :func:`read_stored`'s); a FIFO or ``/dev/zero``
    there is one line, never a hang. The one file digest of results folders, task files and
    released kinbench files."""
    import hashlib
    path = Path(path)
    return hashlib.sha256(read_input(path, max_bytes, within=path.parent, unpack=False)).hexdigest()


def odd_entries(folder: str | Path) -> list[tuple[str, str]]:
    """(relative path, what it is) of every entry below ``folder`` that is not a plain file or
    folder: symbolic links (wherever they point), FIFOs, devices, sockets. A results folder
    fkopt wrote holds none, so ``fkopt check`` refuses to read one that does (a ``runs.csv``
    linked to ``/dev/zero`` or outside the folder)."""
    folder = Path(folder)
    out = []
    for base, dirs, files in os.walk(folder, followlinks=False):
        for name in sorted(dirs) + sorted(files):
            path = Path(base) / name
            mode = os.lstat(path).st_mode
            if stat.S_ISLNK(mode):
                out.append((str(path.relative_to(folder)), "a symbolic link"))
            elif not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
                out.append((str(path.relative_to(folder)), _file_kind(mode)))
    return out


def check_geometry_file(path: Path, mechanism: str, max_bytes: int, what: str) -> None:
    """A mechanism's ``geometry.file`` is a regular file (not a folder, FIFO or device) of at
    most ``max_bytes`` (checked before any parser reads it); ``what`` names the format in the
    message, e.g. "a URDF file"."""
    if not Path(path).exists() and not Path(path).is_symlink():
        raise FkoptError(f"{mechanism} geometry.file: {path} does not exist")
    try:
        os.close(open_input(path, max_bytes, f"{mechanism} geometry.file"))
    except FkoptError as err:
        raise FkoptError(str(err).replace("for this file", f"for {what}")) from None


def load_yaml(path: str | Path, max_bytes: int = MAX_YAML_BYTES) -> Any:
    """Parse a YAML file with the limits above; errors name the file and the line."""
    import yaml
    text = read_text(path, max_bytes)
    try:
        return yaml.load(text, Loader=_loader())  # noqa: S506 - a SafeLoader subclass
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise FkoptError(f"{path}: malformed YAML{where}: {err.problem or err.context}") from None
    except yaml.YAMLError as err:
        raise FkoptError(f"{path}: malformed YAML: {err}") from None
    except RecursionError:
        raise FkoptError(f"{path}: nested too deeply") from None


def load_mapping(path: str | Path, what: str) -> dict:
    """A YAML file whose top level must be a mapping (``what`` says of what)."""
    data = load_yaml(path)
    if not isinstance(data, dict):
        raise FkoptError(f"{path}: expected a mapping of {what} at the top level")
    bad = [k for k in data if not isinstance(k, str)]
    if bad:
        raise FkoptError(f"{path}: field names must be text, got {bad[0]!r}")
    return data


# -- pydantic errors -------------------------------------------------------------------------------
def models_in(annotation) -> list:
    """The pydantic models an annotation can hold (through Optional/Union, list, dict, Annotated)."""
    import typing

    from pydantic import BaseModel
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for arg in typing.get_args(annotation) for m in models_in(arg)]


def field_names_at(model, loc: list[str]) -> list[str]:
    """The field names (and aliases) a mapping at ``loc`` (an error's location without its last
    part) may have, walking ``model``'s annotations; [] where that is not known."""
    current = models_in(model)
    for part in loc:
        if part.isdigit() or part.startswith(("list[", "function-", "literal[", "dict[")):
            continue                         # list items and validator frames: same models
        tagged = [m for m in current if m.__name__ == part]
        if tagged:                           # a union branch pydantic tried
            current = tagged
            continue
        current = [m for c in current if part in c.model_fields for m in models_in(c.model_fields[part].annotation)]
    names = []
    for c in current:
        for key, info in c.model_fields.items():
            names += [key] + ([info.alias] if info.alias else [])
    return sorted(set(names))


def _numeric_only(annotation) -> bool:
    """Whether a field's type takes numbers (int, float, bool; Optional of them) and no text."""
    import typing
    if annotation in (int, float, bool):
        return True
    args = typing.get_args(annotation)
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _numeric_only(args[0])
    if origin in (typing.Union, getattr(__import__("types"), "UnionType", None)) and args:
        kinds = [a for a in args if a is not type(None)]
        return bool(kinds) and all(_numeric_only(a) for a in kinds)
    return False


def no_quoted_numbers(cls, value, info):
    """A pydantic ``field_validator("*", mode="before")``: text where a number belongs is refused
    (``iterations: "300"``), as a YAML file means a number only unquoted; pydantic's lax mode
    would turn "300" into 300 silently. Lists of numbers are checked item by item. Fields that
    also take text (a union with str or a Literal) keep it."""
    import typing
    field = cls.model_fields.get(info.field_name) if info.field_name else None
    if field is None:
        return value
    annotation = field.annotation
    items = None
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if typing.get_origin(annotation) is typing.Union or type(None) in args:    # Optional[list[float]]
        kinds = [a for a in args if a is not type(None)]
        if len(kinds) == 1:
            annotation = kinds[0]
            origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin in (list, tuple) and args:
        inner = [a for a in args if a is not Ellipsis]
        if inner and all(_numeric_only(a) for a in inner) and isinstance(value, (list, tuple)):
            items = value
    elif origin is dict and len(args) == 2 and _numeric_only(args[1]) and isinstance(value, dict):
        items = list(value.values())
    if isinstance(value, str) and _numeric_only(annotation):
        raise ValueError(_text_for_number(value, "a number"))
    for v in items or ():
        if isinstance(v, str):
            raise ValueError(_text_for_number(v, "numbers"))
    return value


def _text_for_number(text: str, wanted: str) -> str:
    import math
    try:
        number = float(text)
    except ValueError:
        return f"needs {wanted}, got the text {short_token(repr(text))}"
    if not math.isfinite(number):
        return f"needs {wanted} (finite), got the text {short_token(repr(text))}"
    return f"needs {wanted}, got the text {short_token(repr(text))} (write it without quotes)"


def field_path(loc) -> str:
    """A field's path as every message of fkopt writes it: names joined by dots, list items by
    index in brackets (``cases[0].pose``, ``algorithms[1].params.limit``), from a pydantic
    error's ``loc`` (list indices are ints there)."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def did_you_mean(word: str, names) -> str:
    """`` (did you mean 'x'?)`` for the closest of ``names`` (difflib, as the CLI's options), else ``""``."""
    import difflib
    close = difflib.get_close_matches(str(word), [str(n) for n in names], n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


def error_line(err, branches: dict[str, dict[str, str]] | None = None, data: dict | None = None,
               model=None) -> str:
    """One line ``field.path: message`` from a pydantic ``ValidationError``.

    ``branches`` maps a union field to ``{key in the user's mapping: branch tag}``, so that the
    error of the branch the user meant (by its key) is reported, not the first branch tried.
    With ``model`` (the validated class), an unknown field names the closest allowed one, and
    such a typo is reported before the "Field required" it causes (``algoritms`` before
    ``algorithms``).
    """
    errors = err.errors()
    if model is not None:     # a misspelt field first: its "missing" twin follows from it
        hint = {id(e): did_you_mean(e["loc"][-1], field_names_at(model, [str(p) for p in e["loc"][:-1]]))
                for e in errors if e["type"] == "extra_forbidden"}
        errors = sorted(errors, key=lambda e: 0 if hint.get(id(e)) else 1)
    else:
        hint = {}
    wanted: dict[str, str] = {}
    tags: set[str] = set()
    for field, table in (branches or {}).items():
        tags |= set(table.values())
        value = (data or {}).get(field)
        if isinstance(value, dict):
            hit = next((tag for key, tag in table.items() if key in value), None)
            if hit:
                wanted[field] = hit
        elif isinstance(value, list):
            wanted[field] = "list["
    for e in errors:
        loc = [str(p) for p in e["loc"]]
        if loc and loc[0] in wanted and len(loc) > 1:
            branch = loc[1]
            union = branch in tags or branch.startswith("list[")
            if union and not branch.startswith(wanted[loc[0]]):
                continue
        loc = [p for p in e["loc"] if isinstance(p, int)
               or (p not in tags and not str(p).startswith(("function-", "list[", "literal[")))]
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] == "extra_forbidden":
            msg = "unknown field" + (hint.get(id(e)) or "")
        return f"{field_path(loc)}: {msg}" if loc else msg
    return str(err).splitlines()[0]


# -- paths -----------------------------------------------------------------------------------------
def check_component(value: Any, field: str) -> str:
    """``value`` as one safe path component, else a one-line error naming ``field``."""
    if not isinstance(value, str) or not _COMPONENT.match(value):
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        raise FkoptError(f"{field}: {shown} is not a single safe folder name: letters, digits and "
                         f"_ . + - only, a letter or digit first, at most {MAX_COMPONENT} characters")
    return value


def file_names(names, reserved=(), allowed: str = "A-Za-z0-9_.+-", sep: str = "_") -> dict[str, str]:
    """A file-name stem for each of ``names``, never the same for two distinct names (nor equal
    to a ``reserved`` stem), compared ignoring case (a case-insensitive file system).

    A name made only of ``allowed`` characters keeps itself (so existing files keep their
    names); any other name has each run of other characters replaced by ``sep``, and when that
    stem is taken -- by a name spelled so (``pso-lm`` beside ``pso+lm``, ``a_b`` beside ``a b``),
    by a reserved stem (``all``) or by another such name -- gets ``sep`` and 8 hex digits of
    its SHA-256 (then a counter, should even that be taken). Deterministic: the same set of
    names gives the same stems."""
    import hashlib
    unsafe = re.compile(f"[^{allowed}]+")
    names = sorted(set(map(str, names)))
    taken = {r.lower() for r in reserved}
    out: dict[str, str] = {}
    owners = [n for n in names if n and not unsafe.search(n) and not n.startswith(".")]
    for group in (owners, [n for n in names if n not in set(owners)]):
        for name in group:
            stem = name if group is owners else (unsafe.sub(sep, name).strip(sep + ".") or "x")[:48]
            if stem.lower() in taken:
                stem = f"{stem[:48]}{sep}{hashlib.sha256(name.encode()).hexdigest()[:8]}"
                base, k = stem, 2
                while stem.lower() in taken:
                    stem, k = f"{base}{sep}{k}", k + 1
            taken.add(stem.lower())
            out[name] = stem
    return out


def inside(root: str | Path, path: str | Path, option: str = "--out") -> Path:
    """``path`` unchanged, after checking that it resolves (every symbolic link on the way,
    including ``path`` itself) to ``root`` or below it; else one line naming both."""
    path = Path(path)
    try:
        base = Path(root).resolve()
        resolved = path.resolve()
    except (OSError, RuntimeError) as err:   # a loop of links
        raise FkoptError(f"{option}: {path}: cannot resolve ({getattr(err, 'strerror', None) or err})") from None
    if resolved != base and base not in resolved.parents:
        link = " (through a symbolic link)" if resolved != path.absolute() else ""
        raise FkoptError(f"{option}: {path} resolves to {resolved}{link}, outside {root}; refusing to write there")
    return path


def output_folder(out: str | Path, *parts: str, option: str = "--out") -> Path:
    """``OUT/parts...`` checked before any computation; returns the path (unresolved, for messages).

    Checks: each part is a safe component; ``OUT`` is a folder or can be created as one (not a
    file); it is writable (a temporary entry is created and removed in the parent of the
    result); the resolved result (symbolic links included) lies inside the resolved ``OUT``.
    The parent of the result is created (the result itself is not: writers swap it in).
    """
    out = Path(out)
    for i, part in enumerate(parts):
        check_component(part, ("paper", "name")[i] if len(parts) == 2 else "name")
    target = out.joinpath(*parts)
    if out.exists() and not out.is_dir():
        raise FkoptError(f"{option}: {out} is a file, not a folder")
    inside(out, target, option)
    if target.exists() and not target.is_dir():
        raise FkoptError(f"{option}: {target} exists and is a file, not a results folder")
    parent = target.parent if parts else target
    for p in [parent, *parent.parents]:
        if p.exists():
            if not p.is_dir():
                raise FkoptError(f"{option}: {p} is a file, not a folder")
            break
    try:
        parent.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".fkopt-probe-", dir=parent)
        os.close(fd)
        os.unlink(probe)
    except OSError as err:
        raise FkoptError(f"{option}: cannot write into {parent} ({err.strerror or err})") from None
    return target


@contextlib.contextmanager
def no_empty_folders_left(folders):
    """Run the block; if it fails (an error, Ctrl-C), remove those of ``folders`` that did not
    exist before it and are empty after it (deepest first): an interrupted fresh run leaves no
    empty ``OUT/<paper>/`` behind. A folder holding anything is never touched."""
    fresh = sorted({Path(f) for f in folders if not Path(f).exists()}, key=lambda p: -len(p.parts))
    try:
        yield
    except BaseException:
        for folder in fresh:
            try:
                folder.rmdir()            # only an empty folder: rmdir refuses anything else
            except OSError:
                pass
        raise


# -- atomic writes ---------------------------------------------------------------------------------
_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap two paths (Linux ``renameat2``); False where unsupported."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    if fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):   # file system or kernel without it
        return False
    raise OSError(code, os.strerror(code), str(b))


def swap_into_place(new: Path, final: Path) -> None:
    """Put folder ``new`` at ``final``; a previous ``final`` is removed only after the swap."""
    if not final.exists():
        try:
            os.replace(new, final)
            return
        except OSError as err:   # another run put a result there meanwhile: swap with it instead
            if err.errno not in (errno.ENOTEMPTY, errno.EEXIST):
                raise
    if _exchange(new, final):
        shutil.rmtree(new, ignore_errors=True)     # ``new`` now holds the previous result
        return
    old = Path(tempfile.mkdtemp(prefix=f".{final.name}.old-", dir=final.parent))
    blocked = {signal.SIGINT, signal.SIGTERM}
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, blocked) if hasattr(signal, "pthread_sigmask") else None
    try:
        os.replace(final, old / "x")
        os.replace(new, final)
    finally:
        if mask is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
    shutil.rmtree(old, ignore_errors=True)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def write_atomically(final: str | Path, write: Callable[[Path], Any],
                     check: Callable[[Path], Any] | None = None) -> Path:
    """Call ``write(tmp)`` on a hidden temporary sibling of ``final``, then swap it into place.

    ``check(final)``, when given, runs just before the swap (after the computation and the
    writing): a publish-time check, e.g. that no other run put a different result at ``final``
    meanwhile; raising from it leaves ``final`` as it is.

    A failed or interrupted write (exception, Ctrl-C, kill -9) leaves ``final`` as it was (the
    previous result or nothing); a killed process may leave a hidden ``.<name>.new-*`` folder.
    """
    final = Path(final)
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{final.name}.new-", dir=final.parent))
    try:
        os.chmod(tmp, 0o777 & ~_umask())      # mkdtemp makes it private; a results folder is not
        write(tmp)
        if check is not None:
            check(final)
        swap_into_place(tmp, final)
    except OSError as err:
        shutil.rmtree(tmp, ignore_errors=True)
        name = Path(err.filename) if err.filename else None
        if name is not None and (name == tmp or tmp in name.parents):   # the file as the user knows it
            name = final / name.relative_to(tmp)
        where = f"{name}: " if name is not None else f"{final}: "
        raise FkoptError(f"{where}cannot write ({err.strerror or err}); the previous result is kept") from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return final


@contextlib.contextmanager
def run_lock(out: str | Path, folder: str | Path):
    """Hold ``OUT/<paper>/.<name>.lock`` (an advisory ``flock``, released by the kernel when the
    process dies, kill -9 included) while a run computes and publishes ``folder``: a second fkopt
    run of the same paper/name at the same time is refused with one line instead of wiping the
    first one's task files or racing its swap. The file is removed when the run ends (a stale
    one left by a killed run is simply taken over)."""
    import fcntl
    folder = Path(folder)
    path = inside(out, folder.parent / f".{folder.name}.lock")
    path.parent.mkdir(parents=True, exist_ok=True)
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise FkoptError(f"{folder}: another fkopt run is computing this result right now ({path.name} is "
                             "locked); wait for it to finish, or choose another --out or name") from None
        try:
            if os.stat(path).st_ino == os.fstat(fd).st_ino:
                break           # still the file at that path (not unlinked by the previous holder)
        except FileNotFoundError:
            pass
        os.close(fd)
    try:
        yield path
    finally:
        try:
            os.unlink(path)     # while still holding it, so no one locks a file about to vanish
        except OSError:
            pass
        os.close(fd)


def write_file_atomically(path: str | Path, write: Callable[[Path], Any]) -> None:
    """Call ``write(tmp)`` on a temporary file beside ``path``, fsync it, rename it into place."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        with naming_the_file(path):
            write(Path(tmp))
            with open(tmp, "rb") as fh:
                os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def naming_the_file(path: str | Path):
    """An OSError raised while writing ``path`` without naming a file (a full disk, a quota: the
    kernel reports ENOSPC at write or close, not at open) is re-raised naming ``path``, so the
    one line says which file could not be written (the previous result is kept by the swap)."""
    try:
        yield
    except OSError as err:
        if err.filename:
            raise
        raise OSError(err.errno, err.strerror or str(err), str(path)) from None


def write_json_atomically(path: str | Path, data: Any, **dump) -> None:
    text = json.dumps(data, **dump)
    write_file_atomically(path, lambda p: p.write_text(text + ("\n" if dump.get("indent") else "")))


def strict_json(data: Any, **dump) -> str:
    """``data`` as strict JSON (RFC 8259: no ``NaN``/``Infinity``, which strict parsers reject),
    for every ``--json`` output: a number that is not finite becomes ``null`` and the object gets
    a ``"non_finite"`` mapping from that field's path (``position_error``, ``solutions[0].x``)
    to ``"inf"``, ``"-inf"`` or ``"nan"`` -- nothing is lost, nothing guessed (docs/cli.md)."""
    import math
    flags: dict[str, str] = {}

    def clean(value, path):
        if isinstance(value, dict):
            return {k: clean(v, f"{path}.{k}" if path else str(k)) for k, v in value.items()}
        if isinstance(value, np.ndarray):
            value = value.tolist()
        if isinstance(value, (list, tuple)):
            return [clean(v, f"{path}[{i}]") for i, v in enumerate(value)]
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        if isinstance(value, np.integer):
            return int(value)
        if isinstance(value, (float, np.floating)):
            value = float(value)
            if not math.isfinite(value):
                flags[path] = "nan" if value != value else ("inf" if value > 0 else "-inf")
                return None
        return value
    out = clean(data, "")
    if flags and isinstance(out, dict):
        out["non_finite"] = flags
    return json.dumps(out, allow_nan=False, default=str, **dump)


def write_json(path: str | Path, data: Any) -> None:
    """The one JSON layout of results files (sorted keys, indent 2, newline at the end)."""
    Path(path).write_text(json.dumps(data, indent=2, sort_keys=True, default=float) + "\n")


# -- resources -------------------------------------------------------------------------------------
def available_cpus() -> int:
    """CPUs this process may run on (its affinity mask, else the CPU count)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


# -- numbers ---------------------------------------------------------------------------------------
def nanmedian(a) -> float:
    """Median over the non-NaN values; NaN when there are none (no numpy warning)."""
    a = np.asarray(a, dtype=float)
    ok = ~np.isnan(a)
    return float(np.median(a[ok])) if ok.any() else float("nan")


#: Characters that mean something in Markdown tables, links, code or HTML, and their escapes.
_MD_ESCAPES = {"\\": "\\\\", "`": "\\`", "*": "\\*", "[": "\\[", "]": "\\]", "|": "\\|",
               "<": "&lt;", ">": "&gt;", "&": "&amp;"}


def md_text(value: Any) -> str:
    """``value`` as literal text inside a Markdown file (a table cell, a heading): HTML (``<script>``,
    ``<img onerror>``) and entities, link and image brackets, table bars, code ticks and
    emphasis stars escaped; newlines, terminal escape sequences and other control characters
    shown as ``\\xNN`` text instead of acting (a title cannot start a new heading or recolour a
    terminal that shows the file)."""
    out = []
    for c in str(value):
        if c in _MD_ESCAPES:
            out.append(_MD_ESCAPES[c])
        elif not c.isprintable():
            out.append(f"\\\\x{ord(c):02x}" if ord(c) < 256 else f"\\\\u{ord(c):04x}")
        else:
            out.append(c)
    return "".join(out)


def short_token(text: Any, limit: int = 40) -> str:
    """A short, printable excerpt of a hostile file's text for an error line: whitespace runs
    made one space, non-printable characters ``?``, at most ``limit`` characters."""
    text = " ".join(str(text).split())
    text = "".join(c if c.isprintable() else "?" for c in text)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def one_line(text: str, limit: int = 2000) -> str:
    """``text`` safe to print as one line: control characters escaped, long text cut."""
    text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))
    return text if len(text) <= limit else text[: limit - 3] + "..."
