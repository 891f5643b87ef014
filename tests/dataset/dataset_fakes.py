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
