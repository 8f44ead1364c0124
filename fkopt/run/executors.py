"""Where the tasks of a config (any kind) run: this process, local worker processes, or a Dask cluster.

:func:`execute` calls ``fn(payload)`` for every payload and ``on_result(result)`` in *this*
process as each finishes (in completion order; the study writes the task file there, so a
remote worker needs no shared file system). The executor never changes a number: each task
carries its own seeds.

* ``local`` with ``jobs=1``: one after the other in this process (no pool, easiest to debug);
* ``local`` with ``jobs=N``: a :class:`concurrent.futures.ProcessPoolExecutor` of N worker
  processes started with the ``spawn`` method (a clean interpreter, safe next to threads);
* ``dask``: :mod:`dask.distributed` (optional extra ``fkopt[dask]``). With ``scheduler`` the
  tasks go to that existing cluster (its workers need fkopt installed); without it a
  ``LocalCluster`` of ``jobs`` single-threaded worker processes is started for the study.

Worker processes are never more than the CPUs available to this process nor than the tasks
(:func:`worker_count`: ``--jobs 10000`` on 2 CPUs starts 2). A scheduler address is checked
for its form and then for a connection (:func:`check_scheduler`) before a study touches its
files, so a mistyped address costs nothing and loses no finished task.

Any exception (a failed task, KeyboardInterrupt, or one raised by ``on_result``) cancels the
tasks not yet started and propagates; finished tasks have already been handed to ``on_result``.
"""
from __future__ import annotations

import multiprocessing
import re
import signal
import socket
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any, Callable

from fkopt.errors import FkoptError
from fkopt.files import available_cpus, sigint_handler

EXECUTORS = ("local", "dask")
#: A Dask scheduler address: ``[tcp|tls]://host:port`` (or ``host:port``).
ADDRESS = re.compile(r"^(?:(?P<scheme>tcp|tls|ws|wss|ucx)://)?(?P<host>[A-Za-z0-9._-]{1,253}|\[[0-9A-Fa-f:.]{2,45}\])"
                     r":(?P<port>[0-9]{1,5})$")
#: A scheduler in this very process (Dask's ``inproc://`` transport): nothing to connect to.
INPROC = re.compile(r"^inproc://[A-Za-z0-9._/-]{1,200}$")
#: Seconds to wait for a Dask scheduler to accept a connection.
CONNECT_TIMEOUT = 5.0


def scheduler_address(scheduler: str) -> tuple[str, str, int]:
    """(scheme, host, port) of a scheduler address, or a one-line error saying what is allowed."""
    if INPROC.match(scheduler or ""):
        return "inproc", "", 0
    m = ADDRESS.match(scheduler or "")
    port = int(m["port"]) if m else 0
    if not m or not 0 < port < 65536:
        shown = repr(scheduler) if len(repr(scheduler)) <= 60 else repr(scheduler)[:57] + "..."
        raise FkoptError(f"--scheduler: {shown} is not a Dask scheduler address; expected "
                         "tcp://HOST:PORT, tls://HOST:PORT or HOST:PORT (port 1-65535)")
    return m["scheme"] or "tcp", m["host"].strip("[]"), port


def check_scheduler(executor: str, scheduler: str | None) -> None:
    """Refuse an unreachable scheduler with one line, before a study touches any file."""
    if executor != "dask" or not scheduler:
        return
    scheme, host, port = scheduler_address(scheduler)
    if scheme == "inproc":
        return
    try:
        socket.create_connection((host, port), timeout=CONNECT_TIMEOUT).close()
    except OSError as err:
        raise FkoptError(f"--scheduler: cannot connect to the Dask scheduler at {scheduler} "
                         f"({err.strerror or type(err).__name__})") from None


def worker_count(jobs: int, tasks: int) -> int:
    """Processes worth starting: at most ``jobs``, the CPUs available and the tasks."""
    return max(1, min(int(jobs), available_cpus(), int(tasks)))


def validate_executor(executor: str, jobs: int, scheduler: str | None) -> None:
    if executor not in EXECUTORS:
        raise FkoptError(f"--executor: '{executor}' unknown; allowed: {', '.join(EXECUTORS)}")
    if int(jobs) < 1:
        raise FkoptError(f"--jobs: must be at least 1, got {jobs}")
    if scheduler and executor != "dask":
        raise FkoptError("--scheduler: only used with --executor dask")
    if scheduler:
        scheduler_address(scheduler)
    if executor == "dask":
        dask_modules()


def dask_modules():
    try:
        import dask.distributed as dd
    except ImportError:
        raise FkoptError("--executor dask needs dask.distributed, which is not installed "
                         "(pip install 'fkopt[dask]')") from None
    return dd


def execute(fn: Callable[[Any], Any], payloads: list, *, executor: str = "local", jobs: int = 1,
            scheduler: str | None = None, on_result: Callable[[Any], None]) -> None:
    validate_executor(executor, jobs, scheduler)
    if not payloads:
        return
    if executor == "dask":
        _dask(fn, payloads, jobs, scheduler, on_result)
    elif worker_count(jobs, len(payloads)) == 1:
        for p in payloads:
            on_result(fn(p))
    else:
        _processes(fn, payloads, worker_count(jobs, len(payloads)), on_result)


def _ignore_interrupts() -> None:
    """A worker's start: Ctrl-C belongs to the parent. A terminal sends SIGINT to the whole process
    group, and a worker interrupted inside numba's compiler printed llvmlite's "Exception ignored
    in ... __del__" traceback beside fkopt's one line (seen in CI). The parent, on its
    KeyboardInterrupt, terminates the workers (:func:`_processes`). Workers started by the pool
    later (after one died) get it here; the first ones are born ignoring SIGINT (below)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _processes(fn, payloads, jobs, on_result) -> None:
    pool = None
    try:
        # SIGINT ignored while the pool starts its workers: a spawned worker keeps an ignored signal
        # through its exec, so a Ctrl-C while it still imports fkopt (before its initializer) cannot
        # print a traceback from it; a Ctrl-C to this process in these milliseconds is ignored too
        with sigint_handler(signal.SIG_IGN):
            pool = ProcessPoolExecutor(max_workers=jobs, initializer=_ignore_interrupts,
                                       mp_context=multiprocessing.get_context("spawn"))
            futures = [pool.submit(fn, p) for p in payloads]
        for fut in as_completed(futures):
            on_result(fut.result())
    except BaseException:
        # Stop at once (Ctrl-C, a failed task): tasks already queued to a worker cannot be
        # cancelled, and the workers ignore SIGINT, so they are terminated (their results would be
        # thrown away anyway).
        if pool is not None:
            procs = list((getattr(pool, "_processes", None) or {}).values())
            pool.shutdown(wait=False, cancel_futures=True)
            for proc in procs:
                if proc.is_alive():
                    proc.terminate()
        raise
    pool.shutdown(wait=True)


def _dask(fn, payloads, jobs, scheduler, on_result) -> None:
    dd = dask_modules()
    cluster = None
    try:
        if scheduler:
            try:
                client = dd.Client(scheduler, timeout="20s")
            except Exception as err:   # refused, timed out, not a scheduler: one line, no traceback
                first = (str(err).strip().splitlines() or [""])[0][:200]
                raise FkoptError(f"--scheduler: cannot connect to the Dask scheduler at {scheduler} "
                                 f"({type(err).__name__}: {first})") from None
        else:
            cluster = dd.LocalCluster(n_workers=worker_count(jobs, len(payloads)), threads_per_worker=1,
                                      processes=True,
                                      dashboard_address=None)
            client = dd.Client(cluster)
        futures = client.map(fn, payloads, pure=False)
        try:
            for fut in dd.as_completed(futures):
                on_result(fut.result())
        except BaseException:
            client.cancel(futures)
            raise
        finally:
            client.close()
    finally:
        if cluster is not None:
            cluster.close()
