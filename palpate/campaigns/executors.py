"""Where campaign trials run: a standard ``concurrent.futures.Executor``, chosen by name.

- ``process`` (default): a local process pool, one trial per core (``workers`` = 1: serial).
- ``thread``: a thread pool (the GIL serialises most of the work; useful to check that trials
  share no state, and where processes cannot be forked).
- ``serial``: every trial in the calling thread, in order.
- ``dask``: a Dask distributed client's executor (``Client.get_executor()``, the
  ``concurrent.futures`` interface). With ``scheduler`` an address (``tcp://host:8786``) it uses a
  running cluster; without, it starts a local one with ``workers`` worker processes. Dask is an
  optional extra (``pip install 'palpate[dask]'``), imported only when asked for.

Local pool workers die with the process that started them (:func:`process_pool`): a campaign
killed with SIGKILL leaves no worker behind waiting forever on its pipe. The workers share the
cores' BLAS threads out (one each when there are as many workers as cores): a pool already puts
one worker on each core, and a BLAS that spreads each worker's small products over every core as
well spends them waiting on each other (a map
study's compute per probe: 0.05 s median and 0.24 worst with two workers of two threads each on
two cores, 0.012 and 0.018 with one thread each; docs/speed.md).

No scheduling of our own: every backend is an Executor, ``palpate.campaigns.campaign.run_campaign``
submits one job per trial and each trial is seeded by its spec, so results do not depend on
which executor ran them.
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import importlib
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import Executor, Future, ProcessPoolExecutor, ThreadPoolExecutor
from typing import Any, TypeVar

from threadpoolctl import threadpool_limits

from palpate.config.loader import InputError

T = TypeVar("T")

_PR_SET_PDEATHSIG = 1  # linux/prctl.h
_WATCH_PERIOD_S = 0.5


def pool_worker(parent: int, blas_threads: int = 1) -> None:
    """Pool worker initializer: die with process ``parent`` (:func:`die_with_parent`) and keep
    BLAS to this worker's share of the cores (``blas_threads``)."""
    threadpool_limits(blas_threads)
    die_with_parent(parent)


def blas_share(workers: int) -> int:
    """BLAS threads for each of ``workers`` pool workers: the cores shared out, at least one
    (two workers on two cores: one each; one worker alone, a new 3-D geometry's factorisation
    for instance, keeps every core)."""
    return max(1, (os.cpu_count() or 1) // max(1, workers))


def die_with_parent(parent: int) -> None:
    """Pool worker initializer: end this worker when process ``parent`` (the one that started
    the pool) dies, however it dies. On Linux the kernel sends SIGKILL (``PR_SET_PDEATHSIG``);
    elsewhere a thread watches the parent's pid."""
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0:
            if os.getppid() != parent:  # the parent died before the request took effect
                os._exit(1)
            return
    threading.Thread(target=_watch_parent, args=(parent,), name="parent-watch", daemon=True).start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        threading.Event().wait(_WATCH_PERIOD_S)
    os._exit(1)


def process_pool(workers: int) -> ProcessPoolExecutor:
    """A local process pool whose workers die with this process and share the cores' BLAS
    threads out among them (:func:`pool_worker`, :func:`blas_share`)."""
    return ProcessPoolExecutor(
        max_workers=workers, initializer=pool_worker, initargs=(os.getpid(), blas_share(workers))
    )


class ExecutorUnavailableError(InputError):
    """The executor asked for cannot be built here (missing optional dependency, bad option)."""


class SerialExecutor(Executor):
    """Runs each submitted call at once in the caller's thread (an Executor with no workers)."""

    def submit(self, fn: Callable[..., T], /, *args: Any, **kwargs: Any) -> Future[T]:
        future: Future[T] = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:
            future.set_exception(exc)
        return future


@contextlib.contextmanager
def _serial(workers: int, scheduler: str | None) -> Iterator[Executor]:
    yield SerialExecutor()


@contextlib.contextmanager
def _threads(workers: int, scheduler: str | None) -> Iterator[Executor]:
    with ThreadPoolExecutor(max_workers=workers) as pool:
        yield pool


@contextlib.contextmanager
def _processes(workers: int, scheduler: str | None) -> Iterator[Executor]:
    if workers == 1:  # a pool of one process only adds start-up and pickling
        yield SerialExecutor()
        return
    with process_pool(workers) as pool:
        yield pool


@contextlib.contextmanager
def _dask(workers: int, scheduler: str | None) -> Iterator[Executor]:
    try:  # optional: typed as Any, so the code checks the same with or without it installed
        distributed: Any = importlib.import_module("distributed")
    except ImportError as exc:
        raise ExecutorUnavailableError(
            "--executor dask needs Dask distributed, an optional extra: "
            "pip install 'palpate[dask]' (or pip install distributed)"
        ) from exc
    if scheduler:
        with distributed.Client(scheduler) as client:
            yield client.get_executor()
        return
    with (
        distributed.LocalCluster(
            n_workers=workers, threads_per_worker=1, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        yield client.get_executor()


EXECUTORS: dict[str, Callable[[int, str | None], contextlib.AbstractContextManager[Executor]]] = {
    "process": _processes,
    "thread": _threads,
    "serial": _serial,
    "dask": _dask,
}
"""Executor name -> context manager factory ``(workers, scheduler) -> Executor``."""


def open_executor(
    kind: str, workers: int = 1, scheduler: str | None = None
) -> contextlib.AbstractContextManager[Executor]:
    """The executor called ``kind`` (a key of ``EXECUTORS``), shut down when the block ends.

    Raises:
        ExecutorUnavailableError: unknown kind, ``workers`` < 1, a scheduler address for a local
            executor, or Dask not installed.
    """
    if kind not in EXECUTORS:
        raise ExecutorUnavailableError(f"unknown executor {kind!r}; known: {sorted(EXECUTORS)}")
    if workers < 1:
        raise ExecutorUnavailableError(f"--workers must be >= 1, got {workers}")
    if scheduler and kind != "dask":
        raise ExecutorUnavailableError(f"--scheduler is for --executor dask, not {kind!r}")
    return EXECUTORS[kind](workers, scheduler)


def add_executor_arguments(parser: argparse.ArgumentParser) -> None:
    """``--executor`` and ``--scheduler`` for a command that runs campaigns (with ``--workers``)."""
    parser.add_argument(
        "--executor",
        choices=sorted(EXECUTORS),
        default="process",
        help="where trials run: a local process pool, threads, serially, or Dask",
    )
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="Dask scheduler address (tcp://host:8786) for --executor dask; "
        "without it a local Dask cluster is started",
    )
