"""Executors: run one task function over many items, serially, in local processes or on Dask.

Every executor has one method, ``map_unordered(fn, items)``, yielding ``(item, outcome)`` pairs
as tasks finish, where *outcome* is ``fn(item)`` or the exception it raised; a failed item never
stops the others. *fn* and the items must be picklable (module-level function, plain records)
for the process and Dask executors.

Local processes use the ``spawn`` start method: Mitsuba/Dr.Jit keep thread pools and LLVM
state that a ``fork`` would copy half-initialised into the children. Each worker asks the kernel
to kill it when its parent dies (``prctl(PR_SET_PDEATHSIG)`` on Linux), so a ``kill -9`` of
the build leaves no orphaned workers holding hundreds of MiB each.
"""

from __future__ import annotations

import ctypes
import logging
import multiprocessing
import os
import signal
import socket
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, TypeVar

from ..errors import DatasetError, MissingDependencyError, validate_choice
from ..file_writes import write_text_file
from ..interrupts import raise_if_requested

__all__ = [
    "Executor",
    "SerialExecutor",
    "ProcessExecutor",
    "DaskExecutor",
    "EXECUTORS",
    "make_executor",
    "ExecutorChoice",
    "choose_executor",
    "WorkerCrashedError",
    "SCHEDULER_TIMEOUT_S",
    "check_scheduler",
    "die_with_parent",
]

log = logging.getLogger(__name__)

T = TypeVar("T")
R = TypeVar("R")

#: How long a Dask scheduler may take to accept a TCP connection before it counts as unreachable.
SCHEDULER_TIMEOUT_S = 3.0
#: ``PR_SET_PDEATHSIG`` from ``<linux/prctl.h>``.
_PR_SET_PDEATHSIG = 1


def die_with_parent(parent_pid: int) -> None:
    """Have the kernel send SIGKILL to this process when its parent dies (Linux only).

    Runs first in every pool worker. If the parent is already gone (it died before the
    ``prctl`` call took effect), exit at once.
    """
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) != 0:
            log.warning("prctl(PR_SET_PDEATHSIG) failed: errno %d", ctypes.get_errno())
    if os.getppid() != parent_pid:
        os._exit(1)


def _init_worker(
    parent_pid: int, initializer: Callable[..., None] | None, initargs: tuple[Any, ...]
) -> None:
    """Pool initializer: tie the worker's life to its parent, then run the user's initializer."""
    die_with_parent(parent_pid)
    if initializer is not None:
        initializer(*initargs)


class WorkerCrashedError(DatasetError):
    """A worker process died (segfault, out of memory, killed) while running an item."""


class Executor(Protocol):
    """Runs ``fn`` over ``items`` and yields ``(item, result or exception)`` as tasks finish."""

    @property
    def name(self) -> str: ...

    def map_unordered(
        self, fn: Callable[[T], R], items: Sequence[T]
    ) -> Iterator[tuple[T, R | BaseException]]: ...


@dataclass(frozen=True)
class SerialExecutor:
    """Run items one after the other in this process (simplest; easiest to debug)."""

    name: str = "serial"

    def map_unordered(
        self, fn: Callable[[T], R], items: Sequence[T]
    ) -> Iterator[tuple[T, R | BaseException]]:
        for item in items:
            raise_if_requested()
            try:
                outcome: R | BaseException = fn(item)
            except Exception as exc:  # a failed item must not stop the others
                # ...but a Ctrl-C that a library re-raised as another error must
                raise_if_requested()
                outcome = exc
            yield item, outcome


@dataclass(frozen=True)
class ProcessExecutor:
    """Run items in a pool of *workers* local processes started with ``spawn``.

    A worker process that dies (segfault, out of memory, killed) breaks the whole pool and
    every unfinished task with it. The items that were *running* then are suspects: each is
    re-run alone in a one-process pool, so a crash there is unambiguous and reported as
    :class:`WorkerCrashedError` for that item only; the items that were merely queued go back
    to the shared pool.
    """

    workers: int
    initializer: Callable[..., None] | None = None
    initargs: tuple[Any, ...] = ()
    name: str = "process"

    def __post_init__(self) -> None:
        if self.workers < 1:
            raise DatasetError(f"workers={self.workers}; expected a positive integer")

    def map_unordered(
        self, fn: Callable[[T], R], items: Sequence[T]
    ) -> Iterator[tuple[T, R | BaseException]]:
        with tempfile.TemporaryDirectory(prefix="spectrinsic-running-") as running_dir:
            queued = list(enumerate(items))
            idle_crashes = 0
            while queued:
                suspects: list[tuple[int, T]] = []
                for i, item, outcome in self._run_pool(fn, queued, self.workers, running_dir):
                    if isinstance(outcome, BrokenProcessPool):
                        suspects.append((i, item))
                    else:
                        yield item, outcome
                running = _running_indices(running_dir)
                queued = [p for p in suspects if p[0] not in running]
                if suspects and not running:
                    # a worker died outside any task (failed initializer, killed while idle):
                    # retry once, then give up rather than loop
                    idle_crashes += 1
                    if idle_crashes > 1:
                        for _, item in queued:
                            yield (
                                item,
                                WorkerCrashedError(
                                    f"worker processes keep dying before running {item!r}"
                                ),
                            )
                        return
                for i, item in (p for p in suspects if p[0] in running):
                    log.warning("a worker process died; re-running %r alone", item)
                    for _, _, outcome in self._run_pool(fn, [(i, item)], 1, running_dir):
                        if isinstance(outcome, BrokenProcessPool):
                            outcome = WorkerCrashedError(
                                f"worker process died while running {item!r}"
                            )
                        yield item, outcome

    def _run_pool(
        self, fn: Callable[[T], R], batch: list[tuple[int, T]], workers: int, running_dir: str
    ) -> Iterator[tuple[int, T, R | BaseException]]:
        for stale in Path(running_dir).iterdir():
            stale.unlink()
        pool = ProcessPoolExecutor(
            max_workers=min(workers, len(batch)),
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_init_worker,
            initargs=(os.getpid(), self.initializer, self.initargs),
        )
        try:
            futures: dict[Future[R], tuple[int, T]] = {
                pool.submit(_run_recorded, fn, item, i, running_dir): (i, item) for i, item in batch
            }
            not_done = set(futures)
            while not_done:
                done, not_done = wait(not_done, return_when=FIRST_COMPLETED)
                for fut in done:
                    i, item = futures[fut]
                    exc = fut.exception()
                    yield i, item, (exc if exc is not None else fut.result())
        except KeyboardInterrupt:
            # Workers inherit the blocked SIGINT (spectrinsic.interrupts): stop the running
            # ones now rather than wait for their samples; those stay temporaries that the
            # next run removes, as after a kill.
            _terminate_running(running_dir)
            raise
        finally:
            # On Ctrl-C or an abandoned generator: drop queued tasks, keep finished ones.
            pool.shutdown(wait=True, cancel_futures=True)


def _run_recorded(fn: Callable[[T], R], item: T, index: int, running_dir: str) -> R:
    """Run ``fn(item)`` in a worker, leaving a file naming *index* while it runs."""
    record = Path(running_dir, str(os.getpid()))
    write_text_file(record, str(index))
    try:
        return fn(item)
    finally:
        record.unlink(missing_ok=True)


def _terminate_running(running_dir: str) -> None:
    """Send SIGTERM to every worker that is running a task (named by its record's file name)."""
    for record in Path(running_dir).iterdir():
        try:
            os.kill(int(record.name), signal.SIGTERM)
        except (ValueError, ProcessLookupError):
            pass


def _running_indices(running_dir: str) -> set[int]:
    """Indices of the items whose worker died while running them (their records remain)."""
    return {int(p.read_text() or -1) for p in Path(running_dir).iterdir()}


@dataclass(frozen=True)
class DaskExecutor:
    """Run items on a Dask distributed cluster whose scheduler listens at *address*.

    Tasks are submitted with ``pure=False`` (each runs once per submission); Dask itself
    reschedules the tasks of a worker that dies (up to the scheduler's
    ``distributed.scheduler.allowed-failures``), so a lost worker does not lose its samples.
    Every worker must be able to import spectrinsic and write to the output folder.
    """

    address: str
    name: str = "dask"

    def map_unordered(
        self, fn: Callable[[T], R], items: Sequence[T]
    ) -> Iterator[tuple[T, R | BaseException]]:
        try:
            from distributed import Client, as_completed
        except ImportError as exc:  # pragma: no cover - depends on the environment
            raise MissingDependencyError(
                "--scheduler needs dask.distributed: pip install 'spectrinsic[distributed]'"
            ) from exc
        check_scheduler(self.address)
        try:
            client = Client(self.address, set_as_default=False, timeout=SCHEDULER_TIMEOUT_S * 3)
        except (OSError, TimeoutError) as exc:
            raise DatasetError(f"--scheduler {self.address!r}: cannot connect ({exc})") from exc
        futures: dict[Any, T] = {}
        try:
            for item in items:
                futures[client.submit(fn, item, pure=False)] = item
            for fut in as_completed(list(futures), loop=client.loop):
                item = futures.pop(fut)
                if fut.status == "error":
                    yield item, fut.exception()
                else:
                    yield item, fut.result()
        finally:
            if futures:  # interrupted: do not leave our tasks running on a shared cluster
                client.cancel(list(futures))
            client.close()


def check_scheduler(address: str, *, timeout: float = SCHEDULER_TIMEOUT_S) -> tuple[str, int]:
    """Check that *address* (``tcp://host:port``) names a Dask scheduler accepting connections
    within *timeout* s; return ``(host, port)``.

    Raises
    ------
    DatasetError
        One line naming the address: malformed, or nothing listening there.
    """
    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    host, colon, port_text = rest.rpartition(":")
    host = host.strip("[]")
    expected = "expected tcp://HOST:PORT, e.g. tcp://10.0.0.5:8786"
    if scheme not in ("tcp", "tls") or not colon or not host or not port_text.isdigit():
        raise DatasetError(f"--scheduler {address!r}: malformed address; {expected}")
    port = int(port_text)
    if not 0 < port < 65536:
        raise DatasetError(f"--scheduler {address!r}: port {port} out of range; {expected}")
    try:
        with socket.create_connection((host, port), timeout=timeout):
            pass
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise DatasetError(
            f"--scheduler {address!r}: no scheduler reachable within {timeout:g} s ({reason})"
        ) from exc
    return host, port


#: Executor kinds known to :func:`make_executor`.
EXECUTORS: tuple[str, ...] = ("serial", "process", "dask")


def make_executor(
    kind: str,
    *,
    workers: int = 1,
    scheduler: str | None = None,
    initializer: Callable[..., None] | None = None,
    initargs: tuple[Any, ...] = (),
) -> Executor:
    """Build an executor by name.

    Parameters
    ----------
    kind
        ``"serial"``, ``"process"`` (needs *workers*) or ``"dask"`` (needs *scheduler*).
    workers
        Local worker processes for ``"process"``.
    scheduler
        Dask scheduler address (``tcp://host:8786``) for ``"dask"``.
    initializer, initargs
        Called once in each local worker process (``"process"`` only).
    """
    validate_choice(kind, EXECUTORS, "executor", error=DatasetError)
    if kind == "serial":
        return SerialExecutor()
    if kind == "process":
        return ProcessExecutor(workers, initializer, initargs)
    if not scheduler:
        raise DatasetError("the dask executor needs a scheduler address (--scheduler ADDRESS)")
    return DaskExecutor(scheduler)


@dataclass(frozen=True)
class ExecutorChoice:
    """What a dataset build runs on: the executor, the render threads per worker (None: Dr.Jit's
    default, every core) and a few words saying where, for messages."""

    executor: Executor
    render_threads: int | None
    where: str


def choose_executor(
    *,
    workers: int | None = None,
    threads: int | None = None,
    scheduler: str | None = None,
    cores: int | None = None,
) -> ExecutorChoice:
    """The executor policy of a dataset build (``spectrinsic dataset --workers/--threads/--scheduler``).

    Parameters
    ----------
    workers
        Local worker processes; None means 1.
    threads
        Render threads per worker; None picks one (see below).
    scheduler
        A Dask scheduler address: if given, the build runs there (*workers* is ignored).
    cores
        CPU cores of this machine; default ``os.cpu_count()``.

    Returns
    -------
    ExecutorChoice
        With a scheduler: the Dask executor, 1 render thread per task by default. With one
        worker: the serial executor in this process, Dr.Jit's thread pool on every core. With
        more: that many ``spawn`` processes, ``cores // workers`` (at least 1) threads each.

    >>> choice = choose_executor(workers=2, cores=8)
    >>> choice.executor.name, choice.render_threads, choice.where
    ('process', 4, '2 local worker processes')
    >>> choose_executor().where
    'this process'
    """
    cores = cores if cores is not None else (os.cpu_count() or 1)
    # One process whose Dr.Jit pool uses every core beat one single-threaded process per core
    # on the 2-core reference machine (28 s vs 42 s for 4 default samples): each process
    # compiles its own kernels and holds its own scene.
    workers = 1 if workers is None else workers
    if scheduler:
        return ExecutorChoice(
            make_executor("dask", scheduler=scheduler),
            threads if threads is not None else 1,
            f"Dask scheduler {scheduler}",
        )
    if workers == 1:
        return ExecutorChoice(make_executor("serial"), threads, "this process")
    return ExecutorChoice(
        make_executor("process", workers=workers),
        threads if threads is not None else max(1, cores // workers),
        f"{workers} local worker processes",
    )
