"""What this machine lets the process use: the CPUs it may run on (worker counts are bounded by
them), which release of a package is installed (env.json, boards' settings, messages), and
SIGINT's handler while a block runs (:func:`sigint_handler`)."""
from __future__ import annotations

import os
import signal
import threading
from contextlib import contextmanager


@contextmanager
def sigint_handler(handler):
    """SIGINT's handler is ``handler`` inside the block, and the previous one is put back whatever
    happens: ``signal.signal`` first runs the handlers of signals already pending, and one of them
    (another library's SIGALRM or SIGTERM handler) may raise before the swap back; a handler left
    swapped would hold or ignore every later Ctrl-C of the process. Only the main thread may set a
    handler: elsewhere, or where the previous handler was not set from Python, nothing changes."""
    previous = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or previous is None:
        yield
        return
    try:
        signal.signal(signal.SIGINT, handler)
        yield
    finally:
        raised = None
        while signal.getsignal(signal.SIGINT) is not previous:
            try:
                signal.signal(signal.SIGINT, previous)
            except BaseException as err:     # a pending handler raised before the swap back
                raised = raised or err
        if raised is not None:
            raise raised


def installed_version(distribution: str) -> str | None:
    """The installed version of a distribution ("numba" -> "0.61.2"), or None when it is not
    installed (fkopt itself run from a source tree). The one lookup every caller words its own way."""
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version(distribution)
    except PackageNotFoundError:
        return None


def available_cpus() -> int:
    """CPUs this process may run on (its affinity mask, else the CPU count)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)
