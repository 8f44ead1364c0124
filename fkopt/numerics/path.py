"""Which numerics path runs: the compiled one (numba) or the numpy/Python reference.

``FKOPT_NUMERICS=numpy`` in the environment forces the reference everywhere (tests, machines
without numba); ``FKOPT_NUMERICS=compiled`` makes a missing numba an error instead of a silent
fallback. Otherwise the compiled path runs when numba is importable. numba is imported on the
first call that wants a compiled kernel, never at ``import fkopt`` (importing numba and loading its
cache costs more than one pose saves, so a one-pose ``fkopt ik`` process keeps the reference:
see ``fkopt/cli.py``); the 3-RPS swarm iterations (PSO, ABC, GABC) import it on their first
iteration. Both paths give the same bits on those swarms (numpy's own ``np.tan`` inside the
compiled iterations, :func:`fkopt.mechanisms.rps3_kernels.numpy_tan`), so stored results do not depend
on the path.
"""
from __future__ import annotations

import os
import threading
from contextlib import contextmanager

from fkopt.errors import FkoptError
from fkopt.files.host import installed_version
from fkopt.numerics.notice import notice

ENV = "FKOPT_NUMERICS"
_STATE: dict = {}
_LOCK = threading.RLock()


try:       # os.environ's own store: .get on os.environ raises and catches a KeyError when the
    # variable is unset (~1 µs of every one-pose fkopt.inverse call); its store is kept in step
    # with os.environ's writes, and a key is encoded as os.environ encodes it
    _ENV_DATA, _ENV_KEY, _ENV_DECODE = os.environ._data, os.environ.encodekey(ENV), os.environ.decodevalue
except AttributeError:       # pragma: no cover - another os.environ
    _ENV_DATA = None


def _environ_get() -> str | None:
    if _ENV_DATA is None:    # pragma: no cover
        return os.environ.get(ENV)
    raw = _ENV_DATA.get(_ENV_KEY)
    return None if raw is None else _ENV_DECODE(raw)


def requested() -> str:
    """'auto', 'numpy' or 'compiled' from ``FKOPT_NUMERICS`` (read on every call: a test or a
    caller may change it; the parsed value is kept per raw string)."""
    raw = _environ_get()
    got = _STATE.get(("requested", raw))
    if got is not None:
        return got
    v = (raw or "auto").strip().lower() or "auto"
    if v not in ("auto", "numpy", "compiled"):
        raise FkoptError(f"{ENV}={v!r}: allowed values auto, numpy, compiled")
    _STATE[("requested", raw)] = v
    return v


def compiled(want: bool | None = None):
    """The :mod:`fkopt.numerics.compiled` module when the compiled path runs, else None.
    ``want``: True/False from an option (``InverseOptions.compiled``), None for the default.

    The first call imports numba and compiles (or loads from the cache) a probe kernel. Where
    that fails -- numba or its llvmlite not importable (no wheel for the platform), a compiler
    that does not compile -- one line on stderr, once per process, names the package to install
    (numba) and the numpy path runs; with ``FKOPT_NUMERICS=compiled`` or ``want=True`` it is an
    FkoptError instead. (An unreadable cache file is no failure: :mod:`fkopt.numerics.jit` sets
    it aside and compiles afresh.)"""
    mode = requested()
    if want is False or mode == "numpy":
        return None
    if "module" not in _STATE:
        with _LOCK:
            if "module" not in _STATE:
                _STATE["module"], _STATE["failure"] = _load()
    mod = _STATE["module"]
    if mod is None:
        if mode == "compiled" or want:
            raise FkoptError(f"the compiled numerics path cannot run: {_STATE['failure']}; "
                             f"pip install numba, or set {ENV}=numpy")
        _say_fallback(_STATE["failure"])
    return mod


def compiled_ik(want: bool | None = None):
    """:mod:`fkopt.numerics.compiled_ik` (the compiled one-pose IK) when :func:`compiled` runs, else None."""
    if compiled(want) is None:
        return None
    from fkopt.numerics import compiled_ik as mod       # lazy: numba, an optional package
    return mod


def _load():
    """(module, None) when numba imports and compiles, else (None, the reason in words)."""
    try:
        from fkopt.numerics import compiled as mod     # lazy: numba, an optional package
    except ImportError as err:
        missing = getattr(err, "name", None) or ""
        if missing.split(".")[0] in ("numba", "llvmlite"):
            # numba's llvmlite is numba's own dependency: the package to install is numba either way
            return None, f"numba is not installed or does not import here ({type(err).__name__})"
        return None, f"numba does not import ({type(err).__name__}: {str(err)[:120]})"
    except Exception as err:      # numba present but broken (a mismatched numpy, a bad llvmlite build)
        return None, f"numba does not import ({type(err).__name__}: {str(err)[:120]})"
    try:
        if mod.probe(2.0) != 3.0:
            return None, "numba's compiled probe gave a wrong value"
    except Exception as err:
        return None, f"numba does not compile here ({type(err).__name__}: {str(err).strip()[:120]})"
    return mod, None


def _say_fallback(reason: str) -> None:
    notice("fallback", f"compiled numerics unavailable ({reason}); running the numpy path, which is "
                       f"slower (pip install numba to restore it; {ENV}=numpy silences this)")


def loaded():
    """:func:`compiled`'s module only when it is already imported (by an earlier :func:`compiled`
    call), else None; never imports numba. For work that pays for the compiled path only once numba
    is loaded anyway (the run streams' refills with a few runs)."""
    if requested() == "numpy":
        return None
    return _STATE.get("module")


def describe(check: bool = False) -> dict:
    """What ``env.json`` records (its ``numerics``): ``path``, the path a default ``fkopt.inverse``
    call takes in this process ('compiled' with numba, else 'numpy'); ``mode``, the
    ``FKOPT_NUMERICS`` setting it ran under ('auto', 'numpy' or 'compiled'; the 3-RPS PSO, ABC
    and GABC iterations run compiled under both 'auto' and 'compiled', with the numpy path's bits);
    ``compiled_fitness``: with 'compiled', single 3-RPS fitness calls are compiled too (the same
    bits); the compiler's versions (``numba``, its ``llvmlite``); the raw variable; and, when
    the compiled path was tried in this process and could not run, ``fallback``: why.
    ``check``: try the compiled path now (imports numba: ``fkopt --version``) rather than judge
    by the installed package when it was not tried yet."""
    nv = installed_version("numba")
    mode = requested()
    if check and mode != "numpy" and nv is not None:
        try:
            compiled()
        except FkoptError:
            pass
    failure = _STATE.get("failure") if "module" in _STATE else None
    path = "numpy" if mode == "numpy" or nv is None or failure else "compiled"
    got = {"path": path, "mode": mode, "compiled_fitness": mode == "compiled" and path == "compiled", "numba": nv,
           "llvmlite": installed_version("llvmlite"), "env": os.environ.get(ENV, "")}
    if failure and mode != "numpy":
        got["fallback"] = failure
    return got


def version_line() -> str:
    """``fkopt --version``'s numerics part: the path a default call takes here and the compiler."""
    d = describe(check=True)
    if d["path"] == "compiled":
        return f"numerics: compiled (numba {d['numba']}, llvmlite {d['llvmlite']})"
    why = ("FKOPT_NUMERICS=numpy" if d["mode"] == "numpy" else d.get("fallback") or "numba is not installed")
    return f"numerics: numpy ({why})"


def recorded(env: dict | None) -> str:
    """The ``FKOPT_NUMERICS`` mode a stored result ran under, from its ``env.json``: its
    ``numerics.mode``; 'auto' when it records none -- results stored before the record existed
    ran the numpy swarm fitness and one-pose inverse answers that both paths give alike, which
    'auto' reproduces."""
    got = env.get("numerics") if isinstance(env, dict) else None
    mode = got.get("mode") if isinstance(got, dict) else None
    return mode if mode in ("auto", "numpy", "compiled") else "auto"


@contextmanager
def forced(path: str | None):
    """``FKOPT_NUMERICS`` set to ``path`` ('auto', 'numpy' or 'compiled') inside the block (worker
    processes started inside inherit it), restored after; None leaves it alone. 'compiled' on a
    machine without numba runs 'auto' (the reference): the one-pose inverse answers are the same
    on both paths, and fkopt check's comparison reports whatever else differs."""
    if path is None:
        yield
        return
    if path == "compiled":
        try:
            from importlib.util import find_spec
            have = find_spec("numba") is not None
        except (ImportError, ValueError):
            have = False
        path = "compiled" if have else "auto"
    before = os.environ.get(ENV)
    os.environ[ENV] = path
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(ENV, None)
        else:
            os.environ[ENV] = before
