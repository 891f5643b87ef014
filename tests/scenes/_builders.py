"""Run the bpy builder scripts beside this module (``make_*.py``): each in its own subprocess,
as bpy's state is global to the process.

A helper module, not a conftest: its function takes arguments (script, target, options), and
tests/test_test_layout.py checks only ``test_*.py`` files.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

__all__ = ["build_blend"]

HERE = Path(__file__).resolve().parent
#: A builder writes at most 14 small files; bpy's start-up is most of it (about 2 s idle).
TIMEOUT_S = 180


def build_blend(script: str, target: Path, *options: str) -> Path:
    """*target* (a ``.blend`` or a folder of them) written by ``tests/scenes/<script>`` run as
    ``python -P SCRIPT -- TARGET OPTIONS...``; skipped, saying why, where bpy is missing."""
    pytest.importorskip("bpy", reason="the optional 'blender' extra (bpy) is not installed")
    proc = subprocess.run(
        [sys.executable, "-P", str(HERE / script), "--", str(target), *options],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
    )
    assert proc.returncode == 0 and target.exists(), proc.stderr[-2000:]
    return target
