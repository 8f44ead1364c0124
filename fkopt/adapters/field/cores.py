"""One core for the clock track: a package's call pinned to the core its caller runs on.

pytracik starts two threads per call (KDL's Newton and the SQP solve) and joins both. On a
shared machine with other runnable processes the second thread can wait for the kernel's
scheduler tick (4 ms here): calls of ~4 ms wall time used ~0.5 ms of CPU for both threads
together (docs/kinbench.md, "Outside entries"). Pinned to the caller's core, the two threads
take turns on it and the call costs its CPU time. The clock track (:func:`fkopt.kinbench.clock.run_clock`)
runs every entry pinned so, so every entry gets the same single core; the throughput track may
use every core.

``os.sched_setaffinity(tid, ...)`` sets one thread's affinity (Linux), which threads it starts
afterwards inherit; the caller's core is ``sched_getcpu`` (glibc). Threads a package started
*before* the block (OpenBLAS's pool at numpy's import, a Rust package's worker pool) would keep
both cores: a board stored with only the caller pinned showed entries using more CPU than wall
time (CMA-ES 40 ms of CPU in a 20 ms call, OptIK 8x). So :func:`pinned` pins every thread of the
process (``/proc/self/task``) and limits the BLAS and OpenMP pools to one thread
(threadpoolctl) for the block, and restores both after (threads started inside the block get
the affinity they would have inherited without it). Where affinity is not available (not
Linux) the block runs unpinned and :func:`pinned` says so (False).
"""
from __future__ import annotations

import ctypes
import os
from contextlib import contextmanager, nullcontext

from threadpoolctl import threadpool_limits


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


def _threads() -> list[int]:
    """The ids of this process's threads (Linux ``/proc/self/task``); [0] (the caller) elsewhere."""
    try:
        return [int(t) for t in os.listdir("/proc/self/task")]
    except OSError:
        return [0]


def _set(tid: int, cores) -> set[int] | None:
    """``tid``'s affinity before it is set to ``cores``; None when the thread is gone or not ours."""
    try:
        before = os.sched_getaffinity(tid)
        os.sched_setaffinity(tid, cores)
        return before
    except OSError:             # the thread ended meanwhile, or a sandbox forbids it
        return None


@contextmanager
def pinned(whole_process: bool = True):
    """The block runs on one core, the one the caller is on: every thread of the process (and the
    threads they start) with the BLAS/OpenMP pools at one thread, or with ``whole_process=False``
    only the calling thread and the threads it starts (cheap enough for a wrapper's every call:
    TRAC-IK's two threads). Yields whether it is pinned (already on one core counts); restores
    every affinity and pool size after."""
    if not hasattr(os, "sched_setaffinity"):
        yield False
        return
    allowed = os.sched_getaffinity(0)
    if len(allowed) <= 1:
        yield True
        return
    core = {caller_core(allowed)}
    before = {tid: _set(tid, core) for tid in (_threads() if whole_process else [0])}
    try:
        with threadpool_limits(limits=1) if whole_process else nullcontext():
            yield True
    finally:
        for tid, cores in before.items():
            if cores is not None:
                _set(tid, cores)
        # a thread started inside the block (a pool a package made lazily) inherited the one core:
        # it gets the affinity it would have inherited without the block
        for tid in (_threads() if whole_process else []):
            if tid not in before:
                _set(tid, allowed)
