"""What spectrinsic owns in a dataset folder, and whether a sample is what it claims to be.

A dataset folder knows it is one: the build writes :data:`MARKER_NAME` (the config hash of the
dataset) before its first sample, and ``manifest.json`` after its last. spectrinsic only ever
removes or replaces

* its own temporaries, named :data:`TMP_PREFIX` ``<id>``, inside a folder it recognises as a
  dataset;
* sample folders whose ``meta.json`` it wrote and that hold no file that ``meta.json`` does not
  list (so a user's notes inside a sample folder stop the build instead of vanishing).

A sample is *intact* when its ``meta.json`` is valid, matches its own seal (a hash of its
content, :func:`~spectrinsic.gt_export.sample.meta_seal`), has the expected config hash, and
every file it lists lies inside the sample folder and matches the SHA-256 recorded there. Only
intact samples are resumed; any other is rendered again, with a warning that says why.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import shutil
from collections.abc import Iterator
from pathlib import Path, PurePosixPath

from ...errors import DatasetError, DiskFullError, SampleMetaError, SpectrinsicError, WriteError
from ...file_writes import NO_SPACE, disk_full, write_text_file
from ..folders.outfolder import LOCK_NAME, check_out_folder, require_folder_path
from . import FORMAT_VERSION, MANIFEST_NAME, META_NAME, TMP_PREFIX, file_sha256
from .meta import owned_files, read_meta

__all__ = [
    "MARKER_NAME",
    "NO_SPACE",
    "disk_full",
    "guarded_write",
    "sample_problem",
    "replaceable_sample",
    "remove_sample",
    "dataset_config_hash",
    "require_folder_path",
    "check_build_folder",
    "write_marker",
    "remove_owned_temporaries",
    "unmarked_on_error",
]

#: Written first into every dataset folder: ``{"spectrinsic_dataset": 1, "config_hash": ...}``.
MARKER_NAME = ".spectrinsic-dataset"


@contextlib.contextmanager
def guarded_write(path: str | os.PathLike[str]) -> Iterator[None]:
    """Turn a failure while making *path* (a folder) into a one-line error naming *path*, and
    remove what was written of it (a full disk leaves no partial or zero-byte file behind).
    Files are written with :func:`spectrinsic.file_writes.replacing`, never in place.

    ``write()`` failures (a full disk) carry no file name of their own, so without this the
    message would not say which file could not be written. An ``OSError`` becomes a
    :class:`~spectrinsic.errors.WriteError`, a full disk (also as a C library's
    ``RuntimeError``, :func:`disk_full`) a :class:`~spectrinsic.errors.DiskFullError`.
    """
    try:
        yield
    except (OSError, RuntimeError) as exc:
        if isinstance(exc, SpectrinsicError) or not (isinstance(exc, OSError) or disk_full(exc)):
            raise  # already one line (a nested guard), or not a write failure
        target = Path(path)
        if disk_full(exc) and target.is_file() and not target.is_symlink():
            target.unlink(missing_ok=True)  # the file this block was writing: partial at best
        reason = os.strerror(errno.ENOSPC) if not isinstance(exc, OSError) else exc.strerror
        cls = DiskFullError if disk_full(exc) else WriteError
        raise cls(f"cannot write {str(path)!r}: {reason or exc}") from exc


def sample_problem(folder: str | os.PathLike[str], config_hash: str) -> str | None:
    """Why the sample in *folder* cannot be resumed, or ``None`` if it is complete and intact:
    its ``meta.json`` valid and matching its seal (:func:`~spectrinsic.gt_export.sample.meta.read_meta`),
    written in this format with *config_hash*, and every file it lists matching its SHA-256."""
    folder = Path(folder)
    if not folder.is_dir():
        return "absent"
    if not (folder / META_NAME).is_file():
        return f"{META_NAME} is missing"
    try:
        meta = read_meta(folder)
    except SampleMetaError as exc:
        return str(exc)
    if meta.format_version != FORMAT_VERSION:
        return f"written in format {meta.format_version}; this version writes {FORMAT_VERSION}"
    if meta.config_hash != config_hash:
        return "built with another config"
    for rel in meta.files:
        path = folder / rel
        if not path.is_file():
            return f"file {rel!r} is missing"
        if file_sha256(path) != meta.hashes[rel]:
            return f"file {rel!r} does not match its SHA-256 in {META_NAME}"
    return None


def replaceable_sample(folder: Path) -> None:
    """Check that *folder* may be replaced: absent, or a sample spectrinsic wrote holding only
    files its ``meta.json`` lists.

    Raises
    ------
    DatasetError
        One line naming the folder or the file that is not spectrinsic's.
    """
    if not folder.exists() and not folder.is_symlink():
        return
    if folder.is_symlink() or not folder.is_dir():
        raise DatasetError(
            f"{str(folder)!r} is in the way of a sample folder and is not one spectrinsic wrote; "
            "move it away or choose another --out"
        )
    owned = owned_files(folder)
    if owned is None:
        raise DatasetError(
            f"{str(folder)!r} has the name of a sample but no valid spectrinsic {META_NAME}; "
            "move it away or choose another --out"
        )
    listed = {PurePosixPath(f) for f in owned} | {PurePosixPath(META_NAME)}
    for path in sorted(folder.rglob("*")):
        rel = PurePosixPath(path.relative_to(folder).as_posix())
        if (path.is_symlink() or not path.is_dir()) and rel not in listed:
            raise DatasetError(
                f"{str(path)!r} was not written by spectrinsic, so its sample folder is not "
                "replaced; move the file away to rebuild the sample"
            )


def remove_sample(folder: Path) -> None:
    """Delete a sample folder after :func:`replaceable_sample` allowed it."""
    replaceable_sample(folder)
    if folder.exists():
        shutil.rmtree(folder)


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
