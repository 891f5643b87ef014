"""One registry of spectra and sensor sets with names people can type.

A name is ``family:key``. Reflectances and illuminants (:func:`get_spectrum`):

============  ====================================  ===========================================
family        example                               source
============  ====================================  ===========================================
munsell       ``munsell:5R 4/14``, ``munsell:#12``  1269 matte Munsell chips (luxpy wheel)
colorchecker  ``colorchecker:dark skin``            BabelColor average (colour-science)
sfu           ``sfu:munsell/17``, ``sfu:krinov/3``  Barnard et al. 2002 (data directory)
flat          ``flat:0.5``                          spectrally flat grey
planck        ``planck:2800K``                      Planck's law (Eq. B.1)
daylight      ``daylight:6500K``                    CIE D-series at any CCT
cie           ``cie:D65``, ``cie:FL11``             colour-science ``SDS_ILLUMINANTS``
light         ``light:Cool White FL``               colour-science ``SDS_LIGHT_SOURCES``
sfu-illum     ``sfu-illum:mws_090``                 Barnard et al. 2002 (data directory)
mix           ``mix:0.3*munsell:5R 4/14+0.7*...``  convex combination (spectral textures)
led           ``led:460/20``, ``led:630/20@1+...``  narrow-band / mixed LEDs (Ohno 2005)
filtered      ``filtered:cie:A|bandpass:520/80``    a lamp behind a generated colour filter
csv           ``csv:paints.csv#red``                a user's CSV column, unit in its header
inline        ``inline:reflectance:400=0.1,...``    written-out samples
rgb, srgb     ``rgb:0.8,0.2,0.1``, ``srgb:#cc3311``  Mallett & Yuksel 2019 uplift of a colour
rgblight      ``rgblight:1,0,0``                    that uplift times D65 (an envmap channel)
============  ====================================  ===========================================

Sensor sets (:func:`get_sensors`): ``cie1931``, ``srgb``, ``gaussian:6@400-700``,
``bands:31@400-700``, ``camera:Nikon 5100 (NPL)``, ``csv:/path/to/file.csv``.

Everything is loaded lazily on first use.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Mapping

import numpy as np

from ..data_dir import resolve_data_dir
from ..errors import SpectrumNotFoundError, did_you_mean
from . import coloured_lights, illuminants, io, reflectances, sensors, user_spectra
from .records import SensorSet, Spectrum

__all__ = [
    "get_spectrum",
    "get_sensors",
    "list_spectra",
    "family_values",
    "SPECTRUM_FAMILIES",
    "SPECTRUM_FAMILY_NOTES",
    "SENSOR_FAMILIES",
]

DataDir = str | os.PathLike[str] | None


#: family -> loader(key, data_dir)
SPECTRUM_FAMILIES: dict[str, Callable[[str, str | None], Spectrum]] = {
    "munsell": lambda k, d: reflectances.munsell(k),
    "colorchecker": lambda k, d: reflectances.colorchecker(k),
    "sfu": reflectances.sfu_reflectance,
    "flat": lambda k, d: reflectances.flat(k),
    "planck": lambda k, d: illuminants.planckian(k),
    "daylight": lambda k, d: illuminants.daylight(k),
    "cie": lambda k, d: illuminants.cie_illuminant(k),
    "light": lambda k, d: illuminants.light_source(k),
    "sfu-illum": illuminants.sfu_illuminant,
    "mix": lambda k, d: reflectances.mix(k, lambda name: get_spectrum(name, data_dir=d)),
    "led": lambda k, d: coloured_lights.led(k),
    "filtered": lambda k, d: coloured_lights.filtered(
        k, lambda lamp: get_spectrum(lamp, data_dir=d)
    ),
    "csv": lambda k, d: user_spectra.csv_spectrum(k),
    "inline": lambda k, d: user_spectra.inline_spectrum(k),
    "rgb": lambda k, d: user_spectra.rgb_spectrum(k),
    "srgb": lambda k, d: user_spectra.srgb_spectrum(k),
    "rgblight": lambda k, d: user_spectra.rgb_light_spectrum(k),
}

#: family -> example and source, the module table as data (``spectrinsic list spectra``).
SPECTRUM_FAMILY_NOTES: dict[str, str] = {
    "munsell": "munsell:5R 4/14 or munsell:#12; 1269 matte Munsell chips (luxpy wheel)",
    "colorchecker": "colorchecker:dark skin; BabelColor average (colour-science)",
    "sfu": "sfu:krinov/3; Barnard et al. 2002 reflectances (data directory)",
    "flat": "flat:0.5; spectrally flat grey of that reflectance",
    "planck": "planck:2800K; Planck's law (Eq. B.1), any temperature",
    "daylight": "daylight:6500K; CIE D-series at any CCT",
    "cie": "cie:D65, cie:FL11; colour-science SDS_ILLUMINANTS",
    "light": "light:Cool White FL; colour-science SDS_LIGHT_SOURCES",
    "sfu-illum": "sfu-illum:mws_090; Barnard et al. 2002 illuminants (data directory)",
    "mix": "mix:0.3*munsell:5R 4/14+0.7*munsell:5B 6/8; convex combination of reflectances",
    "led": "led:460/20 or led:630/20@1+530/30@0.6; narrow-band and mixed LEDs (Ohno 2005)",
    "filtered": "filtered:planck:3200K|bandpass:520/80; a lamp behind a generated colour filter",
    "csv": "csv:paints.csv#red; a column of your CSV, unit in its header ([%], [1], [W/m2/nm])",
    "inline": "inline:reflectance:400=0.1,700=0.5; samples written out (YAML: wavelengths/values)",
    "rgb": "rgb:0.8,0.2,0.1; linear sRGB as a reflectance (Mallett & Yuksel 2019)",
    "srgb": "srgb:#cc3311 or srgb:0.8,0.2,0.1; sRGB-encoded colour as a reflectance",
    "rgblight": "rgblight:1,0,0; linear sRGB as a light: Mallett & Yuksel basis times D65",
}

#: family -> loader(key, data_dir); families without a key take an empty key.
SENSOR_FAMILIES: dict[str, Callable[[str, str | None], SensorSet]] = {
    "cie1931": lambda k, d: sensors.cie1931(),
    "srgb": lambda k, d: sensors.srgb(),
    "gaussian": lambda k, d: sensors.gaussian(k),
    "bands": lambda k, d: sensors.bands(k),
    "camera": sensors.camera,
    "csv": lambda k, d: sensors.user_csv(k),
}


def _split(name: str, families: Mapping[str, object], what: str) -> tuple[str, str]:
    if not isinstance(name, str) or not name.strip():
        raise SpectrumNotFoundError(
            f"{what} name {name!r}: expected 'family:key', e.g. 'munsell:5R 4/14'"
        )
    family, sep, key = name.strip().partition(":")
    family = family.strip().lower()
    if family not in families:
        raise SpectrumNotFoundError(
            f"unknown {what} family {family!r} in {name!r}; expected one of "
            f"{', '.join(sorted(families))}" + did_you_mean(family, families)
        )
    return family, key.strip() if sep else ""


def _data(data_dir: DataDir) -> str | None:
    root = resolve_data_dir(data_dir)
    return None if root is None else str(root)


def get_spectrum(name: str, *, data_dir: DataDir = None) -> Spectrum:
    """Return the reflectance or illuminant called *name* (see the module table).

    Raises
    ------
    SpectrumNotFoundError
        Unknown family or key, with close matches suggested.
    DataDirectoryError
        A data-directory family (``sfu``, ``sfu-illum``) without a configured directory.
    """
    family, key = _split(name, SPECTRUM_FAMILIES, "spectrum")
    # a filtered lamp may be an SFU illuminant, so it gets the data directory too
    needs_data = family.startswith("sfu") or family in ("filtered", "mix")
    return SPECTRUM_FAMILIES[family](key, _data(data_dir) if needs_data else None)


def get_sensors(name: str, *, data_dir: DataDir = None) -> SensorSet:
    """Return the sensor set called *name*, e.g. ``"gaussian:6@400-700"`` or ``"camera:Nikon D50"``."""
    family, key = _split(name, SENSOR_FAMILIES, "sensor set")
    return SENSOR_FAMILIES[family](key, _data(data_dir) if family == "camera" else None)


def list_spectra(family: str, *, data_dir: DataDir = None) -> list[str]:
    """Full names of every spectrum of an enumerable family.

    Enumerable: ``munsell``, ``colorchecker``, ``sfu``, ``cie``, ``light``, ``sfu-illum``,
    ``camera`` (sensor sets). ``planck``, ``daylight`` and ``flat`` are continuous.
    """
    import colour

    listing: dict[str, Callable[[], list[str]]] = {
        "munsell": reflectances.munsell_names,
        "colorchecker": reflectances.colorchecker_names,
        "sfu": lambda: reflectances.sfu_reflectance_names(_data(data_dir)),
        "cie": lambda: list(colour.SDS_ILLUMINANTS),
        "light": lambda: list(colour.SDS_LIGHT_SOURCES),
        "sfu-illum": lambda: list(io.read_sfu_illuminants(_data(data_dir)).labels),
        "camera": lambda: sensors.camera_names(_data(data_dir)),
    }
    if family not in listing:
        raise SpectrumNotFoundError(
            f"family {family!r} cannot be listed; expected one of {', '.join(listing)}"
            + did_you_mean(family, listing)
        )
    return [f"{family}:{k}" for k in listing[family]()]


def family_values(family: str, wavelengths: np.ndarray, *, data_dir: DataDir = None) -> np.ndarray:
    """``(N, W)`` values of every spectrum of a listable family (``"munsell"``, ``"sfu"``...),
    in :func:`list_spectra` order, resampled onto *wavelengths* (nm).

    Read-only and cached per family, grid and data directory: resampling the 1269 Munsell chips
    costs tens of milliseconds, and renders, ground truth and studies all need them.
    """
    grid = tuple(np.asarray(wavelengths, float).ravel().tolist())
    return _family_values(family, grid, _data(data_dir))


@functools.lru_cache(maxsize=8)
def _family_values(family: str, grid: tuple[float, ...], data_dir: str | None) -> np.ndarray:
    wl = np.asarray(grid)
    names = list_spectra(family, data_dir=data_dir)
    table = np.stack([get_spectrum(n, data_dir=data_dir).on(wl) for n in names])
    table.setflags(write=False)
    return table
