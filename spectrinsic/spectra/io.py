"""Readers for spectral data files: with :mod:`~spectrinsic.spectra.csv_spectra` (a user's CSV
spectra, in any layout) the only modules of :mod:`spectrinsic.spectra` that read files.

Sources
-------
* Munsell: the 1269 matte Munsell chips measured at the University of Eastern Finland
  (Parkkinen, Hallikainen & Jaaskelainen 1989), as shipped in the ``luxpy`` wheel
  (``luxpy/data/rfls/Munsell1269.dat``, 380–800 nm at 1 nm). luxpy is located, never imported.
* SFU: Barnard, Martin, Funt & Coath, "A Data Set for Colour Research", Color Res. Appl.
  27(3):147–151, 2002, read from a configured data directory.
* Cameras: Jiang, Liu, Gu & Süsstrunk, WACV 2013 (28 cameras, CC BY-NC-SA 4.0) and Image
  Engineering 2024 (98 entries), read from a configured data directory.
"""

from __future__ import annotations

import csv
import functools
import importlib.util
import os
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from ..data_dir import require_data_file
from ..errors import DataDirectoryError, SpectralDataError
from .csv_spectra import CSV_MAX_BYTES
from .grid import validate_wavelengths

__all__ = [
    "Table",
    "luxpy_data_file",
    "read_munsell",
    "read_spectra_csv",
    "read_sfu_reflectances",
    "read_sfu_illuminants",
    "read_camera_table",
    "read_user_csv",
    "read_spd",
    "CSV_MAX_BYTES",
]


class Table(NamedTuple):
    """Spectra sharing one grid: ``wavelengths`` (W,) nm, ``values`` (N, W), ``labels`` (N,)."""

    wavelengths: np.ndarray
    values: np.ndarray
    labels: tuple[str, ...]


def _read_only(table: Table) -> Table:
    """*table* with its arrays made read-only: the cached readers share one table with every
    caller, so an in-place change by one would corrupt the spectra of all the others."""
    for array in (table.wavelengths, table.values):
        array.flags.writeable = False
    return table


def luxpy_data_file(*parts: str) -> Path:
    """Path of a data file inside the installed ``luxpy`` package, found without importing it.

    Importing luxpy unpickles look-up tables that need numpy >= 2; only its data files are needed.
    """
    spec = importlib.util.find_spec("luxpy")
    if spec is None or not spec.submodule_search_locations:
        raise DataDirectoryError(
            "the 'luxpy' package (which ships the Munsell spectra) is not installed"
        )
    path = Path(next(iter(spec.submodule_search_locations)), "data", *parts)
    if not path.is_file():
        raise DataDirectoryError(f"luxpy installation lacks the expected file {str(path)!r}")
    return path


@functools.lru_cache(maxsize=1)
def read_munsell() -> tuple[Table, tuple[tuple[str, float, float], ...]]:
    """The 1269 matte Munsell reflectances (read-only, cached) and their notations
    ``(hue, value, chroma)``."""
    source = luxpy_data_file("rfls", "Munsell1269.dat")
    data = np.loadtxt(source, delimiter=",")
    wl, values = data[:, 0].copy(), data[:, 1:].T.copy()
    if not (np.isfinite(values).all() and (values >= 0).all()):
        raise SpectralDataError(f"{source}: expected finite reflectances >= 0")
    notations: list[tuple[str, float, float]] = []
    with luxpy_data_file("rfls", "Munsell1269NotationInfo.dat").open(newline="") as fh:
        reader = csv.reader(fh)
        next(reader)
        for row in reader:
            notations.append((row[1].strip(), float(row[2]), float(row[3])))
    if values.shape[0] != len(notations):
        raise SpectralDataError(
            f"Munsell1269.dat holds {values.shape[0]} spectra but its notation file {len(notations)}"
        )
    labels = tuple(f"#{i}" for i in range(values.shape[0]))
    return _read_only(Table(wl, values, labels)), tuple(notations)


def _read_rows(path: Path) -> list[list[str]]:
    """The CSV rows of *path*, or a one-line error for bytes that are not UTF-8."""
    try:
        with path.open(newline="", encoding="utf-8") as fh:
            return list(csv.reader(fh))
    except UnicodeDecodeError as exc:
        raise SpectralDataError(
            f"{path}: byte {exc.start} (0x{exc.object[exc.start]:02x}) is not UTF-8; "
            "expected a UTF-8 (or ASCII) CSV file"
        ) from None
    except csv.Error as exc:
        raise SpectralDataError(f"{path}: malformed CSV ({exc})") from None


def _first(mask: np.ndarray) -> tuple[int, int]:
    """(row, column) of the first true cell of *mask*."""
    row, col = np.argwhere(mask)[0]
    return int(row), int(col)


def _check_values(
    path: Path,
    values: np.ndarray,
    empty: np.ndarray,
    labels: tuple[str, ...],
    *,
    missing: bool,
    maximum: float | None = None,
) -> None:
    """Every spectral value finite (empty cells aside when *missing*) and >= 0: reflectances,
    illuminant powers and sensitivities cannot be negative, and a NaN would reach the pixels;
    and at most *maximum* (1 for reflectances) if given. Column 0 holds the wavelengths."""
    above = np.zeros_like(empty)
    if maximum is not None:
        above[:, 1:] = ~empty[:, 1:] & (np.nan_to_num(values[:, 1:]) > maximum)
    checks = (
        (~empty & ~np.isfinite(values), "non-finite", "finite numbers"),
        (empty if not missing else np.zeros_like(empty), "empty", "a number in every cell"),
        (~empty & (np.nan_to_num(values) < 0), "negative", "values >= 0"),
        (above, "too large", f"values <= {maximum if maximum is not None else 0:g} (reflectances)"),
    )
    for mask, problem, expected in checks:
        if mask.any():
            row, col = _first(mask)
            where = "wavelength_nm" if col == 0 else labels[col - 1]
            what = "empty cell" if problem == "empty" else f"{problem} value {values[row, col]:g}"
            raise SpectralDataError(
                f"{path}: {what} in row {row + 2}, column {where!r}; expected {expected}"
            )


def read_spectra_csv(
    path: str | os.PathLike[str], *, missing: bool = False, maximum: float | None = None
) -> Table:
    """A CSV with a header row, first column ``wavelength_nm``, one column per spectrum.

    Every value is validated at load time: finite, >= 0 (and <= *maximum* if given: 1 for
    reflectances), wavelengths increasing. Empty cells
    (not measured) are read as NaN when *missing* is true (camera tables that stop at 720 nm)
    and are an error otherwise; a literal ``nan`` or ``inf`` always is.

    Raises
    ------
    SpectralDataError
        One line naming the file (and the row and column of a bad value).
    """
    path = Path(path)
    rows = _read_rows(path)
    if len(rows) < 3:
        raise SpectralDataError(f"{path}: expected a header row and at least 2 wavelength rows")
    header, body = rows[0], [r for r in rows[1:] if r]
    if any(len(r) != len(header) for r in body):
        raise SpectralDataError(f"{path}: a row has not {len(header)} columns like the header")
    try:
        arr = np.array([[float(c) if c.strip() else np.nan for c in r] for r in body])
    except ValueError as exc:
        raise SpectralDataError(f"{path}: non-numeric value ({exc})") from None
    empty = np.array([[not c.strip() for c in r] for r in body])
    labels = tuple(h.strip() for h in header[1:])
    _check_values(path, arr, empty, labels, missing=missing, maximum=maximum)
    wl = validate_wavelengths(arr[:, 0], what=str(path))
    return Table(wl, arr[:, 1:].T.copy(), labels)


@functools.lru_cache(maxsize=4)
def read_sfu_reflectances(data_dir: str | None) -> tuple[Table, tuple[tuple[str, int], ...]]:
    """The 1995 SFU reflectances (read-only, cached) and ``(group, index_in_group)`` per spectrum
    (1-based index)."""
    table = read_spectra_csv(
        require_data_file("sfu_barnard2002/reflect_db_1995.csv", data_dir), maximum=1.0
    )
    index_path = require_data_file("sfu_barnard2002/reflect_db_index.csv", data_dir)
    with index_path.open(newline="", encoding="utf-8") as fh:
        keys = tuple((r["group"], int(r["index_in_group"])) for r in csv.DictReader(fh))
    if len(keys) != table.values.shape[0]:
        raise SpectralDataError(
            f"{index_path}: {len(keys)} rows for {table.values.shape[0]} spectra"
        )
    return _read_only(table), keys


@functools.lru_cache(maxsize=4)
def read_sfu_illuminants(data_dir: str | None) -> Table:
    """SFU illuminants: the 102 measured + lab sources (``mws_NNN``) and 87 training (``train_NNN``).

    Labels are the ids before any ``": name"`` suffix. The arrays are read-only (cached).
    """
    a = read_spectra_csv(
        require_data_file("sfu_barnard2002/measured_with_sources_102.csv", data_dir)
    )
    b = read_spectra_csv(require_data_file("sfu_barnard2002/train_illum_87.csv", data_dir))
    if not np.array_equal(a.wavelengths, b.wavelengths):
        raise SpectralDataError("SFU illuminant files disagree in wavelengths")
    labels = tuple(lbl.split(":")[0].strip() for lbl in a.labels + b.labels)
    return _read_only(Table(a.wavelengths, np.vstack([a.values, b.values]), labels))


@functools.lru_cache(maxsize=8)
def read_camera_table(
    data_dir: str | None, relative: str
) -> Mapping[str, tuple[np.ndarray, np.ndarray]]:
    """Cameras from a ``<camera>_R/_G/_B`` CSV: name -> (wavelengths (W,) nm, curves (3, W)).

    Cells not measured (empty) become 0: they lie beyond ~760 nm where sensors hardly respond.
    Cached: the mapping and its arrays are read-only.
    """
    table = _read_only(read_spectra_csv(require_data_file(relative, data_dir), missing=True))
    cams: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for i in range(0, len(table.labels) - 2, 3):
        names = table.labels[i : i + 3]
        if not (names[0].endswith("_R") and names[1].endswith("_G") and names[2].endswith("_B")):
            raise SpectralDataError(f"{relative}: columns {names} are not an _R/_G/_B triple")
        curves = np.nan_to_num(table.values[i : i + 3], nan=0.0)
        curves.flags.writeable = False
        cams[names[0][:-2]] = (table.wavelengths, curves)
    return MappingProxyType(cams)


def read_user_csv(path: str | os.PathLike[str], *, kind: str) -> Table:
    """A user's spectra CSV (``wavelength_nm`` then one column per spectrum or sensor).

    Raises
    ------
    SpectralDataError
        On a missing file, bytes that are not UTF-8, an empty or non-increasing wavelength
        column, empty cells, NaN/inf, or negative values (see :func:`read_spectra_csv`).
    """
    path = Path(path)
    if not path.is_file():
        raise SpectralDataError(f"{kind} file {str(path)!r} does not exist")
    table = read_spectra_csv(path)
    if table.values.size == 0:
        raise SpectralDataError(
            f"{path}: expected at least one {kind} column after the wavelengths"
        )
    return table


def read_spd(path: str | os.PathLike[str]) -> tuple[np.ndarray, np.ndarray]:
    """Wavelengths (nm) and values of a Mitsuba ``.spd`` file (``WL VALUE`` per line, ``#``
    comments), at most :data:`CSV_MAX_BYTES`; one-line :class:`SpectralDataError` otherwise."""
    path = Path(path)
    if not path.is_file() or path.stat().st_size > CSV_MAX_BYTES:
        raise SpectralDataError(
            f"spectrum file {str(path)!r}: expected a file of at most {CSV_MAX_BYTES} bytes"
        )
    try:
        data = np.loadtxt(path, comments="#", dtype=float, ndmin=2)
    except ValueError as exc:
        raise SpectralDataError(f"{path}: expected 'WAVELENGTH VALUE' lines ({exc})") from None
    if data.shape[1] != 2 or len(data) < 2 or not np.isfinite(data).all():
        raise SpectralDataError(f"{path}: expected >= 2 lines of two finite numbers")
    return data[:, 0].copy(), data[:, 1].copy()


def mitsuba_ior_dir() -> Path:
    """Folder of the spectral ``<name>.eta.spd`` / ``<name>.k.spd`` tables shipped inside the
    installed ``mitsuba`` package (``data/ior``), found without importing Mitsuba."""
    spec = importlib.util.find_spec("mitsuba")
    if spec is None or spec.origin is None:
        raise DataDirectoryError(
            "the 'mitsuba' package (which ships the conductor η/k tables) is not installed"
        )
    # the package's folder (once a variant is set, the spec is that of Mitsuba's alias module in it)
    return Path(spec.origin).parent / "data" / "ior"


@functools.lru_cache(maxsize=64)
def read_conductor_ior(name: str) -> Table:
    """Mitsuba's measured complex index of refraction of conductor *name* (``Au``, ``Cu``...):
    a read-only table with wavelengths in nm and values ``(2, N)`` = (η, k), both read from
    the two ``.spd`` files (first column: wavelength in nm, second: value) on η's grid."""
    folder = mitsuba_ior_dir()
    columns = []
    for part in ("eta", "k"):
        path = folder / f"{name}.{part}.spd"
        if not path.is_file():
            raise SpectralDataError(f"conductor {name!r}: no table {str(path)!r} in Mitsuba's data")
        columns.append(np.loadtxt(path, comments="#", dtype=float, ndmin=2))
    eta, k = columns
    wl = eta[:, 0]
    k_on_eta = np.interp(wl, k[:, 0], k[:, 1])
    return _read_only(
        Table(wavelengths=wl, values=np.stack([eta[:, 1], k_on_eta]), labels=("eta", "k"))
    )
