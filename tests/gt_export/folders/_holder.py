"""Another process holding an output folder's lock (:func:`folder_lock`), for the tests of what
a second run is told (tests/gt_export/folders/test_outfolder.py, relight's refusal).

A helper module, not a conftest: its function takes the folder, and tests/test_test_layout.py
checks only ``test_*.py`` files.
"""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["HOLDER_START_S", "held_lock"]

#: How long the holding process may take to start (and to end once released), in seconds.
HOLDER_START_S = 60.0

_HOLDER = (
    "import sys; from pathlib import Path; from spectrinsic.gt_export.folders.outfolder import "
    "folder_lock\nwith folder_lock(Path(sys.argv[1])):\n    print('held', flush=True); "
    "sys.stdin.read()\n"
)


@contextmanager
def held_lock(folder: Path) -> Iterator[subprocess.Popen]:
    """A second process holding *folder*'s lock while the ``with`` block runs (it takes the lock
    before the block starts, and releases it, ending with status 0, when the block ends)."""
    proc = subprocess.Popen(
        [sys.executable, "-P", "-c", _HOLDER, str(folder)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + HOLDER_START_S
        assert proc.stdout is not None and proc.stdout.readline().strip() == "held"
        assert time.monotonic() < deadline
        yield proc
    finally:
        assert proc.stdin is not None
        proc.stdin.close()
        assert proc.wait(timeout=HOLDER_START_S) == 0
