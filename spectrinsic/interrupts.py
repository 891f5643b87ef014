"""Ctrl-C that reaches Python while Mitsuba renders.

Mitsuba's Python binding of ``mi.render`` installs its own SIGINT handler for the length of the
call ("Received interrupt signal, winding down..") and restores the previous one afterwards. An
interrupt that lands mid-render is consumed there: the render returns early or fails, and Python
never sees a ``KeyboardInterrupt``, so a serial build either ran to the end (rc 0) or reported one
failed sample and went on (rc 1).

:func:`interrupts_reach_python` takes SIGINT away from signal *handlers* altogether: the calling
(main) thread blocks it, so every thread started afterwards (Dr.Jit's and OIDN's pools, tqdm's
monitor) inherits the block, and one watcher thread receives it synchronously with
:func:`signal.sigwait`. A handler installed by a library is never run for a blocked signal; the
watcher turns each SIGINT into :func:`_thread.interrupt_main`, which raises ``KeyboardInterrupt``
in the main thread as soon as it runs Python again, and records it (:func:`requested`).

The record is what makes the stop certain: Dr.Jit's ``custom`` operation, through which
``mi.render`` runs, re-raises a ``KeyboardInterrupt`` from inside a render as a ``RuntimeError``,
and a task runner that survives failed items would then go on. Long loops call
:func:`raise_if_requested` between their steps (passes, samples), so a build stops within one
render pass of the Ctrl-C (a pass of a default sample takes well under a second).

SIGTERM (what ``timeout``, ``kill`` and batch schedulers send) is handled like Ctrl-C within
the block: a Python handler records it and raises ``KeyboardInterrupt``, so a run stopped that
way cleans up as after Ctrl-C (temporaries removed, completed work kept) and exits with status
143 (:func:`exit_status`). It is not blocked, so pool workers (started with ``spawn``, which
resets handlers) still die of it at once.

Child processes inherit the blocked mask (they are stopped by their parent, see
:mod:`spectrinsic.pipeline.executors`). Only POSIX systems have per-thread signal masks;
elsewhere the context manager does nothing.
"""

from __future__ import annotations

import _thread
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["interrupts_reach_python", "requested", "raise_if_requested", "exit_status"]

_SIGINT = {signal.SIGINT}
_watcher_lock = threading.Lock()
_watcher: threading.Thread | None = None
_requested = threading.Event()
#: The signal that stopped the run (SIGINT unless a SIGTERM came first).
_by: list[int] = [signal.SIGINT]


def exit_status() -> int:
    """The shell's exit status for a run stopped by the recorded signal: 130 (Ctrl-C), 143
    (SIGTERM)."""
    return 128 + int(_by[0])


def _on_sigterm(signum: int, _frame: object) -> None:
    """SIGTERM as Ctrl-C: recorded, then ``KeyboardInterrupt`` in the main thread."""
    if not _requested.is_set():
        _by[0] = signum
    _requested.set()
    raise KeyboardInterrupt


def requested() -> bool:
    """Whether a Ctrl-C arrived within the current :func:`interrupts_reach_python` block."""
    return _requested.is_set()


def raise_if_requested() -> None:
    """Raise ``KeyboardInterrupt`` if a Ctrl-C arrived, wherever Python saw it (or lost it)."""
    if _requested.is_set():
        raise KeyboardInterrupt


@contextmanager
def interrupts_reach_python() -> Iterator[None]:
    """Within the block, Ctrl-C raises ``KeyboardInterrupt`` in the main thread even while a
    library (Mitsuba) has its own SIGINT handler installed. Restores the signal mask on exit.

    Call it in the main thread before any thread is started, so that all of them inherit the
    block (threads started earlier could still receive SIGINT and run a library's handler).

    A process started with SIGINT ignored (``nohup``, a background job of a shell script) was
    asked by its parent to ignore Ctrl-C: the block then changes nothing, so it stays ignored.
    SIGTERM raises ``KeyboardInterrupt`` too (module notes), unless it was ignored at the start.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    term = signal.getsignal(signal.SIGTERM)
    if term is not signal.SIG_IGN:  # asked to ignore it (``nohup``): it stays ignored
        signal.signal(signal.SIGTERM, _on_sigterm)
    _requested.clear()
    _by[0] = signal.SIGINT
    try:
        if hasattr(signal, "pthread_sigmask") and signal.getsignal(signal.SIGINT) is not (
            signal.SIG_IGN
        ):
            previous = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGINT)
            try:
                _start_watcher()
                yield
            finally:
                signal.pthread_sigmask(signal.SIG_SETMASK, previous)
        else:
            yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL if term is None else term)
        _requested.clear()


def _start_watcher() -> None:
    """Start the one SIGINT watcher of this process (a daemon thread), if not yet running."""
    global _watcher
    with _watcher_lock:
        if _watcher is None:
            _watcher = threading.Thread(target=_watch, name="spectrinsic-sigint", daemon=True)
            _watcher.start()


def _watch() -> None:
    """Receive each SIGINT, record it and raise ``KeyboardInterrupt`` in the main thread."""
    while True:
        signal.sigwait(_SIGINT)
        _requested.set()
        _thread.interrupt_main(signal.SIGINT)
