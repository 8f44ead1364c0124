"""Where and how fkopt writes: :func:`output_folder` checks ``OUT/<paper>/<name>`` before any
computation (inside ``OUT``, a writable folder, not a file); :func:`inside` is the one
output-path guard every writer calls on every path (a symbolic link planted inside ``--out``
cannot redirect a write outside); :func:`write_atomically` writes a folder aside (a hidden
temporary sibling) and swaps it into place with one ``renameat2(RENAME_EXCHANGE)`` system call
(two renames with signals blocked where that call does not exist), so the previous result stays
complete until the new one is; :func:`write_file_atomically` does the same for one file;
:func:`run_lock` keeps two runs of the same result apart; :func:`file_names` gives
collision-free file-name stems for user-given names."""
from __future__ import annotations

import contextlib
import ctypes
import errno
import hashlib
import json
import os
import re
import shutil
import signal
import tempfile
from pathlib import Path
from typing import Any, Callable

from fkopt.errors import FkoptError
from fkopt.files.validation import check_component

def file_names(names, reserved=(), allowed: str = "A-Za-z0-9_.+-", sep: str = "_") -> dict[str, str]:
    """A file-name stem for each of ``names``, never the same for two distinct names (nor equal
    to a ``reserved`` stem), compared ignoring case (a case-insensitive file system).

    A name made only of ``allowed`` characters keeps itself (so existing files keep their
    names); any other name has each run of other characters replaced by ``sep``, and when that
    stem is taken -- by a name spelled so (``pso-lm`` beside ``pso+lm``, ``a_b`` beside ``a b``),
    by a reserved stem (``all``) or by another such name -- gets ``sep`` and 8 hex digits of
    its SHA-256 (then a counter, should even that be taken). Deterministic: the same set of
    names gives the same stems."""
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
    import fcntl       # POSIX only: imported where used, so fkopt imports where it is absent
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
    try:                                    # from the temporary's creation on, any exit removes it
        os.close(fd)
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


def write_json(path: str | Path, data: Any) -> None:
    """The one JSON layout of results files (sorted keys, indent 2, newline at the end)."""
    Path(path).write_text(json.dumps(data, indent=2, sort_keys=True, default=float) + "\n")
