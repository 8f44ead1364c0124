"""Where the tasks of a study run: this process, local worker processes, or a Dask cluster.

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

Any exception (a failed task, KeyboardInterrupt, or one raised by ``on_result``) cancels the
tasks not yet started and propagates; finished tasks have already been handed to ``on_result``.
"""
from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any, Callable

from ..errors import FkoptError

EXECUTORS = ("local", "dask")


def validate_executor(executor: str, jobs: int, scheduler: str | None) -> None:
    if executor not in EXECUTORS:
        raise FkoptError(f"--executor: '{executor}' unknown; allowed: {', '.join(EXECUTORS)}")
    if int(jobs) < 1:
        raise FkoptError(f"--jobs: must be at least 1, got {jobs}")
    if scheduler and executor != "dask":
        raise FkoptError("--scheduler: only used with --executor dask")
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
    elif jobs == 1 or len(payloads) == 1:
        for p in payloads:
            on_result(fn(p))
    else:
        _processes(fn, payloads, jobs, on_result)


def _processes(fn, payloads, jobs, on_result) -> None:
    pool = ProcessPoolExecutor(max_workers=min(jobs, len(payloads)),
                               mp_context=multiprocessing.get_context("spawn"))
    futures = [pool.submit(fn, p) for p in payloads]
    try:
        for fut in as_completed(futures):
            on_result(fut.result())
    except BaseException:
        # Stop at once (Ctrl-C, a failed task): tasks already queued to a worker cannot be
        # cancelled, so the workers are terminated (their results would be thrown away anyway).
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
            except (OSError, TimeoutError) as err:
                raise FkoptError(f"--scheduler: cannot connect to the Dask scheduler at {scheduler} "
                                 f"({type(err).__name__}: {err})") from None
        else:
            cluster = dd.LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True,
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
