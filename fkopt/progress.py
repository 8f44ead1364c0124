"""Progress inside a task: how far the running solve is, for a progress bar whose ETA moves.

A task of the runner (:mod:`fkopt.run.tasks`) is an algorithm on all cases of an
experiment, a study's chunk of poses or a suite's (problem, solver): a bar that counts finished
tasks sits at 0/3 for most of a short run. So the innermost loops say how far they are with
:func:`tick` -- an algorithm after each iteration (:meth:`fkopt.algorithms.base.Algorithm.minimize`),
an exact solver after each row, :func:`fkopt.solve` by chunk of rows -- and whoever shows
progress listens with :func:`listening`. Without a listener a tick costs one context-variable
lookup; nothing here touches a number or a random stream.

The listener is a context variable, not a global, so nested scopes compose: :func:`fkopt.solve`
maps the fraction of one chunk onto the fraction of its whole batch (:func:`part`). Ticks do not
cross process boundaries: tasks run in worker processes (``--jobs``, Dask) move the bar when
they finish.
"""
from __future__ import annotations

import contextvars
from contextlib import contextmanager
from typing import Callable, Iterator

_listener: contextvars.ContextVar[Callable[[float], None] | None] = contextvars.ContextVar(
    "fkopt_progress", default=None)


def tick(done: float, total: float) -> None:
    """``done`` of ``total`` steps of the innermost running loop are finished."""
    listener = _listener.get()
    if listener is not None and total > 0:
        listener(min(max(done / total, 0.0), 1.0))


def heard() -> bool:
    """Is anyone listening? Loops that run many steps per compiled call cut their calls shorter
    then, so the bar moves inside a task (:meth:`fkopt.algorithms.base.Algorithm.minimize`)."""
    return _listener.get() is not None


@contextmanager
def listening(callback: Callable[[float], None] | None) -> Iterator[None]:
    """Within the block, ``callback(fraction)`` hears every :func:`tick` (fraction in [0, 1])."""
    token = _listener.set(callback)
    try:
        yield
    finally:
        _listener.reset(token)


@contextmanager
def part(start: float, stop: float) -> Iterator[None]:
    """Within the block, ticks are the fraction of a part [start, stop] of the enclosing loop
    (e.g. one chunk of a solve's rows), passed on as the enclosing loop's fraction."""
    outer = _listener.get()
    if outer is None:
        yield
        return
    with listening(lambda f: outer(start + f * (stop - start))):
        yield
