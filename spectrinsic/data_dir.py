"""Where spectrinsic finds its optional spectral data.

The default dataset builds from what the declared dependencies ship (luxpy's Munsell spectra,
colour-science's illuminants, CMFs and cameras). Measured data that may not be redistributed
(the SFU set, further cameras, colour-naming tables) is read at run time from a *data
directory*: the ``--data-dir`` option, else the ``SPECTRINSIC_DATA`` environment variable.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .errors import DataDirectoryError
from .path_kinds import folder_problem

__all__ = ["DATA_ENV", "DATA_SUBDIRS", "resolve_data_dir", "require_data_file", "one_data_dir"]

DATA_ENV = "SPECTRINSIC_DATA"

#: The sub-folders of a data directory and what each holds.
DATA_SUBDIRS: dict[str, str] = {
    "sfu_barnard2002": "Barnard et al. 2002 (SFU): 1995 reflectances, 102 + 87 illuminants",
    "camera_jiang2013_camspec": "Jiang et al. 2013: 28 camera sensitivities",
    "camera_imageengineering_2024": "Image Engineering 2024: 98 camera sensitivities",
    "colour_naming_vandeweijer2009": "van de Weijer et al. 2009 colour-name table (w2c)",
    "colour_naming_benavente2008_tse": "Benavente et al. 2008 parametric colour naming",
}


def resolve_data_dir(data_dir: str | os.PathLike[str] | None = None) -> Path | None:
    """Return the configured data directory, or ``None`` when none is configured.

    Parameters
    ----------
    data_dir
        Explicit directory (``--data-dir``); takes precedence over ``SPECTRINSIC_DATA``.

    Raises
    ------
    DataDirectoryError
        If a directory is configured but does not exist.
    """
    source = "--data-dir"
    if data_dir is None:
        env = os.environ.get(DATA_ENV, "").strip()
        if not env:
            return None
        data_dir, source = env, DATA_ENV
    if not str(data_dir).strip():  # Path("") is the working folder
        raise DataDirectoryError(f"data directory {str(data_dir)!r} (from {source}): an empty path")
    path = Path(data_dir).expanduser()
    if (problem := folder_problem(path)) is not None:
        raise DataDirectoryError(f"data directory {str(path)!r} (from {source}) {problem}")
    return path.resolve()


def require_data_file(relative: str, data_dir: str | os.PathLike[str] | None = None) -> Path:
    """Return ``<data dir>/<relative>``, or raise a one-line error naming what is missing."""
    root = resolve_data_dir(data_dir)
    if root is None:
        raise DataDirectoryError(
            f"{relative} needs a spectral data directory: pass --data-dir DIR or set "
            f"{DATA_ENV} (e.g. to ../shared/data)"
        )
    path = root / relative
    if not path.is_file():
        raise DataDirectoryError(
            f"data directory {str(root)!r} lacks the expected file {relative!r}"
        )
    return path


@contextmanager
def one_data_dir(data_dir: str | os.PathLike[str] | None = None) -> Iterator[str | None]:
    """One data directory for a whole run: *data_dir* (``--data-dir``), else
    ``SPECTRINSIC_DATA``, resolved once and yielded as an absolute path (``None`` when none is
    configured).

    While the run lasts ``SPECTRINSIC_DATA`` holds that same path, so every reader that is not
    handed the directory explicitly, and every worker the run starts (processes inherit the
    environment, local Dask workers too), sees the directory the run resolved, never another
    one. The previous value is restored afterwards. A *data_dir* that does not exist is
    refused here; a wrong ``SPECTRINSIC_DATA`` only where something is read from it.
    """
    try:
        root = resolve_data_dir(data_dir)
    except DataDirectoryError:
        if data_dir is not None:
            raise
        root = None  # a wrong $SPECTRINSIC_DATA is refused where it is read, naming it
    previous = os.environ.get(DATA_ENV)
    if root is not None:
        os.environ[DATA_ENV] = str(root)
    try:
        yield None if root is None else str(root)
    finally:
        if root is not None:
            if previous is None:
                os.environ.pop(DATA_ENV, None)
            else:
                os.environ[DATA_ENV] = previous
