"""The one bounded reader of every file fkopt did not write in this run (configs, URDF, MJCF,
pose sets, outside results, IOH data; :func:`read_stored` for stored results): regular files
only, inside the folder they were named from, a size cap checked before reading, ``.gz``
streamed with a cap on the unpacked size. :func:`read_text`, :func:`parse_json` /
:func:`read_json` (strict JSON) and :func:`parse_xml` (nesting bounded while parsing) read on
top of it; :func:`odd_entries` lists what a results folder must not hold (links, FIFOs, devices).
Every refusal is one line naming the file (and the field it came from)."""
from __future__ import annotations

import gzip
import hashlib
import io
import json
import os
import stat
import xml.etree.ElementTree as ET
import zlib
from pathlib import Path
from typing import Any

from fkopt.errors import FkoptError
from fkopt.files.text import one_line

#: Largest config or geometry file read (bytes).
MAX_YAML_BYTES = 1 << 20
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


def where_named(path: Path, field: str | None) -> str:
    """The file as a message names it: ``field: path`` (or the path alone)."""
    return f"{field}: {path}" if field else str(path)


def check_within(path: str | Path, root: str | Path, field: str | None = None) -> Path:
    """``path`` unchanged after checking that it resolves (symbolic links included) inside the
    folder ``root`` it was named from; else one line naming the file and the folder."""
    path = Path(path)
    try:
        base, resolved = Path(root).resolve(), path.resolve()
    except (OSError, RuntimeError) as err:       # a loop of links
        why = getattr(err, "strerror", None) or err
        raise FkoptError(f"{where_named(path, field)}: cannot resolve ({why})") from None
    if resolved != base and base not in resolved.parents:
        raise FkoptError(f"{where_named(path, field)}: resolves outside {root}; only files inside that folder are read")
    return path


def open_input(path: str | Path, max_bytes: int, field: str | None = None,
               within: str | Path | None = None) -> int:
    """A read-only descriptor of the regular file ``path`` (the caller closes it), after every
    check a file of another tool gets: inside ``within`` (when given), a regular file (not a
    folder, FIFO or device: a FIFO would block, ``/dev/zero`` never ends; checked on the opened
    file, so a link swapped meanwhile changes nothing) and at most ``max_bytes`` by its size."""
    path = Path(path)
    where = where_named(path, field)
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
    path = Path(path)
    where = where_named(path, field)
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


def read_text(path: str | Path, max_bytes: int = MAX_YAML_BYTES, *, field: str | None = None,
              within: str | Path | None = None, unpacked: int | None = None) -> str:
    """The UTF-8 text of a user file (:func:`read_input`'s bounds); every failure is one line."""
    data = read_input(path, max_bytes, field=field, within=within, unpacked=unpacked)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise FkoptError(f"{where_named(Path(path), field)}: not UTF-8 text (byte 0x{data[err.start]:02x} at offset "
                         f"{err.start})") from None


#: Deepest element nesting of an XML robot file (URDF, MJCF and every file an MJCF includes):
#: URDF is 3-4 deep, MJCF nests one body per link (real arms and humanoids: under 40). Checked
#: while parsing, before any outside library reads the file: TRAC-IK's parser crashed (exit 139)
#: on a URDF nested 100,000 deep outside the chain.
MAX_XML_DEPTH = 256


def png_size(head: bytes) -> tuple[int, int] | None:
    """(width, height) in pixels from a file's first 24 bytes when they are a PNG's (its signature,
    then the first chunk's length and tag, and IHDR's width and height), else None."""
    if len(head) != 24 or head[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


def parse_xml(data: bytes | str, where: str, max_depth: int = MAX_XML_DEPTH):
    """The root element of an XML document (the standard library's parser, streamed), refused
    with one line naming ``where`` once an element lies deeper than ``max_depth`` (the rest is
    never parsed) or the XML is malformed."""
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
    return parse_json(read_input(path, max_bytes, field=field, within=within), where_named(Path(path), field))


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
