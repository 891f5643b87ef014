"""Mitsuba XML colours and spectra as registry names, for :mod:`spectrinsic.scenes.mitsuba_xml`.

Values come from :mod:`~spectrinsic.scenes.mitsuba_tree` (Mitsuba's parser):

- a number (``<float>``, ``<spectrum value="0.5"/>``): ``flat:V`` as a reflectance, equal
  energy (``cie:E``) of power V as an emission;
- a colour (``<rgb value="0.6, 0.1, 0.1"/>``, ``<rgb value="5"/>``): ``rgb:R,G,B``, linear
  sRGB upsampled by Mallett & Yuksel 2019 (:mod:`~spectrinsic.spectra.user_spectra`), as a
  reflectance; a grey emission is D65 of power V (as Mitsuba's spectral variants emit it), a
  coloured one that colour's reflectance times D65, written out (its linear sRGB is the rgb);
- written-out samples (``<spectrum value="400:0.1, ..."/>``, a ``.spd`` file, ``irregular``,
  ``regular``): ``inline:KIND:...`` names; an emission keeps its absolute scale in the power
  (the registry normalises illuminants to unit luminance-weighted mean);
- ``blackbody`` (emission only): ``planck:TK`` with the power of Mitsuba's absolute Planck
  radiance, W m⁻² sr⁻¹ nm⁻¹ over 360–830 nm;
- ``<string value="csv:PATH#COLUMN"/>``: a column of a CSV file in the scene's folder
  (:func:`~spectrinsic.scenes.spectrum_refs.confined_csv`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import SceneError
from ..spectra import get_spectrum
from ..spectra.illuminants import normalise_illuminant
from ..spectra.user_spectra import inline_name
from .mitsuba_tree import Spectrum, Value, XmlNode
from .spectrum_refs import confined_csv

__all__ = ["reflectance_name", "emission", "planck_radiance"]

#: Planck's constant (J s), the speed of light (m/s) and Boltzmann's constant (J/K), as
#: Mitsuba's ``blackbody`` plugin takes them.
_H, _C, _K = 6.62607004e-34, 2.99792458e8, 1.38064852e-23


def planck_radiance(wavelengths_nm: np.ndarray, temperature: float) -> np.ndarray:
    """Black-body spectral radiance in W m⁻² sr⁻¹ nm⁻¹ (Planck's law, per metre × 1e-9), the
    values Mitsuba's ``blackbody`` emits."""
    lam = np.asarray(wavelengths_nm, float) * 1e-9
    return 2 * _H * _C**2 / lam**5 / np.expm1(_H * _C / (lam * _K * temperature)) * 1e-9


def _samples(value: Value, what: str) -> tuple[np.ndarray, np.ndarray] | None:
    """Wavelengths and values of written-out samples, or ``None`` for other forms."""
    if isinstance(value, Spectrum):
        return np.array(value.wavelengths), np.array(value.values)
    if isinstance(value, XmlNode) and value.plugin == "irregular":
        try:
            wl = [float(x) for x in str(value.props.get("wavelengths", "")).split(",")]
            vs = [float(x) for x in str(value.props.get("values", "")).split(",")]
        except ValueError:
            raise SceneError(f"{what}: {value.label()} needs comma-separated numbers") from None
        return np.array(wl), np.array(vs)
    if isinstance(value, XmlNode) and value.plugin == "regular":
        vs = [float(x) for x in str(value.props.get("values", "")).split(",")]
        lo = value.number("wavelength_min", 360.0)
        hi = value.number("wavelength_max", 830.0)
        return np.linspace(lo, hi, len(vs)), np.array(vs)
    return None


def _unsupported(value: Value, what: str, role: str) -> SceneError:
    shown = value.label() if isinstance(value, XmlNode) else repr(value)
    return SceneError(f"{what}: unsupported {role} {shown}; expected rgb, spectrum or float")


def reflectance_name(value: Value | None, what: str, base: Path) -> str:
    """The reflectance spectrum name of a BSDF parameter (Mitsuba's default 0.5 for ``None``);
    a ``bitmap`` is refused here (the caller may approximate it)."""
    if value is None:
        return "flat:0.5"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return f"flat:{float(value):.9g}"
    if isinstance(value, XmlNode) and value.plugin == "uniform":
        return f"flat:{value.number('value', 0.5):.9g}"
    if isinstance(value, np.ndarray) and value.size == 3:
        return "rgb:" + ",".join(f"{c:.9g}" for c in value)
    if isinstance(value, str) and value.strip().lower().startswith("csv:"):
        return confined_csv(value.strip(), base)
    samples = _samples(value, what)
    if samples is None:
        raise _unsupported(value, what, "reflectance")
    return inline_name(*samples, "reflectance", where=what)


def _absolute(wl: np.ndarray, values: np.ndarray, what: str) -> tuple[str, float]:
    if not (np.diff(wl) > 0).all() or not (values >= 0).all():
        raise SceneError(f"{what}: expected increasing wavelengths and values >= 0")
    power = float(values.sum() / normalise_illuminant(wl, values).sum())
    return inline_name(wl, values, "illuminant", where=what), power


def _rgb_emission(rgb: np.ndarray, what: str) -> tuple[str, float]:
    """A grey ``rgb`` emission as D65 of that power; a coloured one as the reflectance of its
    colour (over its largest channel) times D65 (unit luminance) times that channel, written
    out every 5 nm: under D65 the basis keeps linear sRGB, so the light's colour is *rgb*."""
    if not (np.isfinite(rgb).all() and (rgb >= 0).all() and rgb.max() > 0):
        raise SceneError(f"{what}: rgb emission {rgb.tolist()}; expected channels >= 0, not all 0")
    if np.ptp(rgb) == 0:
        return "cie:D65", float(rgb[0])
    scale = float(rgb.max())
    wl = np.arange(360.0, 831.0, 5.0)
    colour = get_spectrum("rgb:" + ",".join(f"{c / scale:.9g}" for c in rgb)).on(wl)
    return _absolute(wl, colour * get_spectrum("cie:D65").on(wl) * scale, what)


def emission(value: Value | None, what: str, base: Path) -> tuple[str, float]:
    """``(illuminant name, power)`` of an emitter's radiance, intensity or irradiance."""
    if value is None:
        raise SceneError(f"{what}: the emitter gives no radiance, intensity or irradiance")
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return "cie:E", float(value)
    if isinstance(value, np.ndarray) and value.size == 3:
        return _rgb_emission(value, what)
    if isinstance(value, XmlNode) and value.plugin == "blackbody":
        extra = set(value.props) - {"temperature"}
        if extra:
            raise SceneError(f"{what}: unsupported {sorted(extra)} in {value.label()}")
        t = value.number("temperature", 0.0)
        if not 0 < t < 1e5:
            raise SceneError(f"{what}: blackbody temperature {t}; expected 0 < T < 100000 K")
        wl = np.arange(360.0, 831.0)
        _, power = _absolute(wl, planck_radiance(wl, t), what)
        return f"planck:{t:g}K", power
    if isinstance(value, str) and value.strip().lower().startswith("csv:"):
        return confined_csv(value.strip(), base), 1.0
    samples = _samples(value, what)
    if samples is None:
        raise _unsupported(value, what, "emission")
    return _absolute(*samples, what)
