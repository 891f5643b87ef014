"""The one reader of CSV spectra, in the three layouts instruments and spreadsheets write.

Layouts (found from the header row; ``docs/csv_spectra.md`` shows each):

- **wide**: wavelengths (nm) in the first column, one spectrum per further column
  (``wavelength [nm],red [%],lamp [W/m2/nm]``).
- **pairs**: one wavelength/value column pair per spectrum (``Wavelength [nm],Refl. %,
  Wavelength [nm],Refl. %``), as spectrophotometers export several samples; the pairs may
  have different lengths, and a row where both cells of a pair are empty is skipped. A file is
  read as pairs when a column after the first one is a wavelength column.
- **long**: ``sample,wavelength,value`` rows, one row per sample and wavelength, in the order
  they come (a database export).

A spectrum is chosen by name (the header's name before its unit, or the full header; in the
long layout the sample's name) or, when no name matches, by its number from 1: the N-th
spectrum column (wide), the N-th pair, or the N-th sample in order of first appearance. A name
two spectra share is refused, naming both positions (choose by number then). The unit is the
header's ``[unit]``, ``(unit)`` or a trailing ``%`` (``Refl. %``); in the long layout that of
the value column. A UTF-8 byte-order mark, CRLF line ends and ``;`` or tab delimiters (when the
header row holds no comma) are read; decimal commas are not.
"""

from __future__ import annotations

import csv
import io as text_io
import math
import os
import re
from pathlib import Path
from typing import Literal, NamedTuple

import numpy as np

from ..errors import SpectralDataError, did_you_mean

__all__ = ["Column", "Layout", "layout_of", "read_csv_column", "split_label", "CSV_MAX_BYTES"]

#: Largest spectrum CSV read (bytes): a 1 nm table of hundreds of spectra is far smaller.
CSV_MAX_BYTES = 16 * 1024 * 1024

Layout = Literal["wide", "pairs", "long"]

_UNIT = re.compile(r"(?:\[([^\]]*)\]|\(([^)]*)\)|(%))\s*$")
_WAVELENGTH = re.compile(r"^(wavelengths?|wave length|wl|lambda|λ|nm)\b", re.IGNORECASE)


class Column(NamedTuple):
    """One spectrum of a CSV: ``wavelengths`` (W,) nm and ``values`` (W,) as written,
    ``label`` its header (or ``sample (value header)``), ``unit`` the unit it states (``None``
    when it states none), ``rows`` (W,) the 1-based file row of each sample, ``layout`` and
    ``position`` (``column 3``, ``pair 2 (columns 3-4)``, ``sample 'x'``) for messages."""

    wavelengths: np.ndarray
    values: np.ndarray
    label: str
    unit: str | None
    rows: tuple[int, ...]
    layout: Layout
    position: str


def split_label(label: str) -> tuple[str, str | None]:
    """A header's name and unit: ``'red [%]'`` -> ``('red', '%')``, ``'Refl. %'`` ->
    ``('Refl.', '%')``, ``'red'`` -> ``('red', None)``."""
    label = label.strip()
    match = _UNIT.search(label)
    if match is None:
        return label, None
    unit = next(g for g in match.groups() if g is not None).strip()
    return label[: match.start()].strip(), unit


def _is_wavelength(label: str) -> bool:
    name, unit = split_label(label)
    return bool(_WAVELENGTH.match(name)) or unit == "nm"


def _rows(path: Path) -> list[list[str]]:
    """The CSV rows of *path* (BOM dropped, any line end, ``,``/``;``/tab sniffed from the
    header row), trailing empty cells removed; one-line errors for bad bytes or sizes."""
    if not path.is_file():
        raise SpectralDataError(f"spectrum file {str(path)!r} does not exist")
    size = path.stat().st_size
    if size > CSV_MAX_BYTES:
        raise SpectralDataError(
            f"{path}: {size} bytes; expected a spectrum CSV of at most {CSV_MAX_BYTES} bytes"
        )
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise SpectralDataError(
            f"{path}: byte {exc.start} (0x{exc.object[exc.start]:02x}) is not UTF-8; "
            "expected a UTF-8 (or ASCII) CSV file"
        ) from None
    first = text.split("\n", 1)[0]
    delimiter = "," if "," in first else ";" if ";" in first else "\t" if "\t" in first else ","
    try:
        rows = list(csv.reader(text_io.StringIO(text, newline=""), delimiter=delimiter))
    except csv.Error as exc:
        raise SpectralDataError(f"{path}: malformed CSV ({exc})") from None
    for row in rows:
        while row and not row[-1].strip():
            row.pop()
    return rows


def layout_of(header: list[str]) -> Layout:
    """The layout a header row states (module docstring)."""
    if len(header) == 3 and _is_wavelength(header[1]) and not _is_wavelength(header[0]):
        return "long"
    if any(_is_wavelength(h) for h in header[1:]):
        return "pairs"
    return "wide"


def _cell(path: Path, text: str, row: int, column: str) -> float:
    """One cell as a finite number; a one-line error naming file, row and column otherwise."""
    try:
        value = float(text) if text.strip() else math.nan
    except ValueError:
        raise SpectralDataError(
            f"{path}: row {row}, column {column!r}: {text!r} is not a number"
        ) from None
    if not math.isfinite(value):
        what = "empty cell" if not text.strip() else f"non-finite value {text.strip()!r}"
        raise SpectralDataError(
            f"{path}: row {row}, column {column!r}: {what}; expected a finite number"
        )
    return value


def _choose(path: Path, want: str, labels: list[str], positions: list[str], what: str) -> int:
    """Index of the spectrum *want* names among *labels* (by name, else by number from 1)."""
    names = [split_label(label)[0] for label in labels]
    hits = [i for i, label in enumerate(labels) if want in (label, names[i])]
    if len(hits) > 1:
        raise SpectralDataError(
            f"{path}: {what} {want!r} at {positions[hits[0]]} and {positions[hits[1]]}; "
            f"expected one {what} per name (choose one by number, e.g. #{hits[0] + 1})"
        )
    if hits:
        return hits[0]
    if want.isdigit() and 1 <= int(want) <= len(labels):
        return int(want) - 1
    raise SpectralDataError(
        f"{path}: no {what} {want!r}; expected one of {labels} or a number from 1 to "
        f"{len(labels)}" + did_you_mean(want, names)
    )


def _increasing(path: Path, wl: list[float], rows: list[int], column: str) -> None:
    for i in range(1, len(wl)):
        if not wl[i] > wl[i - 1]:
            raise SpectralDataError(
                f"{path}: row {rows[i]}, column {column!r}: wavelength {wl[i]:g} nm "
                f"follows {wl[i - 1]:g} nm; expected strictly increasing wavelengths"
            )
    if len(wl) < 2:
        raise SpectralDataError(f"{path}: {column!r}: expected at least 2 wavelength rows")
    if wl[0] <= 0:  # increasing, so every later one is positive
        raise SpectralDataError(
            f"{path}: row {rows[0]}, column {column!r}: wavelength {wl[0]:g} nm; expected "
            "positive wavelengths in nm"
        )


def _wide(path: Path, rows: list[list[str]], want: str) -> Column:
    header = [h.strip() for h in rows[0]]
    positions = [f"column {i + 1}" for i in range(1, len(header))]
    col = _choose(path, want, header[1:], positions, "column") + 1
    body = [(n + 1, r) for n, r in enumerate(rows) if n > 0 and any(c.strip() for c in r)]
    wl, values = [], []
    for n, r in body:
        wl.append(_cell(path, r[0], n, header[0]))
        values.append(_cell(path, r[col] if len(r) > col else "", n, header[col]))
    at = [n for n, _ in body]
    _increasing(path, wl, at, header[0])
    name_unit = split_label(header[col])[1]
    return Column(
        np.array(wl),
        np.array(values),
        header[col],
        name_unit,
        tuple(at),
        "wide",
        f"column {col + 1}",
    )


def _pairs(path: Path, rows: list[list[str]], want: str) -> Column:
    header = [h.strip() for h in rows[0]]
    if len(header) % 2 or not all(_is_wavelength(h) for h in header[0::2]):
        raise SpectralDataError(
            f"{path}: header {header} has a wavelength column after the first one, so it is "
            "read as wavelength/value pairs; expected a wavelength column first in every pair"
        )
    labels = header[1::2]
    positions = [f"pair {k + 1} (columns {2 * k + 1}-{2 * k + 2})" for k in range(len(labels))]
    k = _choose(path, want, labels, positions, "column")
    w_col, v_col = 2 * k, 2 * k + 1
    wl, values, at = [], [], []
    for n, r in enumerate(rows[1:], start=2):
        w = r[w_col] if len(r) > w_col else ""
        v = r[v_col] if len(r) > v_col else ""
        if not w.strip() and not v.strip():  # this pair ended (or pauses) in this row
            continue
        wl.append(_cell(path, w, n, header[w_col]))
        values.append(_cell(path, v, n, header[v_col]))
        at.append(n)
    _increasing(path, wl, at, header[w_col])
    unit = split_label(header[v_col])[1]
    return Column(
        np.array(wl), np.array(values), header[v_col], unit, tuple(at), "pairs", positions[k]
    )


def _long(path: Path, rows: list[list[str]], want: str) -> Column:
    header = [h.strip() for h in rows[0]]
    samples: dict[str, list[int]] = {}
    for n, r in enumerate(rows[1:], start=2):
        if any(c.strip() for c in r):
            samples.setdefault(r[0].strip(), []).append(n)
    names = list(samples)
    positions = [f"sample {s!r} (first at row {samples[s][0]})" for s in names]
    name = names[_choose(path, want, names, positions, "sample")]
    wl, values = [], []
    for n in samples[name]:
        r = rows[n - 1]
        wl.append(_cell(path, r[1] if len(r) > 1 else "", n, header[1]))
        values.append(_cell(path, r[2] if len(r) > 2 else "", n, header[2]))
    _increasing(path, wl, samples[name], header[1])
    label, unit = f"{name} ({header[2]})", split_label(header[2])[1]
    return Column(
        np.array(wl),
        np.array(values),
        label,
        unit,
        tuple(samples[name]),
        "long",
        f"sample {name!r}",
    )


def read_csv_column(path: str | os.PathLike[str], column: str) -> Column:
    """The spectrum *column* names in the CSV at *path*, in any layout (module docstring).

    Checked cell by cell: the file at most :data:`CSV_MAX_BYTES`, every wavelength and value a
    finite number, wavelengths strictly increasing; other spectra are not read.

    Raises
    ------
    SpectralDataError
        One line naming the file and, for a bad cell, its row (1 = header) and column.
    """
    path = Path(path)
    rows = _rows(path)
    if not rows or len(rows[0]) < 2:
        raise SpectralDataError(f"{path}: expected a header row with wavelengths and spectra")
    reader = {"wide": _wide, "pairs": _pairs, "long": _long}[layout_of(rows[0])]
    return reader(path, rows, column.strip())
