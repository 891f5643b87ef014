"""Saturated light sources: narrow-band and mixed LEDs, and lamps behind coloured filters.

Names (registry families ``led`` and ``filtered``):

* ``led:460/20``: one LED of peak 460 nm and FWHM 20 nm (Ohno 2005 model, colour-science's
  ``sd_single_led_Ohno2005``).
* ``led:630/20@1+530/30@0.6+460/25@0.3``: several LEDs in one lamp (RGB-mix LEDs); each term is
  ``peak/fwhm@peak-power-ratio`` (their sum, as Ohno 2005's multi-LED model).
* ``filtered:planck:3200K|bandpass:520/80``: a lamp (any illuminant name) times a filter's
  transmission ``T(λ)``, ``E_f(λ) = E(λ) T(λ)``. Filters are smooth gel-like curves generated
  here (no measured filter data ships with the dependencies; colour-science's only filter is a
  diffuser): ``bandpass:C/W`` (super-Gaussian of centre C and FWHM W nm),
  ``longpass:E/W`` and ``shortpass:E/W`` (logistic edge at E nm, 10-90 % rise over W nm), each
  leaking :data:`FILTER_FLOOR` outside its pass band like real gels.

All are illuminants, normalised like every other (unit luminance-weighted mean). An LED peaks
inside :data:`LED_PEAKS`; a filtered lamp is an illuminant whose pass band transmits at least
:data:`~spectrinsic.spectra.illuminants.VISIBLE_SHARE` of its luminance; each light's visible
share is checked as for every illuminant.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable

import numpy as np

from ..errors import SpectralDataError, SpectrumNotFoundError
from .grid import wavelength_grid
from .illuminants import VISIBLE_SHARE, normalise_illuminant, ybar_at
from .records import Spectrum

__all__ = ["FILTER_FLOOR", "FILTERS", "LED_PEAKS", "filter_transmission", "led", "filtered"]

#: Transmission of a filter far outside its pass band (theatre gels leak about 1 %).
FILTER_FLOOR = 0.01
#: Peak wavelengths (nm) an LED may have: the range illuminants are sampled on.
LED_PEAKS = (360.0, 830.0)
_NUM = r"(\d+(?:\.\d+)?)"
_LED_TERM = re.compile(rf"^{_NUM}/{_NUM}(?:@{_NUM})?$")
_FILTER = re.compile(rf"^(bandpass|longpass|shortpass):{_NUM}/{_NUM}$")
#: 10-90 % rise of a logistic: 2 ln 9 scale lengths.
_RISE = 2.0 * math.log(9.0)


def _bandpass(wl: np.ndarray, centre: float, width: float) -> np.ndarray:
    # exponent 4: flatter top and steeper sides than a Gaussian; T = 1/2 at centre ± width/2
    return np.exp(-math.log(2.0) * ((wl - centre) / (width / 2.0)) ** 4)


def _longpass(wl: np.ndarray, edge: float, width: float) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-(wl - edge) * _RISE / width))


def _shortpass(wl: np.ndarray, edge: float, width: float) -> np.ndarray:
    return 1.0 - _longpass(wl, edge, width)


#: Filter shapes by name: ``(wavelengths nm, position nm, width nm) -> pass fraction in [0, 1]``.
FILTERS: dict[str, Callable[[np.ndarray, float, float], np.ndarray]] = {
    "bandpass": _bandpass,
    "longpass": _longpass,
    "shortpass": _shortpass,
}


def _pass_band(spec: str, wavelengths: np.ndarray) -> np.ndarray:
    """The pass band in [0, 1] of filter *spec* at *wavelengths* nm, without the leak."""
    m = _FILTER.match(spec.strip())
    if not m or not float(m.group(3)) > 0:
        raise SpectrumNotFoundError(
            f"filter {spec!r}: expected bandpass:CENTRE/FWHM, longpass:EDGE/RISE or "
            "shortpass:EDGE/RISE in nm, e.g. 'bandpass:520/80'"
        )
    return FILTERS[m.group(1)](np.asarray(wavelengths, float), float(m.group(2)), float(m.group(3)))


def filter_transmission(spec: str, wavelengths: np.ndarray) -> np.ndarray:
    """Transmission in [FILTER_FLOOR, 1] of filter *spec* (``"bandpass:520/80"``) at *wavelengths* nm."""
    return FILTER_FLOOR + (1.0 - FILTER_FLOOR) * _pass_band(spec, wavelengths)


def led(key: str) -> Spectrum:
    """One LED (``"460/20"``) or several in one lamp (``"630/20@1+530/30@0.5"``), 360-830 nm."""
    import colour

    terms = [_LED_TERM.match(t.strip()) for t in key.split("+")]
    if not key.strip() or not all(terms) or any(float(m.group(2)) <= 0 for m in terms if m):
        raise SpectrumNotFoundError(
            f"LED {key!r}: expected PEAK/FWHM in nm, or a mix PEAK/FWHM@RATIO+..., e.g. "
            "'led:460/20' or 'led:630/20@1+530/30@0.5'"
        )
    peaks, fwhm, ratio = (
        np.array([float(m.group(i) or 1.0) for m in terms if m]) for i in (1, 2, 3)
    )
    lo, hi = LED_PEAKS
    if not np.all((peaks >= lo) & (peaks <= hi)):
        raise SpectralDataError(
            f"LED {key!r}: peak {peaks[(peaks < lo) | (peaks > hi)][0]:g} nm is outside "
            f"{lo:g}-{hi:g} nm, the visible range spectra are sampled on (a UV or IR LED)"
        )
    shape = colour.SpectralShape(360, 830, 1)
    # the sum of single LEDs, as sd_multi_leds_Ohno2005 defines it (colour 0.4.6's own returns
    # NaN where an LED's tail underflows)
    singles = [
        colour.colorimetry.sd_single_led_Ohno2005(p, w, shape=shape).values
        for p, w in zip(peaks, fwhm, strict=True)
    ]
    wl = wavelength_grid(360.0, 830.0, 1.0)
    values = np.nan_to_num(np.einsum("i,iw->w", ratio, np.asarray(singles, float)))
    source = "Ohno (2005) LED model via colour-science sd_single_led_Ohno2005"
    return Spectrum(
        f"led:{key.strip()}", "illuminant", wl, normalise_illuminant(wl, values), source
    )


def _check_passes_visible(key: str, wl: np.ndarray, lamp: np.ndarray, band: np.ndarray) -> None:
    """Refuse a filter whose pass band transmits less than :data:`VISIBLE_SHARE` of the lamp's
    luminance (its leak alone would give back the lamp's own shape)."""
    ybar = ybar_at(wl)
    lum = float(np.sum(lamp * ybar))
    passed = float(np.sum(lamp * band * ybar)) / lum if lum > 0 else 0.0
    if not passed >= VISIBLE_SHARE:
        raise SpectralDataError(
            f"filtered light {key!r}: the filter's pass band transmits {passed:.2g} of the "
            f"lamp's luminance (below {VISIBLE_SHARE:g}); it blocks all the visible light"
        )


def filtered(key: str, lamp: Callable[[str], Spectrum]) -> Spectrum:
    """Lamp times filter: *key* is ``"<lamp name>|<filter>"``; *lamp* resolves the lamp's name."""
    name, sep, spec = key.rpartition("|")
    if not sep or not name.strip():
        raise SpectrumNotFoundError(
            f"filtered light {key!r}: expected LAMP|FILTER, e.g. 'filtered:planck:3200K|bandpass:520/80'"
        )
    base = lamp(name.strip())
    if base.kind != "illuminant":
        raise SpectralDataError(
            f"filtered light {key!r}: lamp {name.strip()!r} is a {base.kind} spectrum; "
            "expected an illuminant (planck:3200K, cie:A, ...)"
        )
    wl = np.asarray(base.wavelengths, float)
    band = _pass_band(spec, wl)
    _check_passes_visible(key, wl, base.values, band)
    values = base.values * (FILTER_FLOOR + (1.0 - FILTER_FLOOR) * band)
    source = f"{base.source}; generated filter {spec.strip()}"
    return Spectrum(
        f"filtered:{name.strip()}|{spec.strip()}",
        "illuminant",
        wl,
        normalise_illuminant(wl, values),
        source,
    )
