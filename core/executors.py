"""Executors: run one task function over many items, serially, in local processes or on Dask.

Every executor has one method, ``map_unordered(fn, items)``, yielding ``(item, outcome)`` pairs
as tasks finish, where *outcome* is ``fn(item)`` or the exception it raised; a failed item never
stops the others. *fn* and the items must be picklable (module-level function, plain records)
for the process and Dask executors.

Local processes use the ``spawn`` start method: Mitsuba/Dr.Jit keep thread pools and LLVM
state that a ``fork`` would copy half-initialised into the children.
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import tempfile
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, TypeVar

from spectrinsic.errors import DatasetError, MissingDependencyError, validate_choice

__all__ = [
    "Executor",
    "SerialExecutor",
    "ProcessExecutor",
    "DaskExecutor",
    "EXECUTORS",
    "make_executor",
    "WorkerCrashedError",
]

log = logging.getLogger(__name__)

T = TypeVar("T")
R = TypeVar("R")

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
            try:
                outcome: R | BaseException = fn(item)
            except Exception as exc:  # a failed item must not stop the others
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
                            yield item, WorkerCrashedError(
                                f"worker processes keep dying before running {item!r}"
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
            initializer=self.initializer,
            initargs=self.initargs,
        )
        try:
            futures: dict[Future[R], tuple[int, T]] = {
                pool.submit(_run_recorded, fn, item, i, running_dir): (i, item)
                for i, item in batch
            }
            not_done = set(futures)
            while not_done:
                done, not_done = wait(not_done, return_when=FIRST_COMPLETED)
                for fut in done:
                    i, item = futures[fut]
                    exc = fut.exception()
                    yield i, item, (exc if exc is not None else fut.result())
        finally:
            # On Ctrl-C or an abandoned generator: drop queued tasks, keep finished ones.
            pool.shutdown(wait=True, cancel_futures=True)


def _run_recorded(fn: Callable[[T], R], item: T, index: int, running_dir: str) -> R:
    """Run ``fn(item)`` in a worker, leaving a file naming *index* while it runs."""
    record = Path(running_dir, str(os.getpid()))
    record.write_text(str(index))
    try:
        return fn(item)
    finally:
        record.unlink(missing_ok=True)


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
        client = Client(self.address, set_as_default=False)
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
    validate_choice(kind, EXECUTORS, "executor")
    if kind == "serial":
        return SerialExecutor()
    if kind == "process":
        return ProcessExecutor(workers, initializer, initargs)
    if not scheduler:
        raise DatasetError("the dask executor needs a scheduler address (--scheduler ADDRESS)")
    return DaskExecutor(scheduler)
