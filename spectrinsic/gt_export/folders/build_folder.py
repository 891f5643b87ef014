"""What spectrinsic owns in a dataset folder: the build-folder marker and its temporaries.

A dataset folder knows it is one: the build writes :data:`MARKER_NAME` (the config hash of the
dataset) before its first sample, and ``manifest.json`` after its last. spectrinsic only ever
removes its own temporaries, named :data:`~spectrinsic.file_writes.TMP_PREFIX` ``<id>``, inside
a folder it recognises as a dataset; which sample folders it may replace is
:mod:`spectrinsic.gt_export.sample.integrity`'s.
"""

from __future__ import annotations

import contextlib
import json
import shutil
from collections.abc import Iterator
from pathlib import Path

from ...errors import DatasetError, WriteError
from ...file_writes import TMP_PREFIX, write_text_file
from ..sample import MANIFEST_NAME
from .outfolder import LOCK_NAME, check_out_folder

__all__ = [
    "MARKER_NAME",
    "dataset_config_hash",
    "check_build_folder",
    "write_marker",
    "remove_owned_temporaries",
    "unmarked_on_error",
]

#: Written first into every dataset folder: ``{"spectrinsic_dataset": 1, "config_hash": ...}``.
MARKER_NAME = ".spectrinsic-dataset"


def dataset_config_hash(root: Path) -> str | None:
    """The config hash *root* was built with (marker first, then manifest), or ``None`` if
    *root* is not a spectrinsic dataset folder."""
    for name, key in ((MARKER_NAME, "spectrinsic_dataset"), (MANIFEST_NAME, "format_version")):
        try:
            record = json.loads((root / name).read_text(encoding="utf-8"))
        except (OSError, ValueError, RecursionError):
            continue
        if (
            isinstance(record, dict)
            and key in record
            and isinstance(record.get("config_hash"), str)
        ):
            return record["config_hash"]
    return None


def check_build_folder(root: Path, config_hash: str, *, rebuild: bool) -> str | None:
    """Check that a build with *config_hash* may write into *root*; return the hash the folder
    was built with before (``None``: new or empty folder).

    Raises
    ------
    DatasetError
        *root* breaks the rule of every writing verb
        (:func:`spectrinsic.gt_export.folders.outfolder.check_out_folder`: a file, inside a dataset,
        locked by another run, non-empty and not a spectrinsic dataset), or it was built with
        another config and *rebuild* is false.
    """
    if check_out_folder(
        root,
        own=lambda p: dataset_config_hash(p) is not None,
        what=f"a spectrinsic dataset (no {MARKER_NAME} or {MANIFEST_NAME})",
    ):
        return None
    previous = dataset_config_hash(root)
    if previous is not None and previous != config_hash and not rebuild:
        raise DatasetError(
            f"--out {str(root)!r} was built with another config (hash {previous[:12]}, this run "
            f"{config_hash[:12]}); pass --rebuild to rebuild it, or choose another folder"
        )
    return previous


def write_marker(root: Path, config_hash: str) -> None:
    """Create *root* if needed and record that it is a dataset built with *config_hash*."""
    try:
        root.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WriteError(f"--out {str(root)!r}: cannot create the folder ({exc.strerror})") from exc
    record = {"spectrinsic_dataset": 1, "config_hash": config_hash}
    write_text_file(root / MARKER_NAME, json.dumps(record, allow_nan=False) + "\n")


def remove_owned_temporaries(root: Path) -> list[Path]:
    """Delete spectrinsic's temporaries (:data:`TMP_PREFIX`) in a dataset folder; return them.

    Nothing is removed from a folder without the dataset marker or manifest. Call it only when
    no writer of this build is still running.
    """
    if not root.is_dir() or dataset_config_hash(root) is None:
        return []
    stale = sorted(root.glob(f"{TMP_PREFIX}*"))
    for path in stale:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink(missing_ok=True)
    return stale


@contextlib.contextmanager
def unmarked_on_error(out: Path, new: bool) -> Iterator[None]:
    """A build into a new (or empty) folder that stops with an error (a full disk, a refusal)
    before any sample is in place leaves no dataset marker, so the folder is left as it was
    (:func:`~spectrinsic.gt_export.folders.outfolder.folder_lock` then removes a folder it made)."""
    try:
        yield
    except Exception:
        if new and out.is_dir() and {p.name for p in out.iterdir()} <= {MARKER_NAME, LOCK_NAME}:
            (out / MARKER_NAME).unlink(missing_ok=True)
        raise
