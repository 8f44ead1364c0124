"""One core for the clock track: a package's call pinned to the core its caller runs on.

pytracik starts two threads per call (KDL's Newton and the SQP solve) and joins both. On a
shared machine with other runnable processes the second thread can wait for the kernel's
scheduler tick (4 ms here): calls of ~4 ms wall time used ~0.5 ms of CPU for both threads
together (docs/kinbench.md, "Outside entries"). Pinned to the caller's core, the two threads
take turns on it and the call costs its CPU time. The clock track (:func:`fkopt.kinbench.clock.run_clock`)
runs every entry pinned so, so every entry gets the same single core; the throughput track may
use every core.

``os.sched_setaffinity(0, ...)`` sets the calling thread's affinity (Linux), which threads it
starts afterwards inherit; the caller's core is ``sched_getcpu`` (glibc). Where affinity is not
available (not Linux) the block runs unpinned and :func:`pinned` says so (False).
"""
from __future__ import annotations

import ctypes
import os
from contextlib import contextmanager


def _libc_getcpu():
    try:
        f = ctypes.CDLL(None, use_errno=True).sched_getcpu
        f.restype = ctypes.c_int
        return f
    except (AttributeError, OSError):
        return None


_GETCPU = _libc_getcpu()


def caller_core(allowed) -> int:
    """The core the calling thread runs on, if it is one of ``allowed``, else the lowest allowed."""
    cpu = _GETCPU() if _GETCPU is not None else -1
    return cpu if cpu in allowed else min(allowed)


@contextmanager
def pinned():
    """The block runs with the calling thread (and the threads it starts) on one core: the one it
    is on. Yields whether it is pinned (already on one core counts); restores the affinity after."""
    if not hasattr(os, "sched_setaffinity"):
        yield False
        return
    allowed = os.sched_getaffinity(0)
    if len(allowed) <= 1:
        yield True
        return
    os.sched_setaffinity(0, {caller_core(allowed)})
    try:
        yield True
    finally:
        os.sched_setaffinity(0, allowed)
