"""Writing a file by renaming a finished temporary over its name: the one way spectrinsic writes.

Every file any verb writes is written to a temporary beside it (same folder, so the rename stays
on one file system), then ``os.replace``-d over its name (:func:`replacing`). So

* a *hard link* to an earlier run's file keeps its content: the rename gives the name a new
  inode, and the other link (the user's file, perhaps outside the output folder) is untouched;
* a *symbolic link* is never followed: the target name and its folder are checked for links
  when the temporary is made and again just before the rename (a link planted while a build
  runs is refused in one line, not written through and not replaced, since spectrinsic never
  replaces what it did not write);
* a failed write (a full disk, Ctrl-C) leaves the old file, or no file, never a partial one;
  it is reported in one line naming the file (:class:`~spectrinsic.errors.WriteError`,
  :class:`~spectrinsic.errors.DiskFullError`).

The temporary's name starts with :data:`TMP_PREFIX` (the prefix every sweep of spectrinsic's
temporaries knows) and ends with the target's own name, so writers that read the format from
the suffix (``savefig``, PIL) write the same format.
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import shutil
from collections.abc import Iterator
from pathlib import Path

from .errors import DiskFullError, SpectrinsicError, WriteError

__all__ = [
    "TMP_PREFIX",
    "NO_SPACE",
    "disk_full",
    "refuse_link",
    "replacing",
    "guarded_write",
    "write_text_file",
    "write_bytes_file",
]

#: Prefix of every temporary file or folder spectrinsic creates. Only names with this prefix are
#: ever cleaned up: ``.tmp-*`` belongs to other programs.
TMP_PREFIX = ".spectrinsic-tmp-"
#: errno values that mean "no space": retrying another sample cannot help.
NO_SPACE = frozenset({errno.ENOSPC, errno.EDQUOT})
#: How C libraries (OpenEXR) word a full disk in the ``RuntimeError`` they raise.
_NO_SPACE_TEXT = tuple(os.strerror(code) for code in sorted(NO_SPACE))


def disk_full(exc: BaseException) -> bool:
    """Whether *exc* says the disk (or the user's quota) is full: an ``OSError`` with
    ``ENOSPC``/``EDQUOT``, or a C library's ``RuntimeError`` quoting that error's text."""
    if isinstance(exc, OSError):
        return exc.errno in NO_SPACE
    return isinstance(exc, RuntimeError) and any(t in str(exc) for t in _NO_SPACE_TEXT)


def refuse_link(path: Path) -> None:
    """Raise :class:`~spectrinsic.errors.WriteError` if *path* or its folder is a symbolic link.

    Checked when a file is about to be written, not only when a run starts: a link planted in
    the output folder while a build runs would otherwise be written through.
    """
    for candidate, what in ((path, "file"), (path.parent, "folder")):
        if candidate.is_symlink():
            raise WriteError(
                f"cannot write {str(path)!r}: its {what} {str(candidate)!r} is a symbolic link "
                "(made after the run began); spectrinsic never writes through a link"
            )


def _one_line(path: Path, exc: BaseException) -> SpectrinsicError:
    reason = os.strerror(errno.ENOSPC) if not isinstance(exc, OSError) else exc.strerror
    cls = DiskFullError if disk_full(exc) else WriteError
    return cls(f"cannot write {str(path)!r}: {reason or exc}")


@contextlib.contextmanager
def replacing(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a new temporary path beside *path*; when the block ends normally, rename it over
    *path* (module docstring). On any error the temporary is removed and *path* is left as it
    was; an ``OSError`` (or a C library's full-disk ``RuntimeError``) becomes one line naming
    *path*.

    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> with replacing(folder / "a.txt") as tmp:
    ...     _ = tmp.write_text("new")
    >>> (folder / "a.txt").read_text(), sorted(p.name for p in folder.iterdir())
    ('new', ['a.txt'])
    """
    target = Path(path)
    refuse_link(target)
    tmp = target.with_name(f"{TMP_PREFIX}{os.getpid()}-{secrets.token_hex(4)}-{target.name}")
    try:
        yield tmp
        refuse_link(target)  # again: the write may have taken minutes
        os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            if tmp.is_dir() and not tmp.is_symlink():
                shutil.rmtree(tmp)
            else:
                tmp.unlink(missing_ok=True)
        if isinstance(exc, SpectrinsicError) or not (isinstance(exc, OSError) or disk_full(exc)):
            raise
        raise _one_line(target, exc) from exc


@contextlib.contextmanager
def guarded_write(path: str | os.PathLike[str]) -> Iterator[None]:
    """Turn a failure while making *path* (a folder, or a file a library writes itself) into a
    one-line error naming *path*, and remove what was written of it (a full disk leaves no
    partial or zero-byte file behind). Files are written with :func:`replacing`, never in place.

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
        raise _one_line(target, exc) from exc


def write_text_file(path: str | os.PathLike[str], text: str) -> Path:
    """Write *text* (UTF-8) to *path* through :func:`replacing`; return *path*."""
    with replacing(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def write_bytes_file(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write *data* to *path* through :func:`replacing`; return *path*."""
    with replacing(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)
