"""Spectra given by file or inline in scene files and material maps, made self-standing names.

Where a scene file (or a ``--material-map``) names a spectrum it may also give

- ``csv:PATH#COLUMN``, a column of a CSV file (:mod:`spectrinsic.spectra.user_spectra`) whose
  PATH is relative to the scene's folder: absolute paths, paths leading out of the folder
  (``..``, symbolic links) and files over :data:`~spectrinsic.spectra.io.CSV_MAX_BYTES` are
  refused, so a shared scene folder reads nothing outside itself;
- ``{wavelengths: [...], values: [...]}``, samples written out (reflectances as fractions).

:func:`resolve_spectrum_refs` rewrites both in the parsed document before the scene is built:
``csv:`` with the file's resolved path, mappings as ``inline:KIND:...`` names. The spectra
themselves are read and checked with every other spectrum name by
:func:`~spectrinsic.scenes.validate.validate_scene`, before any work.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from ..errors import SceneError, SpectrinsicError
from ..spectra.io import CSV_MAX_BYTES
from ..spectra.user_spectra import inline_name, split_csv_key
from .model import GLASS_TINTS

__all__ = ["resolve_spectrum_refs", "resolve_spectrum", "confined_csv"]

_INLINE_KEYS = {"wavelengths", "values"}


def confined_csv(name: str, base: Path) -> str:
    """``csv:PATH#COLUMN`` with PATH resolved inside folder *base*; a one-phrase
    :class:`SceneError` otherwise (absolute, escaping, missing or too large)."""
    path, column = split_csv_key(name.strip()[4:])  # after "csv:", in any case
    if Path(path).is_absolute() or re.match(r"^[A-Za-z]:[\\/]", path):
        raise SceneError(
            f"absolute path {path!r} not allowed; give a path relative to the scene's folder"
        )
    root = base.resolve()
    resolved = (root / path).resolve()
    if not resolved.is_relative_to(root):
        raise SceneError(f"path {path!r} leads outside the scene's folder {str(root)!r}")
    if not resolved.is_file():
        raise SceneError(f"spectrum file {path!r} not found in {str(root)!r}")
    size = resolved.stat().st_size
    if size > CSV_MAX_BYTES:
        raise SceneError(f"spectrum file {path!r}: {size} bytes; expected <= {CSV_MAX_BYTES}")
    return f"csv:{resolved}#{column}"


def resolve_spectrum(value: Any, kind: str, base: Path) -> Any:
    """*value* as a self-standing spectrum name (module docstring); other values unchanged."""
    if isinstance(value, dict) and set(value) == _INLINE_KEYS:
        return inline_name(value["wavelengths"], value["values"], kind)
    if isinstance(value, dict) and _INLINE_KEYS & set(value):
        raise SceneError(
            f"expected exactly the keys 'wavelengths' and 'values' for an inline spectrum, got {sorted(value)}"
        )
    if isinstance(value, str) and value.strip().lower().startswith("csv:"):
        return confined_csv(value.strip(), base)
    return value


def _material(value: Any, base: Path) -> Any:
    if not isinstance(value, dict) or _INLINE_KEYS & set(value):
        return resolve_spectrum(value, "reflectance", base)
    out = dict(value)
    for key in ("spectrum", *GLASS_TINTS):  # a glass's tints are fractions too
        if key in out:
            out[key] = resolve_spectrum(out[key], "reflectance", base)
    if isinstance(out.get("basis"), list):
        out["basis"] = [resolve_spectrum(b, "reflectance", base) for b in out["basis"]]
    return out


def _field(source: str, field: str, fn: Any, *args: Any) -> Any:
    try:
        return fn(*args)
    except SpectrinsicError as exc:
        raise SceneError(f"{source}: {field}: {exc}") from None


def resolve_spectrum_refs(data: Any, base: str | Path, source: str) -> Any:
    """A copy of the parsed scene document *data* with file and inline spectra in its
    ``materials`` and ``lights`` made names (module docstring); anything else untouched.

    Raises
    ------
    SceneError
        ``"<source>: <field>: <problem>"``.
    """
    if not isinstance(data, dict):
        return data
    base = Path(base)
    out = dict(data)
    if isinstance(data.get("materials"), dict):
        out["materials"] = {
            k: _field(source, f"materials.{k}", _material, v, base)
            for k, v in data["materials"].items()
        }
    if isinstance(data.get("lights"), list):
        lights = []
        for i, light in enumerate(data["lights"]):
            if isinstance(light, dict) and "spectrum" in light:
                spectrum = _field(
                    source,
                    f"lights[{i}].spectrum",
                    resolve_spectrum,
                    light["spectrum"],
                    "illuminant",
                    base,
                )
                light = {**light, "spectrum": spectrum}
            lights.append(light)
        out["lights"] = lights
    return out
