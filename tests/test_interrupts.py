"""Ctrl-C delivered to Python, not to a library's own SIGINT handler (spectrinsic.interrupts).

Each check runs in a fresh interpreter: the block only covers threads started inside it, and a
test process (pytest-xdist's I/O threads) has threads of its own that could take the signal.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

#: Every check starts from Python's own Ctrl-C handler: a test process may have been started
#: with SIGINT ignored (a background job of a script), which its children inherit and which the
#: block then keeps (see :func:`test_an_inherited_ignored_sigint_stays_ignored`).
PRELUDE = """
import os, signal, time
signal.signal(signal.SIGINT, signal.default_int_handler)
from spectrinsic.interrupts import interrupts_reach_python, raise_if_requested, requested
def wait_for(predicate):
    deadline = time.monotonic() + 20
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.01)
"""


def _run(body: str) -> str:
    script = PRELUDE + textwrap.dedent(body)
    run = subprocess.run(
        [sys.executable, "-P", "-c", script], capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stderr
    return run.stdout.strip()


def test_sigint_becomes_a_recorded_keyboard_interrupt_and_the_mask_is_restored():
    out = _run("""
        before = signal.pthread_sigmask(signal.SIG_BLOCK, [])
        try:
            with interrupts_reach_python():
                assert signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, [])
                os.kill(os.getpid(), signal.SIGINT)
                wait_for(lambda: False)  # the watcher thread raises it in this thread
            print("not interrupted")
        except KeyboardInterrupt:
            print("interrupted")
        assert signal.pthread_sigmask(signal.SIG_BLOCK, []) == before
        assert not requested()  # the record belongs to the block
    """)
    assert out == "interrupted"


def test_a_library_sigint_handler_never_sees_the_signal():
    """Mitsuba installs its own C-level SIGINT handler during mi.render. One installed inside
    the block (through libc, as Mitsuba does) is never run: the blocked signal goes to the
    watcher, which records it and interrupts the main thread."""
    out = _run("""
        import ctypes
        libc = ctypes.CDLL(None)
        HANDLER = ctypes.CFUNCTYPE(None, ctypes.c_int)
        seen = []
        library_handler = HANDLER(lambda signum: seen.append(signum))
        libc.signal.restype = ctypes.c_void_p
        libc.signal.argtypes = [ctypes.c_int, ctypes.c_void_p]
        interrupted = False
        with interrupts_reach_python():
            previous = libc.signal(signal.SIGINT, ctypes.cast(library_handler, ctypes.c_void_p))
            try:
                os.kill(os.getpid(), signal.SIGINT)
                wait_for(requested)
                time.sleep(0.2)
            except KeyboardInterrupt:
                interrupted = True
            finally:
                libc.signal(signal.SIGINT, previous)
            print(requested(), interrupted, seen)
    """)
    assert out == "True True []"


def test_a_swallowed_interrupt_is_still_raised_at_the_next_check():
    """A library that catches the KeyboardInterrupt (Dr.Jit re-raises it as RuntimeError)
    cannot lose it: the next raise_if_requested() raises it again."""
    out = _run("""
        with interrupts_reach_python():
            try:
                os.kill(os.getpid(), signal.SIGINT)
                wait_for(lambda: False)
            except KeyboardInterrupt:
                pass  # swallowed, as a library would
            assert requested()
            try:
                raise_if_requested()
                print("lost")
            except KeyboardInterrupt:
                print("raised again")
    """)
    assert out == "raised again"


@pytest.mark.parametrize("where", ["before", "inside"])
def test_threads_started_inside_the_block_inherit_the_block(where):
    """Dr.Jit's, OIDN's and tqdm's pools start inside the block: their masks hold SIGINT."""
    out = _run(f"""
        import threading
        masks = []
        def record():
            masks.append(signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, []))
        if "{where}" == "before":
            t = threading.Thread(target=record); t.start(); t.join()
        with interrupts_reach_python():
            if "{where}" == "inside":
                t = threading.Thread(target=record); t.start(); t.join()
        print(masks[0])
    """)
    assert out == ("True" if where == "inside" else "False")


def test_an_inherited_ignored_sigint_stays_ignored():
    """A process whose parent set SIGINT to ignored (``nohup``, ``cmd &`` in a script) keeps
    ignoring it inside the block: no record, no interrupt, the disposition untouched."""
    out = _run("""
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        with interrupts_reach_python():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.3)
            print(requested(), signal.getsignal(signal.SIGINT) is signal.SIG_IGN)
    """)
    assert out == "False True"
