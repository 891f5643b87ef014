"""An output folder written all at once: a run that fails leaves ``--out`` as it was.

:func:`staged_output` holds ``--out`` as :func:`spectrinsic.gt_export.folders.outfolder.output_folder`
does (checked, locked, its files recorded as spectrinsic's) and hands the run a temporary
folder inside it (``.spectrinsic-tmp-stage-<pid>``, which the output rule ignores). Only when
the run's block ends without an error are the staged files moved into place, one
``os.replace`` each; on an error (a refused sample, Ctrl-C) the temporary folder is removed,
and a folder the run created itself is removed again, so nothing of the failed run is left.
The staging folders of runs that were killed (``kill -9``, a power cut) are swept by the next
run, under the folder's lock (no other run can be using them then).

A full disk is reported in one line naming the file that could not be written: writers that
name their file themselves (:func:`~spectrinsic.gt_export.file_writes.guarded_write`) do; for
the others (a figure, a CSV table), the newest file in the staging folder is the one that was
being written when the disk filled.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

from ...errors import DiskFullError, SpectrinsicError, WriteError
from ...file_writes import disk_full, guarded_write, refuse_link
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
            refuse_link(target_dir / name)  # a link planted in --out while the run ran
            os.replace(here / name, target_dir / name)


def _newest_file(stage: Path) -> Path | None:
    """The most recently modified file below *stage* (the one being written), if any."""
    files = [p for p in stage.rglob("*") if p.is_file() and not p.is_symlink()]
    return max(files, key=lambda p: p.stat().st_mtime_ns, default=None)


def _write_error(exc: BaseException, stage: Path, root: Path) -> WriteError | None:
    """A one-line error naming the file in *root* (not in *stage*) for a failed write."""
    if isinstance(exc, WriteError):  # named by its writer: the name it will have in --out
        return type(exc)(str(exc).replace(str(stage), str(root)))
    if isinstance(exc, SpectrinsicError) or not disk_full(exc):
        return None
    newest = _newest_file(stage)
    name = root / newest.relative_to(stage) if newest is not None else root
    return DiskFullError(f"cannot write {str(name)!r}: {os.strerror(errno.ENOSPC)}")


def _sweep_stages(root: Path) -> None:
    """Remove every staging folder in *root*: under the lock they are killed runs' own."""
    for path in root.glob(f"{STAGE_PREFIX}*"):
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)


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
    made = [p for p in (root, *root.parents) if not p.exists()]  # deepest first
    try:
        with output_folder(root, option):
            _sweep_stages(root)  # killed runs' (the lock is ours: nobody else's is in use)
            stage = root / f"{STAGE_PREFIX}{os.getpid()}"
            try:
                with guarded_write(stage):
                    stage.mkdir()
                yield stage
                _move_into(stage, root)
            except Exception as exc:
                named = _write_error(exc, stage, root)
                if named is None:
                    raise
                raise named from exc
            finally:
                shutil.rmtree(stage, ignore_errors=True)
    except BaseException:
        if made:
            _remove_created(root)
            for folder in made[1:]:  # the parents made for it, if nothing else is in them
                with contextlib.suppress(OSError):
                    folder.rmdir()
        raise
