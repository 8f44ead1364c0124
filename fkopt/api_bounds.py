"""Upper (and lower) bounds of every option of the Python API, checked in one place.

``fkopt.inverse``, ``fkopt.InverseSolver`` / ``inverse_solver`` (through
:meth:`fkopt.numerics.InverseOptions.validated`) and ``fkopt.forward`` call :func:`check_options`
on their options and :func:`check_array` on the numbers they are given, so bad input is one
:class:`FkoptError` line naming the option and what it allows -- never an ``OverflowError`` from
a 20-digit seed, a ``MemoryError`` (or 4 GB taken) from ``table=10**7``, a ``ValueError`` from
``table='x'``, nor a complex target silently losing its imaginary part (issue 42).

The bounds (docs/python-api.md, docs/reliability.md):

* numbers given as data (targets, joints, starts) and float options: finite, real, |v| <=
  :data:`MAX_API_VALUE` = 1e9 in their own units (``fkopt.files.MAX_MAGNITUDE``, the bound of
  every number fkopt reads from a file);
* ``seed``: an integer in [0, 2^63 - 1] (the compiled loops take it as a 64-bit integer);
* the integer options: :data:`INTEGER_BOUNDS`. ``table`` is bounded by memory: the start table
  holds ~0.4 kB per entry (``table=10**7`` took 4.1 GB), so its 1,000,000 keep it under ~0.5 GB;
  ``threads`` (None: the CPUs the process may run on) at most 256, each a thread started per batch.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from fkopt.errors import FkoptError
from fkopt.files import MAX_MAGNITUDE

#: Largest |value| of a number given to the API (targets, joints, starts, float options).
MAX_API_VALUE = MAX_MAGNITUDE
#: Largest seed (the compiled loops' int64).
MAX_SEED = 2 ** 63 - 1
#: (smallest, largest) of each integer option of ``inverse`` and ``forward``.
INTEGER_BOUNDS = {
    "restarts": (0, 1_000_000),        # random restarts per row
    "starts": (1, 10_000),             # candidates side by side per row
    "iterations": (0, 100_000),        # per candidate before it restarts
    "fill": (1, 10_000),
    "table": (0, 1_000_000),           # start-table entries (~0.4 kB each)
    "neighbours": (0, 1_000_000),
    "tail": (1, 1_000_000),
    "candidates": (1, 10_000),         # forward: nearest table poses all run
    "threads": (1, 256),               # inverse: threads sharing a batch (more than the CPUs only adds switching)
    "seed": (0, MAX_SEED),
}


def check_integer(name: str, value, what: str) -> int:
    """``value`` as an int within :data:`INTEGER_BOUNDS` [``name``], else one line."""
    low, high = INTEGER_BOUNDS[name]
    ok = not isinstance(value, bool) and (isinstance(value, numbers.Integral)
                                           or isinstance(value, float) and value.is_integer())
    if not ok or not low <= value <= high:
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        raise FkoptError(f"{what} {name}: expected an integer >= {low} and <= {high}, got {shown}")
    return int(value)


def check_number(name: str, value, what: str, *, low: float = -MAX_API_VALUE, positive: bool = False,
                 none: bool = False):
    """``value`` as a float: real, finite, within [``low``, :data:`MAX_API_VALUE`] (> 0 when
    ``positive``; None allowed when ``none``), else one line."""
    if none and value is None:
        return None
    ok = not isinstance(value, bool) and isinstance(value, numbers.Real)
    if ok:
        try:
            v = float(value)
        except (OverflowError, ValueError):
            ok = False
        else:
            ok = math.isfinite(v) and low <= v <= MAX_API_VALUE and (v > 0 or not positive)
    if not ok:
        allowed = ("None or " if none else "") + ("a number > 0" if positive else f"a number >= {low:g}") + \
            f" and <= {MAX_API_VALUE:g}"
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        raise FkoptError(f"{what} {name}: expected {allowed}, got {shown}")
    return v


def check_options(what: str, **options) -> dict:
    """The one check of an API entry's options (``what``: ``inverse``, ``forward``, ...): each
    integer option (:data:`INTEGER_BOUNDS`) and ``seed`` an integer in its range, each other
    option a finite real number within :data:`MAX_API_VALUE` (``rest`` >= 0; ``stall`` in [0, 1]; ``tol`` and the
    rest > 0; ``orientation_scale`` also None). Returns the options as ints and floats."""
    out = {}
    for name, value in options.items():
        if name in INTEGER_BOUNDS:
            out[name] = check_integer(name, value, what)
        elif name == "rest":
            out[name] = check_number(name, value, what, low=0.0)
        elif name == "stall":                          # a ratio of |r|^2: 0 (off) to 1 (never met)
            v = check_number(name, value, what, low=0.0)
            if v > 1.0:
                raise FkoptError(f"{what} {name}: expected a number >= 0 and <= 1, got {value!r}")
            out[name] = v
        else:
            out[name] = check_number(name, value, what, positive=True, none=name == "orientation_scale")
    return out


def check_array(values, what: str) -> np.ndarray:
    """``values`` as a float array: real (a complex number is refused, not cut to its real
    part), at least one row, every value finite and |v| <= :data:`MAX_API_VALUE`; else one line."""
    try:
        a = np.asarray(values)
    except (TypeError, ValueError, OverflowError):
        raise FkoptError(f"{what}: expected an array of numbers, got {type(values).__name__}") from None
    if a.dtype.kind == "c" or (a.dtype == object and any(isinstance(v, complex) for v in a.ravel()[:1000])):
        raise FkoptError(f"{what}: complex numbers are not accepted (real values only)")
    if a.dtype.kind not in "fiub":
        try:
            a = a.astype(float)
        except (TypeError, ValueError, OverflowError):
            raise FkoptError(f"{what}: expected numbers, got {a.dtype} values") from None
    elif a.dtype.kind != "f":
        a = a.astype(float)
    if a.size == 0:
        raise FkoptError(f"{what}: no values (an empty batch, shape {a.shape}); give at least one")
    with np.errstate(invalid="ignore"):
        bad = ~(np.abs(a) <= MAX_API_VALUE)
    if bad.any():
        v = float(a.ravel()[int(np.flatnonzero(bad.ravel())[0])])
        raise FkoptError(f"{what}: values must be finite and within +-{MAX_API_VALUE:g} (the bound of every "
                         f"value given to fkopt), got {v!r}")
    return a
