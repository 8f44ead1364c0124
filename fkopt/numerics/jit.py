"""numba's ``njit`` with an on-disk cache that cannot break a run, and fkopt's one-line notices
about the compiled path.

numba's own ``cache=True`` unpickles the cache's index (``.nbi``) and data (``.nbc``) files
without a guard: a garbage, empty or truncated file (a full disk, a killed process, a copied
folder) raises ``UnpicklingError``, ``EOFError`` or ``ValueError`` out of the first call of that
kernel in every later process, until someone deletes the folder (issue 42, break 14); a cache
folder that turns read-only after it was found writable raises ``PermissionError`` out of the
save. :func:`njit` compiles as ``numba.njit`` and caches through :class:`GuardedCache` instead:

* a file that does not load is set aside (moved into ``set-aside-<time>-<pid>/`` beside it, one
  line on stderr once per process) and the kernel is compiled again and saved afresh: the next
  process loads the rebuilt cache;
* a folder that cannot be read or written (gone, replaced, read-only) keeps the compiled code for
  this process only (one line once per process);
* no usable cache folder at all (numba's locators find none writable) compiles without a cache
  (one line once per process), where ``numba.njit(cache=True)`` raises at import.

The cache object is numba's own ``FunctionCache`` (its locators, index keys and file format), set
on the dispatcher as ``Dispatcher.enable_caching`` does (``dispatcher._cache``); only its load and
save are guarded, and its index key also names the state of every module that holds compiled
kernels (:data:`KERNEL_MODULES`, :func:`kernel_sources_stamp`). numba checks only the calling
function's own file, but a kernel's compiled code includes the kernels it calls from other
modules: an edit of ``compiled_ik.py`` (or an upgrade that changes only it) left
``compiled_branches.py``'s cached kernels running the old ``compiled_ik`` code -- stale code, or in
a fresh install a signature that no longer types. With the stamp, any change of a kernel module
recompiles every kernel once.

A Ctrl-C waits for the kernel being compiled or loaded (:func:`interrupts_deferred`, around every
``Dispatcher.compile``): a KeyboardInterrupt raised inside numba's compiler or llvmlite's
finalisers left them half done, and the process then printed a finaliser's traceback or reported
a broken cache ("no compiled object yet"); a CI run interrupted while compiling died of a
segmentation fault. The interrupt is raised as soon as that compile ends.
"""
from __future__ import annotations

import functools
import hashlib
import os
import signal
import threading
import time
import weakref
from contextlib import contextmanager

import numba
from numba.core.caching import FunctionCache
from numba.core.dispatcher import Dispatcher
from numba.core.serialize import dumps

from fkopt.files.host import sigint_handler
from fkopt.numerics.notice import notice

#: The modules (relative to the fkopt package) that define kernels compiled through :func:`njit`;
#: tests/test_numerics.py holds this list to the package's files.
KERNEL_MODULES = ("algorithms/abc_kernels.py", "algorithms/kernels.py", "algorithms/pso_kernels.py",
                  "mechanisms/rps3_kernels.py", "numerics/compiled.py", "numerics/compiled_branches.py",
                  "numerics/compiled_homotopy.py", "numerics/compiled_ik.py", "numerics/jit.py",
                  "numerics/ufunc_loop.py")

_LOCK = threading.Lock()
_ASIDE: dict[str, str] = {}          # cache folder -> the folder its bad files went to (this process)


def _describe(err: BaseException) -> str:
    text = str(err).strip().splitlines()[0][:120] if str(err).strip() else ""
    return f"{type(err).__name__}: {text}" if text else type(err).__name__


class GuardedCache(FunctionCache):
    """numba's per-function cache whose load sets unreadable files aside (and returns None, so
    numba compiles and saves afresh) and whose save failing only disables the cache."""

    def load_overload(self, sig, target_context):
        try:
            return super().load_overload(sig, target_context)
        except OSError as err:          # the folder itself unreadable or gone: no cache, nothing to set aside
            self._no_cache(err)
            return None
        except Exception as err:        # garbage, empty, truncated, foreign content: set it aside
            self._set_aside(err)
            return None

    def _closure_key(self, sig, codegen):
        """numba's key, but with a closure's compiled functions described by what they are (module,
        name, bytecode, their source file's stamp, their own cells) where numba pickles them with
        a per-process id: a kernel built by a factory on another module's kernels
        (:mod:`fkopt.algorithms.pso_kernels` on :mod:`fkopt.mechanisms.rps3_kernels`) would get a
        new key in every process (a compile every time), and an edit of the other file would not
        change it (stale code)."""
        closure = self._py_func.__closure__
        if closure is None:
            return super()._index_key(sig, codegen)
        cells = tuple(_stable(c.cell_contents) for c in closure)
        code = hashlib.sha256(self._py_func.__code__.co_code).hexdigest()
        return sig, codegen.magic_tuple(), (code, hashlib.sha256(dumps(cells)).hexdigest())

    def _index_key(self, sig, codegen):
        """:meth:`_closure_key` with :func:`kernel_sources_stamp` added."""
        sig_, magic, hashes = self._closure_key(sig, codegen)
        return sig_, magic, hashes + (kernel_sources_stamp(),)

    def save_overload(self, sig, data):
        try:
            super().save_overload(sig, data)
        except Exception as err:
            self._no_cache(err)

    def _no_cache(self, err: BaseException) -> None:
        self.disable()
        notice("cache-io", f"cannot use numba's compiled-code cache in {self._cache_path} ({_describe(err)}); "
                           f"compiled code is kept for this process only")

    def _files(self) -> list[str]:
        """This function's index file and its data files (``<base>.nbi``, ``<base>.<k>.nbc``)."""
        index = self._cache_file._index_path
        base = os.path.basename(index)[:-len(".nbi")]
        try:
            names = os.listdir(self._cache_path)
        except OSError:
            names = []
        data = [os.path.join(self._cache_path, n) for n in names
                if n.startswith(base + ".") and n.endswith(".nbc") and n[len(base) + 1:-len(".nbc")].isdigit()]
        return [index] + sorted(data)

    def _set_aside(self, err: BaseException) -> None:
        folder = self._cache_path
        files = [f for f in self._files() if os.path.lexists(f)]
        with _LOCK:
            aside = _ASIDE.get(folder)
            if aside is None:
                aside = os.path.join(folder, f"set-aside-{time.strftime('%Y%m%dT%H%M%S')}-{os.getpid()}")
                _ASIDE[folder] = aside
        try:
            os.makedirs(aside, exist_ok=True)
            for f in files:
                try:
                    os.replace(f, os.path.join(aside, os.path.basename(f)))
                except FileNotFoundError:      # another process set it aside first
                    pass
        except OSError as move_err:
            # cannot move them (a read-only folder): leave the files, compile in memory
            self.disable()
            notice("cache-bad", f"numba's compiled-code cache in {folder} holds an unreadable file "
                                f"({os.path.basename(files[0]) if files else '?'}: {_describe(err)}) that cannot "
                                f"be set aside ({_describe(move_err)}); compiling in memory for this process "
                                f"(delete the folder to rebuild it)")
            return
        notice("cache-bad", f"numba's compiled-code cache in {folder} held an unreadable file "
                            f"({os.path.basename(files[0]) if files else '?'}: {_describe(err)}); set aside in "
                            f"{aside}, compiling afresh (seconds, once)")


@functools.cache
def kernel_sources_stamp() -> str:
    """SHA-256 of the (path, mtime, size) of every :data:`KERNEL_MODULES` file, once per process."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parts = []
    for rel in KERNEL_MODULES:
        try:
            st = os.stat(os.path.join(root, rel))
            parts.append(f"{rel} {st.st_mtime_ns} {st.st_size}")
        except OSError:
            parts.append(f"{rel} -")
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()


def _stable(value):
    """A closure cell as :meth:`GuardedCache._index_key` hashes it: a compiled function as its
    module, name, bytecode, source file's (mtime, size) and cells; anything else as itself."""
    py = getattr(value, "py_func", None)
    if not isinstance(value, Dispatcher) or py is None:
        return value
    code = py.__code__
    try:
        st = os.stat(code.co_filename)
        stamp = (st.st_mtime, st.st_size)
    except OSError:
        stamp = None
    cells = tuple(_stable(c.cell_contents) for c in (py.__closure__ or ()))
    return "compiled function", py.__module__, py.__qualname__, code.co_code, stamp, cells


_DEFERRING = {"depth": 0}            # nesting of interrupts_deferred in the main thread


@contextmanager
def interrupts_deferred():
    """Hold a SIGINT that arrives inside the block and raise it (through the handler it was meant
    for, Python's KeyboardInterrupt) when the block ends; a second SIGINT inside the block is
    raised at once (someone insists). Only the main thread runs Python's signal handlers; in
    another thread, or where SIGINT is ignored or fatal (no Python handler), the block runs as it
    is. Nested blocks defer to the outermost. The original handler is put back whatever happens
    (:func:`fkopt.files.sigint_handler`)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    if _DEFERRING["depth"]:
        _DEFERRING["depth"] += 1
        try:
            yield
        finally:
            _DEFERRING["depth"] -= 1
        return
    meant_for = signal.getsignal(signal.SIGINT)
    if not callable(meant_for):
        yield
        return
    held = []

    def hold(signum, frame):
        if held:
            meant_for(signum, frame)
        held.append((signum, frame))
    _DEFERRING["depth"] = 1
    try:
        with sigint_handler(hold):
            yield
    finally:
        _DEFERRING["depth"] = 0
        if held:
            meant_for(*held[0])


def _compiled_whole(dispatcher) -> None:
    """Run ``dispatcher.compile`` (numba's lazy compile and cache load, nested for the kernels a
    kernel calls) with Ctrl-C deferred to its end (module docstring). The wrapper holds the
    dispatcher weakly: a bound method would make a reference cycle, and a dropped kernel would
    then be freed by the cyclic collector at any moment instead of at once."""
    compile_ = type(dispatcher).compile
    owner = weakref.ref(dispatcher)

    @functools.wraps(compile_)
    def compile(sig):
        with interrupts_deferred():
            return compile_(owner(), sig)
    dispatcher.compile = compile


def njit(*args, cache: bool = False, **options):
    """``numba.njit(**options)``, with ``cache=True`` meaning :class:`GuardedCache`; used as
    ``@njit`` or ``@njit(cache=True, ...)``. Its compiles finish before a Ctrl-C is raised
    (:func:`interrupts_deferred`)."""
    def decorate(fn):
        dispatcher = numba.njit(**options)(fn)
        _compiled_whole(dispatcher)
        if cache:
            try:
                dispatcher._cache = GuardedCache(fn)
            except Exception as err:    # no writable cache folder anywhere (numba: "no locator available")
                notice("cache-none", f"no writable folder for numba's compiled-code cache ({_describe(err)}); "
                                     f"compiled code is kept for this process only (set NUMBA_CACHE_DIR)")
        return dispatcher
    if args and callable(args[0]) and len(args) == 1 and not options and not cache:
        return decorate(args[0])
    if args:
        raise TypeError("njit takes keyword options only")
    return decorate
