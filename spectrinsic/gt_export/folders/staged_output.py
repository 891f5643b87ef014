"""An output folder written all at once: a run that fails leaves ``--out`` as it was.

:func:`staged_output` holds ``--out`` as :func:`spectrinsic.gt_export.folders.outfolder.output_folder`
does (checked, locked, its files recorded as spectrinsic's) and hands the run a temporary
folder inside it (``.spectrinsic-tmp-stage-<pid>``, which the output rule ignores). Only when
the run's block ends without an error are the staged files moved into place, one
``os.replace`` each; on an error (a refused sample, Ctrl-C) the temporary folder is removed,
and a folder the run created itself is removed again, so nothing of the failed run is left.
"""

from __future__ import annotations

import contextlib
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

from .outfolder import LOCK_NAME, OUTPUT_MARKER, output_folder

__all__ = ["STAGE_PREFIX", "staged_output"]

#: Prefix of the staging folder inside ``--out`` (spectrinsic's temporaries' prefix).
STAGE_PREFIX = ".spectrinsic-tmp-stage-"


def _move_into(stage: Path, root: Path) -> None:
    """Move every file below *stage* to the same relative path below *root*."""
    for dirpath, _dirnames, filenames in os.walk(stage):
        here = Path(dirpath)
        target_dir = root / here.relative_to(stage)
        target_dir.mkdir(parents=True, exist_ok=True)
        for name in filenames:
            os.replace(here / name, target_dir / name)


def _remove_created(root: Path) -> None:
    """Remove *root*, made by this run, if it holds only the run's lock and marker."""
    entries = {p.name for p in root.iterdir()} if root.is_dir() else set()
    if entries <= {LOCK_NAME, OUTPUT_MARKER}:
        for name in entries:
            (root / name).unlink(missing_ok=True)
        with contextlib.suppress(OSError):
            root.rmdir()


@contextlib.contextmanager
def staged_output(root: Path, option: str = "--out") -> Iterator[Path]:
    """Hold *root* as the run's output folder and yield a staging folder to write into.

    The staged files land in *root* only when the block ends normally (module docstring).
    """
    existed = root.exists()
    try:
        with output_folder(root, option):
            stage = root / f"{STAGE_PREFIX}{os.getpid()}"
            shutil.rmtree(stage, ignore_errors=True)  # a killed run's with this pid
            stage.mkdir()
            try:
                yield stage
                _move_into(stage, root)
            finally:
                shutil.rmtree(stage, ignore_errors=True)
    except BaseException:
        if not existed:
            _remove_created(root)
        raise
