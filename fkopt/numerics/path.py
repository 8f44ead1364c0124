"""Which numerics path runs: the compiled one (numba) or the numpy/Python reference.

``FKOPT_NUMERICS=numpy`` in the environment forces the reference everywhere (tests, machines
without numba); ``FKOPT_NUMERICS=compiled`` makes a missing numba an error instead of a silent
fallback. Otherwise the compiled path runs when numba is importable. numba is imported on the
first call that wants a compiled kernel, never at ``import fkopt`` (importing numba and loading its
cache costs more than one pose saves, so a one-pose ``fkopt ik`` process keeps the reference:
see ``fkopt/cli.py``); the 3-RPS swarm iterations (PSO, ABC, GABC) import it on their first
iteration. Both paths give the same bits on those swarms (numpy's own ``np.tan`` inside the
compiled iterations, :func:`fkopt.numerics.compiled.numpy_tan`), so stored results do not depend
on the path.
"""
from __future__ import annotations

import os
from contextlib import contextmanager

from fkopt.errors import FkoptError

ENV = "FKOPT_NUMERICS"
_STATE: dict = {}


def requested() -> str:
    """'auto', 'numpy' or 'compiled' from ``FKOPT_NUMERICS`` (read on every call: a test or a
    caller may change it; the parsed value is kept per raw string)."""
    raw = os.environ.get(ENV)
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
    ``want``: True/False from an option (``InverseOptions.compiled``), None for the default."""
    mode = requested()
    if want is False or mode == "numpy":
        return None
    if "module" not in _STATE:
        try:
            from fkopt.numerics import compiled as mod
        except ImportError as err:
            if mode == "compiled" or want:
                raise FkoptError(f"the compiled numerics path needs numba ({err}); pip install numba, "
                                 f"or set {ENV}=numpy") from None
            mod = None
        _STATE["module"] = mod
    return _STATE["module"]


def loaded():
    """:func:`compiled`'s module only when it is already imported (by an earlier :func:`compiled`
    call), else None; never imports numba. For work that pays for the compiled path only once numba
    is loaded anyway (the run streams' refills with a few runs)."""
    if requested() == "numpy":
        return None
    return _STATE.get("module")


def describe() -> dict:
    """What ``env.json`` records (its ``numerics``): ``path``, the path a default ``fkopt.inverse``
    call takes in this process ('compiled' with numba, else 'numpy'); ``mode``, the
    ``FKOPT_NUMERICS`` setting it ran under ('auto', 'numpy' or 'compiled'; the 3-RPS PSO, ABC
    and GABC iterations run compiled under both 'auto' and 'compiled', with the numpy path's bits);
    ``compiled_fitness``: with 'compiled', single 3-RPS fitness calls are compiled too (the same
    bits); numba's version; the raw variable."""
    try:
        from importlib.metadata import PackageNotFoundError, version
        try:
            nv = version("numba")
        except PackageNotFoundError:
            nv = None
    except Exception:      # pragma: no cover - importlib.metadata is standard
        nv = None
    mode = requested()
    path = "numpy" if mode == "numpy" or nv is None else "compiled"
    return {"path": path, "mode": mode, "compiled_fitness": mode == "compiled" and nv is not None, "numba": nv,
            "env": os.environ.get(ENV, "")}


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
