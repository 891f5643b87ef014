"""Fake per-sample tasks for the executor tests.

Imported by name (this folder is put on ``sys.path`` / ``PYTHONPATH``) so that spawned worker
processes and Dask workers can unpickle them by reference.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class FakeItem:
    """One fake task: sleep *seconds*, then return ``index ** 2`` (or fail / crash)."""

    index: int
    marker_dir: str
    seconds: float = 0.0
    fail: bool = False
    crash: bool = False


def square(item: FakeItem) -> tuple[int, int]:
    """Record the start (with the worker pid), sleep, and return ``(index ** 2, pid)``."""
    pid = os.getpid()
    Path(item.marker_dir, f"start-{item.index}-{pid}").touch()
    if item.crash:
        os._exit(3)  # a hard crash: no exception, no clean-up, like a segfault
    time.sleep(item.seconds)
    if item.fail:
        raise ValueError(f"item {item.index} fails on purpose")
    Path(item.marker_dir, f"done-{item.index}-{pid}").touch()
    return item.index**2, pid


def failing_initializer() -> None:
    """A worker initializer that always fails."""
    raise RuntimeError("this worker cannot start")


def parent_death_signal(item: FakeItem) -> int:
    """The signal the kernel sends this worker when its parent dies (0: none), via
    ``prctl(PR_GET_PDEATHSIG)``."""
    import ctypes

    value = ctypes.c_int(0)
    ctypes.CDLL(None).prctl(2, ctypes.byref(value), 0, 0, 0)  # 2 = PR_GET_PDEATHSIG
    return value.value


def run_sleepers(marker_dir: str) -> None:
    """Run two long tasks in a two-worker pool (for a parent killed with SIGKILL meanwhile)."""
    from spectrinsic.pipeline.executors import ProcessExecutor

    items = [FakeItem(i, marker_dir, seconds=600.0) for i in range(2)]
    for _ in ProcessExecutor(workers=2).map_unordered(square, items):
        pass
