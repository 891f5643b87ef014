"""Whether a sample folder is what it claims to be, and whether spectrinsic may replace it.

spectrinsic only ever removes or replaces sample folders whose ``meta.json`` it wrote and that
hold no file that ``meta.json`` does not list (so a user's notes inside a sample folder stop the
build instead of vanishing). The dataset folder around the samples (its marker, its
temporaries) is :mod:`spectrinsic.gt_export.folders.build_folder`'s.

A sample is *intact* when its ``meta.json`` is valid, matches its own seal (a hash of its
content, :func:`~spectrinsic.gt_export.sample.meta_seal`), has the expected config hash, and
every file it lists lies inside the sample folder and matches the SHA-256 recorded there. Only
intact samples are resumed; any other is rendered again, with a warning that says why.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path, PurePosixPath

from ...errors import DatasetError, SampleMetaError
from . import FORMAT_VERSION, META_NAME, file_sha256
from .meta import owned_files, read_meta

__all__ = ["sample_problem", "replaceable_sample", "remove_sample"]


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
