"""What a path given on the command line is, in words, for a one-line refusal.

A folder option given a file (``check notes.txt``, ``--data-dir notes.txt``), or a file option
given a folder (``--scenes d``), used to be told "does not exist" or "no such file", which sends
the user looking for a typo. :func:`folder_problem` says what the path is instead.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

__all__ = ["file_type", "folder_problem"]


def file_type(path: str | os.PathLike[str]) -> str:
    """What the existing *path* is, in words (``stat`` follows links, as ``open`` would): "a
    file", "a folder", "a FIFO (named pipe)", "a socket", "a character device", "a block
    device" or "a special file"."""
    mode = Path(path).stat().st_mode
    for test, what in (
        (stat.S_ISREG, "a file"),
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
    ):
        if test(mode):
            return what
    return "a special file"


def folder_problem(path: str | os.PathLike[str]) -> str | None:
    """``None`` for an existing folder, else what *path* is instead, to follow its name in a
    refusal: "does not exist" or "is a file, not a folder" (or a FIFO, a device...)."""
    p = Path(path)
    if p.is_dir():
        return None
    if not p.exists():
        return "does not exist"
    return f"is {file_type(p)}, not a folder"
