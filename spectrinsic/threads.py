"""Array work split over a few threads of this process.

numpy releases the GIL inside its loops, so independent array operations (filling the planes
of a decoded file, composing one batch of a relighting) run side by side on the cores this
process may use. Every task writes only its own outputs, so the results do not depend on the
number of threads or their order.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

__all__ = ["array_threads", "thread_map"]

T = TypeVar("T")
R = TypeVar("R")

#: At most this many threads: the relighting's arrays are memory-bound, and two threads already
#: saturate the reference machine's memory bandwidth.
MAX_ARRAY_THREADS = 4


def array_threads() -> int:
    """Threads for array work: the cores this process may run on, at most
    :data:`MAX_ARRAY_THREADS`."""
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cores = os.cpu_count() or 1
    return max(1, min(cores, MAX_ARRAY_THREADS))


def thread_map(fn: Callable[[T], R], items: Iterable[T]) -> list[R]:
    """``[fn(item) for item in items]``, run in :func:`array_threads` threads (in this thread
    when one suffices); an exception of *fn* is raised here."""
    items = list(items)
    threads = min(array_threads(), len(items))
    if threads <= 1:
        return [fn(item) for item in items]
    with ThreadPoolExecutor(max_workers=threads, thread_name_prefix="spectrinsic-array") as pool:
        return list(pool.map(fn, items))
