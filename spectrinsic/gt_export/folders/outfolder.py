"""Which folders a spectrinsic verb may write into, and the lock that keeps two runs apart.

Every verb that writes (``dataset``, ``export``, ``render``, ``evaluate``, ``study``) follows
one rule for its ``--out`` (:func:`check_out_folder`): a new folder, an empty one, or one of
spectrinsic's own of the same kind; never a file, never a folder inside a dataset, and never
one another spectrinsic run holds. Nothing the program did not write is replaced.
A folder holding a symbolic link (to a file or a folder, at any depth) is refused: nothing is
ever written through a link, so nothing lands outside ``--out``.

* A dataset knows itself by its marker (:mod:`spectrinsic.gt_export.folders.build_folder`), a shard
  export by its index (:mod:`spectrinsic.gt_export.dataset.shards`).
* ``render``, ``evaluate`` and ``study`` know their folders by :data:`OUTPUT_MARKER`, which
  lists every file they wrote there (:func:`output_folder`). Such a folder holding a file the
  marker does not list is refused, so a user's file in it can never be overwritten.

The lock (:func:`folder_lock`) is an advisory ``fcntl.flock`` on :data:`LOCK_NAME` inside the
folder, holding the holder's pid, host and start time for the message a second run prints. The
kernel drops it when the holder exits, however it exits, so a lock file left by a killed run is
harmless; a run that ends normally removes it.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import socket
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from ...errors import DatasetError, FolderLockedError, WriteError
from ...file_writes import TMP_PREFIX, write_text_file

__all__ = [
    "LOCK_NAME",
    "OUTPUT_MARKER",
    "require_folder_path",
    "check_out_folder",
    "check_output_folder",
    "check_unlocked",
    "folder_lock",
    "output_folder",
]

#: Lock file of a folder a spectrinsic run writes into (kept; only its ``flock`` matters).
LOCK_NAME = ".spectrinsic-lock"
#: Marker of a ``render``/``evaluate``/``study`` output folder: the files spectrinsic wrote.
OUTPUT_MARKER = ".spectrinsic-output"
#: Files whose presence makes a folder a dataset or a shard export (a folder of spectrinsic's).
_DATASET_MARKERS = (
    (".spectrinsic-dataset", "spectrinsic_dataset"),
    ("manifest.json", "format_version"),
)
_SHARD_INDEX = ("shards.json", "format")
#: Folders whose lock this process holds: checks made under the lock must not probe it (a
#: second ``flock`` on a new descriptor conflicts with the process's own lock).
_HELD_HERE: set[Path] = set()


def require_folder_path(root: Path, option: str = "--out") -> None:
    """Raise a one-line error if *root* is a file or lies below one (so no folder can be made)."""
    for parent in (root, *root.parents):
        if parent.is_dir():
            return
        if parent.exists() or parent.is_symlink():
            what = "is a file" if parent == root else f"lies below the file {str(parent)!r}"
            raise DatasetError(f"{option} {str(root)!r} {what}; expected a folder")


def _json_record(path: Path, key: str) -> dict[str, object] | None:
    """The JSON object in *path* if it has *key*, else ``None`` (absent, unreadable, other)."""
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    return record if isinstance(record, dict) and key in record else None


def _is_dataset(folder: Path) -> bool:
    return any(_json_record(folder / name, key) is not None for name, key in _DATASET_MARKERS)


def _is_own_folder(folder: Path) -> bool:
    """A dataset, a shard export or an output folder of spectrinsic's."""
    return (
        _is_dataset(folder)
        or _json_record(folder / _SHARD_INDEX[0], _SHARD_INDEX[1]) is not None
        or _json_record(folder / OUTPUT_MARKER, "spectrinsic_output") is not None
    )


def _refuse_inside_dataset(root: Path, option: str) -> None:
    """A folder inside a dataset would become part of it (a ``meta.json`` reads as a sample).
    ``..`` is resolved first, as the kernel resolves it: ``ds/../o`` lies beside ``ds``."""
    for parent in root.resolve().parents:
        if parent.is_dir() and _is_dataset(parent):
            raise DatasetError(
                f"{option} {str(root)!r} lies inside the dataset folder {str(parent)!r}; "
                "choose a folder outside it"
            )


def _require_writable(root: Path, option: str) -> None:
    """The folder (or the nearest existing folder above it) must be writable by this user."""
    existing = next(p for p in (root, *root.parents) if p.is_dir())
    probe = existing / f"{TMP_PREFIX}probe-{os.getpid()}"
    try:  # os.access says yes to root even on a read-only mount; only a write answers truly
        probe.mkdir()
        probe.rmdir()
    except OSError as exc:
        raise WriteError(
            f"{option} {str(root)!r}: {str(existing)!r} is not writable ({exc.strerror or exc})"
        ) from None


def _entries(root: Path) -> list[Path]:
    """What *root* holds for the "new or empty" rule: not the lock, nor a write probe that a
    run killed between making and removing it left behind (:func:`_stale_probe`)."""
    return sorted(p for p in root.iterdir() if p.name != LOCK_NAME and not _stale_probe(p))


def _stale_probe(path: Path) -> bool:
    """An empty folder named as :func:`_require_writable`'s probe (``<prefix>probe-<pid>``)."""
    return (
        path.name.startswith(f"{TMP_PREFIX}probe-")
        and path.is_dir()
        and not path.is_symlink()
        and not any(path.iterdir())
    )


def check_out_folder(
    root: Path, *, own: Callable[[Path], bool], what: str, option: str = "--out"
) -> bool:
    """Check that a verb may write into *root*; return True if it is new or empty.

    The one rule of every writing verb: *root* is a folder path (not a file, not below one),
    not inside a dataset, writable, held by no other run, and either new, empty, or its own
    (*own* returns True; *what* names that kind of folder in the message).

    Raises
    ------
    DatasetError
        One line naming *option*, *root* and what was expected.
    """
    require_folder_path(root, option)
    if root.is_symlink():
        raise DatasetError(
            f"{option} {str(root)!r} is a symbolic link; spectrinsic never writes through a "
            "link: name the folder it points to, or choose another folder"
        )
    _refuse_inside_dataset(root, option)
    check_unlocked(root, option)
    if not root.is_dir() or not _entries(root):
        _require_writable(root, option)
        return True
    if not own(root) and _is_dataset(root):  # spectrinsic wrote it, but as another kind
        raise DatasetError(
            f"{option} {str(root)!r} is a spectrinsic dataset, not {what}; choose a new or "
            "empty folder (this verb never writes into a dataset)"
        )
    if not own(root):
        raise DatasetError(
            f"{option} {str(root)!r} is not empty and is not {what}, so it "
            "holds files spectrinsic did not write; choose a new or empty folder"
        )
    _refuse_links(root, option)
    _require_writable(root, option)
    return False


def _refuse_links(root: Path, option: str) -> None:
    """A folder a run writes into holds no symbolic link, to a file or a folder, at any depth:
    spectrinsic never writes through one (a rerun would otherwise write a ``meta.json``, a
    ``REPORT.md`` or a whole ``gallery-pixels/`` into wherever the link points, outside
    *root*). spectrinsic writes no links itself, so one is the user's: refused in one line."""
    for dirpath, dirnames, filenames in os.walk(root):  # links are listed, never followed
        here = Path(dirpath)
        for name in sorted(dirnames + filenames):
            if (here / name).is_symlink():
                rel = (here / name).relative_to(root).as_posix()
                raise DatasetError(
                    f"{option} {str(root)!r} holds {rel!r}, a symbolic link; spectrinsic never "
                    "writes through a link in its output folder: remove it or choose another folder"
                )


# ----------------------------------------------------------------------------------------------
# The lock


def _holder() -> dict[str, object]:
    return {
        "pid": os.getpid(),
        "host": socket.gethostname(),
        "started": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()),
    }


def _locked_message(root: Path, fd: int, option: str) -> str:
    try:
        holder = json.loads(os.pread(fd, 4096, 0).decode("utf-8"))
        who = f"pid {holder['pid']} on {holder['host']}, started {holder['started']}"
    except (OSError, ValueError, KeyError, TypeError, RecursionError):
        who = "its details are not written yet"
    return (
        f"{option} {str(root)!r} is in use by another spectrinsic run ({who}); wait for it "
        "to finish or choose another folder"
    )


def check_unlocked(root: Path, option: str = "--out") -> None:
    """Raise :class:`FolderLockedError` if another run holds *root*'s lock (writes nothing)."""
    path = root / LOCK_NAME
    if not path.is_file() or root.resolve() in _HELD_HERE:
        return
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        raise FolderLockedError(_locked_message(root, fd, option)) from None
    finally:
        os.close(fd)  # also releases the probe's shared lock


def _acquire(root: Path, option: str) -> int:
    """Open and ``flock`` *root*'s lock file; return the descriptor holding the lock."""
    path = root / LOCK_NAME
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            message = _locked_message(root, fd, option)
            os.close(fd)
            raise FolderLockedError(message) from None
        try:  # the holder before us may have removed the file between our open and flock
            same = os.path.samestat(os.fstat(fd), os.stat(path))
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)


@contextlib.contextmanager
def folder_lock(root: Path, option: str = "--out") -> Iterator[None]:
    """Hold *root*'s advisory lock (creating *root*) for the block; the lock file is removed
    when the block ends, and so are the folders it created if they are still empty.

    Raises
    ------
    FolderLockedError
        Another run holds it; the message names its pid, host and start time.
    """
    made = [p for p in (root, *root.parents) if not p.exists()]  # deepest first
    try:
        root.mkdir(parents=True, exist_ok=True)
        fd = _acquire(root, option)
    except OSError as exc:
        raise WriteError(
            f"{option} {str(root)!r}: cannot create the folder's lock ({exc.strerror or exc})"
        ) from None
    held = root.resolve()
    try:
        os.ftruncate(fd, 0)
        with contextlib.suppress(OSError):  # a full disk: the lock holds, without its details
            os.pwrite(fd, (json.dumps(_holder(), allow_nan=False) + "\n").encode("utf-8"), 0)
        _HELD_HERE.add(held)
        yield
    finally:
        _HELD_HERE.discard(held)
        with contextlib.suppress(OSError):
            (root / LOCK_NAME).unlink()  # still locked: a run waiting on this file retries
        os.close(fd)
        for folder in made:  # a run refused under the lock leaves no empty folder behind
            with contextlib.suppress(OSError):
                folder.rmdir()


# ----------------------------------------------------------------------------------------------
# Output folders of render, evaluate and study


def _files_below(root: Path) -> set[str]:
    """Relative paths of the files below *root*, leaving out spectrinsic's own bookkeeping and
    any nested folder of spectrinsic's (a dataset, a shard export, another output folder)."""
    found: set[str] = set()
    for dirpath, dirnames, filenames in os.walk(root):
        here = Path(dirpath)
        dirnames[:] = sorted(
            d for d in dirnames if not d.startswith(TMP_PREFIX) and not _is_own_folder(here / d)
        )
        for name in filenames:
            if name in (LOCK_NAME, OUTPUT_MARKER) or name.startswith(TMP_PREFIX):
                continue
            found.add((here / name).relative_to(root).as_posix())
    return found


def _marker(root: Path) -> dict[str, object] | None:
    record = _json_record(root / OUTPUT_MARKER, "spectrinsic_output")
    if record is None or not isinstance(record.get("files"), list):
        return None
    return record


def _foreign(root: Path) -> tuple[list[str], bool]:
    """Files below *root* the marker does not list, and whether a run died while writing."""
    record = _marker(root) or {}
    files = record.get("files")
    listed = {f for f in files if isinstance(f, str)} if isinstance(files, list) else set()
    return sorted(_files_below(root) - listed), bool(record.get("writing"))


def _is_output_folder(root: Path) -> bool:
    return _marker(root) is not None and not _foreign(root)[0]


def check_output_folder(root: Path, option: str = "--out") -> None:
    """Check a ``render``/``evaluate``/``study`` output folder before any work (writes nothing).

    Raises
    ------
    DatasetError
        *root* breaks :func:`check_out_folder`'s rule; the message names the first file
        spectrinsic did not write.
    """
    # own: the marker's, or holding only other folders of spectrinsic's (results/evaluation)
    if check_out_folder(
        root,
        own=lambda p: _marker(p) is not None or not _files_below(p),
        option=option,
        what=f"a spectrinsic output folder (no {OUTPUT_MARKER})",
    ):
        return
    foreign, died = _foreign(root)
    if foreign:
        more = f" and {len(foreign) - 1} more" if len(foreign) > 1 else ""
        why = (
            "an earlier run was killed before it recorded its files"
            if died
            else "spectrinsic did not write it"
        )
        raise DatasetError(
            f"{option} {str(root)!r} holds {foreign[0]!r}{more}, which is not "
            f"listed in {OUTPUT_MARKER} ({why}); move it away or choose another folder"
        )


def _write_marker(root: Path, files: set[str], writing: dict[str, object] | None) -> None:
    record = {"spectrinsic_output": 1, "files": sorted(files), "writing": writing}
    write_text_file(root / OUTPUT_MARKER, json.dumps(record, indent=1, allow_nan=False) + "\n")


@contextlib.contextmanager
def output_folder(root: Path, option: str = "--out") -> Iterator[Path]:
    """Hold *root* as this run's output folder: checked, locked, and its files recorded.

    The marker says "writing" while the block runs; whatever way the block ends (an error, a
    Ctrl-C), the files it wrote are then listed as spectrinsic's. Only a killed run leaves the
    "writing" state, and its unrecorded files make the next run refuse the folder.
    """
    check_output_folder(root, option)
    with folder_lock(root, option):
        check_output_folder(root, option)  # again under the lock: another run may have written
        listed = _files_below(root)
        _write_marker(root, listed, _holder())
        try:
            yield root
        except BaseException:
            # the block's own error is the one to report (a full disk names its file there):
            # a marker that cannot be written now keeps "writing", as after a kill
            with contextlib.suppress(WriteError):
                _write_marker(root, listed | _files_below(root), None)
            raise
        _write_marker(root, listed | _files_below(root), None)
