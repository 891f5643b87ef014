"""A user's own spectra: columns of CSV files, inline samples and RGB colours.

Registry families (:func:`spectrinsic.spectra.get_spectrum`):

- ``csv:PATH#COLUMN``: a spectrum of a CSV in the wide, pair or long layout
  (:mod:`spectrinsic.spectra.csv_spectra`), *COLUMN* its name or its number from 1. The
  header states the unit (``name [%]``, ``name (%)``, ``Refl. %``), or the name gives it when
  the header has none (``csv:PATH#3?unit=%``); the unit says what the spectrum is:
  ``%`` (reflectance in percent, divided by 100) or ``1`` (reflectance as a fraction) make
  a reflectance; a spectral power unit (``W/m2/nm``, ``mW/(m2 nm)``, ``W/sr/m2/nm``...)
  or ``a.u.`` (relative power) make an illuminant, normalised like every illuminant. A spectrum
  without a unit is refused: ``45`` could be percent or a fraction. *PATH* is absolute or
  relative to the working folder; in scene files it is relative to the scene's folder
  (:mod:`spectrinsic.scenes.spectrum_refs`).
- ``inline:KIND:WL=V,WL=V,...``: samples written out, KIND ``reflectance`` (fractions) or
  ``illuminant``; scene files write them as ``{wavelengths: [...], values: [...]}``.
- ``rgb:R,G,B`` (linear sRGB in [0, 1]) and ``srgb:R,G,B`` / ``srgb:#RRGGBB`` (sRGB-encoded,
  decoded with the sRGB transfer function): a reflectance by Mallett & Yuksel's (2019)
  spectral primary decomposition, ``ρ(λ) = R b_R(λ) + G b_G(λ) + B b_B(λ)`` with colour-science's
  ``MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019``: a non-negative mix of three fixed spectra summing
  to about one, so it stays in [0, 1]. Colours outside the sRGB gamut (a channel outside
  [0, 1]) are refused, not clipped. Round trip: the spectrum's linear sRGB under D65 differs
  from the input by at most 1.2e-3 over an 11³ grid of the sRGB cube (which holds the
  primaries), worst at the blue primary ``rgb:0,0,1``, on spectrinsic's own 1 nm colorimetry
  (the ``reflectance`` layer's: the basis interpolated to 1 nm); colour-science's integration
  on the basis' 5 nm grid gives 2.4e-4 there (measured; ``tests/spectra/test_user_spectra.py``
  checks both, the first on the primaries).
- ``rgblight:R,G,B``: the light of linear sRGB ``R,G,B`` in [0, 1] under D65,
  ``E(λ) ∝ (R b_R(λ) + G b_G(λ) + B b_B(λ)) · D65(λ)``, normalised like every illuminant, so
  ``rgblight:1,1,1`` is D65 (the basis sums to one within 1e-5). The channel lights of an
  environment map (``envmap``) are ``rgblight:1,0,0``, ``rgblight:0,1,0`` and
  ``rgblight:0,0,1``; :func:`rgb_light_power` gives the power that makes channel c's light
  exactly ``b_c · D65`` of the registry's unit-luminance D65.

Every file spectrum is checked before any work: finite numbers, strictly increasing
wavelengths covering :data:`REQUIRED_RANGE`, reflectances in [0, 1]; errors name the file, the
row and the column. Beyond its data a spectrum holds its edge values (:meth:`Spectrum.on`).
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SpectralDataError, SpectrumNotFoundError
from ..number_lists import copy_numbers, numbers_only
from .csv_spectra import read_csv_column
from .illuminants import cie_illuminant, normalise_illuminant
from .records import Spectrum, SpectrumKind

__all__ = [
    "REQUIRED_RANGE",
    "absolute_csv",
    "csv_spectrum",
    "inline_spectrum",
    "inline_name",
    "rgb_spectrum",
    "srgb_spectrum",
    "rgb_light_spectrum",
    "rgb_light_power",
    "split_csv_key",
    "column_unit",
    "spectrum_files",
    "portable_csv",
    "portable_sensor_csv",
    "sensor_files_record",
    "readable_sensor_csv",
    "portable_names",
]

#: Wavelengths (nm) a user's spectrum must cover. Outside it the CIE 1931 2° x̄, ȳ, z̄ (360-830 nm
#: at 1 nm) hold 0.25 %, 0.057 % and 0.49 % of their integrals (``test_required_range_weight``).
REQUIRED_RANGE = (400.0, 700.0)
_REFLECTANCE_UNITS = {"%": 0.01, "1": 1.0, "fraction": 1.0}
_POWER_UNIT = re.compile(r"^(a\.u\.|relative|[munµμk]?W\b.*)$")
MALLETT2019 = "Mallett & Yuksel 2019 spectral primary decomposition (colour-science)"


def split_csv_key(key: str) -> tuple[str, str]:
    """``PATH#COLUMN`` as ``(PATH, COLUMN)``; the last ``#`` splits (paths may hold one)."""
    path, sep, column = key.rpartition("#")
    if not sep or not path.strip() or not column.strip():
        raise SpectrumNotFoundError(
            f"csv spectrum {key!r}: expected 'csv:PATH#COLUMN', e.g. 'csv:paints.csv#red'"
        )
    return path.strip(), column.strip()


def column_unit(column: str) -> tuple[str, str | None]:
    """A ``csv:`` name's ``COLUMN[?unit=U]`` part as ``(COLUMN, U or None)``."""
    column, sep, query = column.partition("?")
    if not sep:
        return column.strip(), None
    key, eq, unit = query.partition("=")
    if key.strip() != "unit" or not eq or not unit.strip():
        raise SpectrumNotFoundError(
            f"csv spectrum column {column!r}?{query}; expected '?unit=UNIT' (e.g. '#3?unit=%')"
        )
    return column.strip(), unit.strip()


def _kind_of(
    path: Path, label: str, unit: str | None, given: str | None
) -> tuple[SpectrumKind, float]:
    """The spectrum kind and the factor to fractions that the header's *unit* (or the name's
    ``?unit=`` *given*, when the header states none) says."""
    if unit is not None and given is not None and unit != given:
        raise SpectralDataError(
            f"{path}: column {label!r} states the unit [{unit}], and the name ?unit={given}; "
            "expected ?unit= only for a header without a unit"
        )
    unit = unit if unit is not None else given
    if unit in _REFLECTANCE_UNITS:
        return "reflectance", _REFLECTANCE_UNITS[unit]
    if unit is not None and _POWER_UNIT.match(unit):
        return "illuminant", 1.0
    said = f"unit [{unit}]" if unit is not None else "no unit"
    raise SpectralDataError(
        f"{path}: column {label!r} has {said}; expected a header like 'name [%]' or 'name [1]' "
        "(reflectance in percent or as a fraction) or 'name [W/m2/nm]' (spectral power), or "
        "the unit in the name: 'csv:FILE#COLUMN?unit=%'"
    )


def _check(
    where: str, wl: np.ndarray, values: np.ndarray, kind: str, at: list[str] | None = None
) -> None:
    """Coverage of :data:`REQUIRED_RANGE`, values >= 0, reflectances <= 1; *at* names each
    sample's place (``"row 7"``) in messages, else its position."""
    lo, hi = REQUIRED_RANGE
    if wl[0] > lo or wl[-1] < hi:
        raise SpectralDataError(
            f"{where}: wavelengths {wl[0]:g}-{wl[-1]:g} nm; expected them to cover "
            f"{lo:g}-{hi:g} nm (the rendering range)"
        )
    place = at or [f"sample {i}" for i in range(len(wl))]
    bad = np.flatnonzero(values < 0)
    if bad.size:
        i = int(bad[0])
        raise SpectralDataError(
            f"{where}: {place[i]} ({wl[i]:g} nm): negative value {values[i]:g}; expected >= 0"
        )
    bad = np.flatnonzero(values > 1.0) if kind == "reflectance" else bad
    if bad.size:
        i = int(bad[0])
        raise SpectralDataError(
            f"{where}: {place[i]} ({wl[i]:g} nm): reflectance {values[i]:g} > 1; expected "
            "fractions in [0, 1] (a percent column needs the unit [%] in its header)"
        )


def sha256(path: str | Path) -> str:
    """Hex SHA-256 of the file at *path*."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


@functools.lru_cache(maxsize=64)
def _csv_cached(path: str, column: str, _stamp: tuple[int, int]) -> Spectrum:
    name, given = column_unit(column)
    col = read_csv_column(path, name)
    kind, scale = _kind_of(Path(path), col.label, col.unit, given)
    values = col.values * scale
    where = f"{path}: {col.position} {col.label!r}"
    _check(where, col.wavelengths, values, kind, [f"row {r}" for r in col.rows])
    if kind == "illuminant":
        values = normalise_illuminant(col.wavelengths, values)
    source = f"user file {path}, {col.position} {col.label!r}, sha256 {sha256(path)}"
    return Spectrum(f"csv:{path}#{column}", kind, col.wavelengths, values, source)


def absolute_csv(name: str) -> str:
    """*name* with a ``csv:`` path made absolute (against the working folder); other names
    unchanged. A sample then records which file it read, wherever it is opened."""
    if not name.strip().lower().startswith("csv:"):
        return name
    path, column = split_csv_key(name.strip()[4:])
    return f"csv:{Path(path).expanduser().resolve()}#{column}"


def csv_spectrum(key: str) -> Spectrum:
    """The spectrum ``csv:PATH#COLUMN`` (module docstring); cached per file state."""
    path, column = split_csv_key(key)
    resolved = Path(path).expanduser().resolve()
    if not resolved.is_file():
        raise SpectralDataError(f"spectrum file {path!r} does not exist")
    stat = resolved.stat()
    return _csv_cached(str(resolved), column, (stat.st_mtime_ns, stat.st_size))


def inline_name(wavelengths: Any, values: Any, kind: str, where: str = "inline spectrum") -> str:
    """The registry name ``inline:KIND:WL=V,...`` of written-out samples (checked on lookup)."""
    try:
        wl = np.asarray(wavelengths, dtype=np.float64).ravel()
        v = np.asarray(values, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise SpectralDataError(
            f"{where}: expected lists of numbers 'wavelengths' (nm) and 'values'"
        ) from None
    if wl.size != v.size or wl.size < 2:
        raise SpectralDataError(
            f"{where}: {wl.size} wavelengths and {v.size} values; expected equally many, >= 2"
        )
    return f"inline:{kind}:" + ",".join(f"{a!r}={b!r}" for a, b in zip(wl.tolist(), v.tolist()))


def inline_spectrum(key: str) -> Spectrum:
    """The spectrum ``inline:KIND:WL=V,WL=V,...`` (module docstring)."""
    kind, _, samples = key.partition(":")
    if kind not in ("reflectance", "illuminant"):
        raise SpectrumNotFoundError(
            f"inline spectrum {key[:40]!r}: expected 'inline:reflectance:WL=V,...' or "
            "'inline:illuminant:WL=V,...'"
        )
    try:
        pairs = [tuple(float(x) for x in p.split("=")) for p in samples.split(",")]
        wl, values = np.array(pairs, dtype=np.float64).reshape(-1, 2).T
    except ValueError:
        raise SpectralDataError(
            f"inline spectrum {key[:40]!r}...: expected WL=VALUE pairs separated by commas"
        ) from None
    where = "inline spectrum"
    if not (np.isfinite(wl).all() and np.isfinite(values).all()):
        i = int(np.flatnonzero(~(np.isfinite(wl) & np.isfinite(values)))[0])
        raise SpectralDataError(f"{where}: sample {i}: non-finite; expected finite numbers")
    steps = np.flatnonzero(np.diff(wl) <= 0)
    if wl.size < 2 or steps.size:
        i = int(steps[0]) + 1 if steps.size else 0
        raise SpectralDataError(
            f"{where}: sample {i} ({wl[i]:g} nm): expected >= 2 strictly increasing wavelengths"
        )
    _check(where, wl, values, kind)
    if kind == "illuminant":
        values = normalise_illuminant(wl, values)
    return Spectrum(f"inline:{key}", kind, wl, values, "written out in a scene or command")  # type: ignore[arg-type]


@functools.lru_cache(maxsize=1)
def _mallett_basis() -> tuple[np.ndarray, np.ndarray]:
    """Wavelengths (W,) nm and the (3, W) Mallett & Yuksel 2019 sRGB basis, read-only."""
    import colour

    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019
    wl = np.array(basis.wavelengths, dtype=np.float64)
    values = np.array(basis.values, dtype=np.float64).T
    for a in (wl, values):
        a.flags.writeable = False
    return wl, values


def _triple(key: str, family: str) -> np.ndarray:
    text = key.strip()
    if family == "srgb" and re.fullmatch(r"#[0-9A-Fa-f]{6}", text):
        return np.array([int(text[i : i + 2], 16) / 255.0 for i in (1, 3, 5)])
    try:
        rgb = np.array([float(x) for x in text.split(",")])
    except ValueError:
        rgb = np.zeros(0)
    if rgb.shape != (3,) or not np.isfinite(rgb).all():
        raise SpectrumNotFoundError(
            f"{family} colour {key!r}: expected 'R,G,B' in [0, 1]"
            + (" or '#RRGGBB'" if family == "srgb" else "")
        )
    if (rgb < 0).any() or (rgb > 1).any():
        raise SpectralDataError(
            f"{family} colour {key!r}: outside the sRGB gamut; expected channels in [0, 1] "
            "(out-of-gamut colours are refused, not clipped)"
        )
    return rgb


def _from_linear(name: str, rgb: np.ndarray) -> Spectrum:
    wl, basis = _mallett_basis()
    values = np.clip(rgb @ basis, 0.0, 1.0)  # clip: float round-off of a sum of ~1 only
    return Spectrum(name, "reflectance", wl, values, MALLETT2019)


def rgb_spectrum(key: str) -> Spectrum:
    """The reflectance of linear sRGB ``R,G,B`` in [0, 1] (module docstring)."""
    rgb = _triple(key, "rgb")
    return _from_linear("rgb:" + ",".join(f"{c:g}" for c in rgb), rgb)


def _rgb_light_values(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Wavelengths of the registry's D65 and ``(rgb · b)(λ) · D65(λ)``, D65 at unit luminance."""
    d65 = cie_illuminant("D65")
    wl, basis = _mallett_basis()
    colour = np.stack([np.interp(d65.wavelengths, wl, b) for b in basis])  # edge values beyond
    return d65.wavelengths, (rgb @ colour) * d65.values


def rgb_light_spectrum(key: str) -> Spectrum:
    """The illuminant of linear sRGB ``R,G,B`` in [0, 1] under D65 (module docstring)."""
    rgb = _triple(key, "rgb")
    wl, values = _rgb_light_values(rgb)
    name = "rgblight:" + ",".join(f"{c:g}" for c in rgb)
    source = MALLETT2019 + " times CIE D65"
    return Spectrum(name, "illuminant", wl, normalise_illuminant(wl, values), source)


def rgb_light_power(rgb: tuple[float, float, float]) -> float:
    """Power of ``rgblight:R,G,B`` whose light is ``(rgb · b) · D65`` with D65 at unit
    luminance: the luminance of that product relative to D65's (``Σ`` over the channels of a
    unit colour is 1). With it a map texel (R, G, B) of a unit-scale environment map has the
    radiance spectrum ``Σ_c rgb_c · power_c · rgblight_c = (rgb · b) · D65``."""
    wl, values = _rgb_light_values(np.asarray(rgb, float))
    return float(values.sum() / normalise_illuminant(wl, values).sum())


def srgb_spectrum(key: str) -> Spectrum:
    """The reflectance of sRGB-encoded ``R,G,B`` or ``#RRGGBB``, decoded by the sRGB transfer
    function first (module docstring)."""
    import colour

    encoded = _triple(key, "srgb")
    linear = np.asarray(colour.cctf_decoding(encoded, function="sRGB"), dtype=np.float64)
    return _from_linear("srgb:" + ",".join(f"{c:g}" for c in encoded), linear)


def portable_csv(name: str, base: str | Path | None = None) -> str:
    """*name* as a sample records it: a ``csv:`` name's absolute path made relative to *base*
    (the scene file's folder) when the file lies inside it, else its file name alone; other
    names, and relative ``csv:`` names, unchanged. No file a build writes then holds a path of
    the machine that built it, and readers resolve the name against the scene's folder again
    (:func:`spectrinsic.scenes.spectrum_refs.confined_csv`)."""
    if not name.strip().lower().startswith("csv:"):
        return name
    path, sep, column = name.strip()[4:].rpartition("#")
    file = Path(path.strip())
    if not sep:  # a sensor set (``csv:PATH``, no column): :func:`portable_sensor_csv`
        return portable_sensor_csv(name)
    if not file.is_absolute():
        return name
    root = Path(base).resolve() if base is not None else None
    rel = file.relative_to(root) if root is not None and file.is_relative_to(root) else None
    return f"csv:{(rel or Path(file.name)).as_posix()}#{column}"


def portable_sensor_csv(name: str) -> str:
    """A camera's sensor set ``csv:PATH`` (three curves, no column) as samples record it: an
    absolute PATH by its file name alone (``csv:/home/u/cam.csv`` -> ``csv:cam.csv``), a
    relative one as given. The name also names the camera's layers (``image_camera/csv:cam.csv``)
    and files; ``meta.json["spectrum_files"]`` keeps its SHA-256, and relight reads the file
    from ``--scene-dir`` or the working folder (:func:`readable_sensor_csv`)."""
    path = Path(name.strip()[4:].strip())
    return f"csv:{path.name}" if path.is_absolute() else name


def readable_sensor_csv(name: str, folder: str | os.PathLike[str] | None) -> str:
    """A recorded sensor set ``csv:NAME`` (:func:`portable_sensor_csv`) with a path the process
    can read: a relative NAME in *folder* when it holds that file, else in the working folder;
    an absolute one (a sample from before portable names) as it is. The caller checks the
    file's SHA-256 (``meta.json["spectrum_files"]``), so a file of that name elsewhere is
    refused, never read in its place."""
    path = Path(name.strip()[4:].strip())
    if path.is_absolute() or folder is None or not (Path(folder) / path).is_file():
        return name
    return f"csv:{Path(folder) / path}"


def sensor_files_record(names: Any) -> dict[str, list[dict[str, str]]]:
    """``{"sensor_files": [...]}`` (:func:`spectrum_files`) for the sensor CSVs among camera
    *names* that are readable files, ``{}`` when there are none: a config names a sensor CSV by
    its file name, so its SHA-256 keeps the config hash tied to the curves."""
    readable = [n for n in names if n[:4].lower() == "csv:" and Path(n[4:].strip()).is_file()]
    return {"sensor_files": spectrum_files(readable)} if readable else {}


def portable_names(data: Any, base: str | Path | None = None) -> Any:
    """A copy of the plain data *data* (dicts, lists, strings) with every ``csv:`` name made
    portable (:func:`portable_csv`), wherever it stands (materials, lights, records); lists of
    plain numbers (a mesh's) copied whole (:mod:`~spectrinsic.number_lists`)."""
    if isinstance(data, str):
        return portable_csv(data, base) if data[:4].lower() == "csv:" else data
    if isinstance(data, dict):
        return {k: portable_names(v, base) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        if numbers_only(data):
            return copy_numbers(data)
        return [portable_names(v, base) for v in data]
    return data


def spectrum_files(names: Any, base: str | Path | None = None) -> list[dict[str, str]]:
    """One record per distinct ``csv:`` spectrum among *names* (paths the build can read): its
    portable name and file (:func:`portable_csv`, relative to *base*), column and the file's
    SHA-256, for ``meta.json`` (``spectrum_files``); a camera's sensor CSV (no column) by its
    portable name (:func:`portable_sensor_csv`)."""
    out = []
    for name in sorted({n for n in names if isinstance(n, str) and n.startswith("csv:")}):
        if "#" not in name:  # a camera's sensor set: by its file name
            portable = portable_sensor_csv(name)
            path = name.removeprefix("csv:").strip()
            out.append({"spectrum": portable, "file": portable[4:], "sha256": sha256(path)})
            continue
        path, key = split_csv_key(name.removeprefix("csv:"))
        column, unit = column_unit(key)
        portable = portable_csv(name, base)
        file = split_csv_key(portable.removeprefix("csv:"))[0]
        record = {"spectrum": portable, "file": file, "column": column, "sha256": sha256(path)}
        out.append(record | ({"unit": unit} if unit is not None else {}))
    return out
