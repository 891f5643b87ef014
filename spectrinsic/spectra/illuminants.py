"""Illuminant spectral power distributions.

Every illuminant is normalised to unit luminance-weighted mean, ``Σ L(λ) ȳ(λ) = Σ ȳ(λ)`` on
its own grid, so that a perfect white under any light has luminance Y = 1 and a light's
brightness is set only by its ``power``.

A light that is not one the eye can see is refused rather than scaled up through its tails:
its *visible share* ``∫ L ȳ dλ / (max ȳ · ∫ L dλ)`` (1 for a monochromatic 555 nm light, about
0.4 for daylight) must be at least :data:`VISIBLE_SHARE` (UV or IR LEDs, a black body of a few
hundred kelvin).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..errors import SpectralDataError, SpectrumNotFoundError, did_you_mean, validate_choice
from . import io
from .grid import wavelength_grid
from .records import Spectrum

__all__ = [
    "planck_law",
    "planckian",
    "daylight",
    "cie_illuminant",
    "light_source",
    "sfu_illuminant",
    "normalise_illuminant",
    "illuminant_set",
    "ILLUMINANT_SETS",
    "VISIBLE_SHARE",
    "visible_share",
    "ybar_at",
]

#: Smallest visible share (module notes) of an illuminant: below it almost all its power is
#: where the eye is insensitive, and unit-luminance scaling would blow its invisible part up.
VISIBLE_SHARE = 1e-4

#: Named sets of 5 like thesis Appendix B, drawn from what the dependencies ship. Planckian:
#: a wide range of common colour temperatures. Non-Planckian: fluorescent (broadband, narrow
#: tri-band), an RGB LED, a high-pressure sodium and a phosphor LED.
ILLUMINANT_SETS: dict[str, tuple[str, ...]] = {
    "planckian": ("planck:2000K", "planck:2800K", "planck:4000K", "planck:6500K", "planck:10000K"),
    "non-planckian": ("cie:FL2", "cie:FL11", "cie:LED-RGB1", "cie:HP1", "cie:LED-B3"),
}


def illuminant_set(name: str) -> tuple[str, ...]:
    """The 5 spectrum names of set ``"planckian"`` or ``"non-planckian"``."""
    return ILLUMINANT_SETS[
        validate_choice(name, ILLUMINANT_SETS, "illuminant set", error=SpectrumNotFoundError)
    ]


@functools.lru_cache(maxsize=1)
def _ybar() -> tuple[np.ndarray, np.ndarray]:
    """CIE 1931 ȳ ``(W,)`` and its wavelengths ``(W,)`` nm (360-830 at 1 nm), read-only."""
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wavelengths = np.array(cmfs.wavelengths, dtype=float)  # copies: colour's own stay writable
    ybar = np.array(cmfs.values[:, 1], dtype=float)
    for array in (wavelengths, ybar):
        array.flags.writeable = False  # cached: shared by every caller
    return wavelengths, ybar


def ybar_at(wavelengths: np.ndarray) -> np.ndarray:
    """CIE 1931 ȳ (peak 1 at 555 nm) at *wavelengths* nm, 0 outside 360-830 nm."""
    wl_y, y = _ybar()
    return np.interp(np.asarray(wavelengths, float), wl_y, y, left=0.0, right=0.0)


def _dense(wavelengths: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The spectrum on its own samples and every whole nanometre between them, linearly
    interpolated (what a spectrum given by a few samples means: two samples at 380 and 780 nm
    have power where the eye is sensitive, though ȳ is 0 at both)."""
    wl = np.asarray(wavelengths, float)
    v = np.asarray(values, float)
    if len(wl) < 2:
        return wl, v
    grid = np.union1d(wl, np.arange(np.ceil(wl[0]), np.floor(wl[-1]) + 1.0))
    return grid, np.interp(grid, wl, v)


def visible_share(wavelengths: np.ndarray, values: np.ndarray) -> float:
    """``∫ L ȳ dλ / (max ȳ · ∫ L dλ)`` of a spectrum *values* on *wavelengths* (nm), in [0, 1]
    for non-negative values: the luminance-weighted share of its power (0 without any).

    >>> round(visible_share(np.array([554.0, 555.0, 556.0]), np.array([0.0, 1.0, 0.0])), 6)
    1.0
    """
    wl, v = _dense(wavelengths, values)
    ybar = ybar_at(wl)
    dl = np.gradient(wl) if len(wl) > 1 else np.ones_like(wl)
    total = float(np.sum(np.abs(v) * dl)) * float(_ybar()[1].max())
    return float(np.sum(v * ybar * dl)) / total if total > 0 else 0.0


#: Peak above which an illuminant is divided by its peak before its sums (float64 overflows
#: near 1.8e308; a sum over 471 samples of values above 1e150 squared would too).
_RESCALE_ABOVE = 1e150


def normalise_illuminant(wavelengths: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Scale *values* so that ``Σ L ȳ = Σ ȳ`` over *wavelengths* (ȳ: CIE 1931 2°); refuse a light
    with no power where the eye is sensitive, or a visible share below :data:`VISIBLE_SHARE`.
    Values above :data:`_RESCALE_ABOVE` are divided by their peak first (the result is the
    same: only the shape counts), so sums of a 1e308 spectrum stay finite."""
    peak = float(np.max(np.abs(values))) if np.size(values) else 0.0
    if math.isfinite(peak) and peak > _RESCALE_ABOVE:
        values = np.asarray(values, float) / peak
    ybar = ybar_at(wavelengths)
    lum = float(np.sum(values * ybar))
    if not lum > 0:
        raise SpectralDataError("illuminant has no power where the eye is sensitive (380-780 nm)")
    share = visible_share(wavelengths, values)
    if not share >= VISIBLE_SHARE:
        raise SpectralDataError(
            f"illuminant has a visible share of {share:.2g} (luminance-weighted), below "
            f"{VISIBLE_SHARE:g}: almost all its power is where the eye is insensitive"
        )
    return values * (float(np.sum(ybar)) / lum)


def _illuminant(name: str, wl: np.ndarray, values: np.ndarray, source: str) -> Spectrum:
    wl = np.asarray(wl, float)
    return Spectrum(
        name, "illuminant", wl, normalise_illuminant(wl, np.asarray(values, float)), source
    )


def planck_law(wavelengths_nm: np.ndarray, temperature: float) -> np.ndarray:
    """Spectral radiance of a black body, W·sr⁻¹·m⁻²·m⁻¹, at wavelengths in nm (thesis Eq. B.1).

    ``R(λ, T) = c1 λ⁻⁵ / (exp(c2 / (λ T)) − 1)`` with c1 = 2hc² (radiance; the exitance form's
    2πhc² divided by π) and c2 = 1.4388e-2 m·K (CIE 015:2018), evaluated by colour-science's ``planck_law`` on λ in
    metres. Only the shape matters downstream: illuminants are normalised.
    """
    import colour

    if not temperature > 0:
        raise SpectralDataError(f"Planckian temperature {temperature!r} K: expected T > 0")
    wl = np.asarray(wavelengths_nm, float)
    with np.errstate(over="ignore", under="ignore"):  # exp overflow: 0 radiance, said after
        values = colour.colorimetry.planck_law(wl.ravel() * 1e-9, float(temperature))
    return np.asarray(values, float).reshape(wl.shape)


def _kelvin(key: str, what: str) -> float:
    text = key.strip().upper().removesuffix("K").strip()
    try:
        t = float(text)
    except ValueError:
        raise SpectrumNotFoundError(
            f"{what} {key!r}: expected a temperature like '2800K'"
        ) from None
    if not 0 < t < float("inf"):
        raise SpectralDataError(f"{what} {key!r}: temperature must be a finite number > 0 K")
    return t


def planckian(key: str) -> Spectrum:
    """A black body at a temperature, e.g. ``"2800K"`` (360–830 nm at 1 nm)."""
    t = _kelvin(key, "Planckian temperature")
    wl = wavelength_grid(360.0, 830.0, 1.0)
    return _illuminant(f"planck:{t:g}K", wl, planck_law(wl, t), "Planck's law (thesis Eq. B.1)")


def daylight(key: str) -> Spectrum:
    """CIE daylight (D-series) at a correlated colour temperature, e.g. ``"6500K"`` (4000–25000 K)."""
    import colour

    t = _kelvin(key, "daylight CCT")
    if not 4000 <= t <= 25000:
        raise SpectralDataError(f"daylight CCT {key!r}: CIE daylight is defined for 4000-25000 K")
    xy = colour.temperature.CCT_to_xy_CIE_D(t)
    sd = colour.sd_CIE_illuminant_D_series(xy)
    return _illuminant(f"daylight:{t:g}K", sd.wavelengths, sd.values, "CIE 015:2018 daylight")


def _colour_dataset(table: str, key: str, family: str, what: str, source: str) -> Spectrum:
    """Spectrum *key* of colour-science's dataset ``colour.<table>``, named ``<family>:<key>``."""
    import colour

    sds = getattr(colour, table)
    if key not in sds:
        raise SpectrumNotFoundError(f"unknown {what} {key!r}" + did_you_mean(key, sds))
    sd = sds[key]
    return _illuminant(f"{family}:{key}", sd.wavelengths, sd.values, source)


def cie_illuminant(key: str) -> Spectrum:
    """A CIE standard illuminant shipped by colour-science: A, D50, D65, FL1–FL12, LED-*, HP*..."""
    return _colour_dataset(
        "SDS_ILLUMINANTS", key, "cie", "CIE illuminant", "CIE illuminants via colour-science"
    )


def light_source(key: str) -> Spectrum:
    """A measured light source from colour-science's ``SDS_LIGHT_SOURCES``."""
    return _colour_dataset(
        "SDS_LIGHT_SOURCES", key, "light", "light source", "colour-science SDS_LIGHT_SOURCES"
    )


def sfu_illuminant(key: str, data_dir: str | None = None) -> Spectrum:
    """An SFU illuminant by id: ``"mws_081"`` (measured + lab sources) or ``"train_001"``."""
    table = io.read_sfu_illuminants(data_dir)
    if key not in table.labels:
        raise SpectrumNotFoundError(
            f"unknown SFU illuminant {key!r}; expected 'mws_000'..'mws_101' or 'train_001'..'train_087'"
            + did_you_mean(key, table.labels)
        )
    i = table.labels.index(key)
    return _illuminant(
        f"sfu-illum:{key}",
        table.wavelengths,
        table.values[i],
        "Barnard et al., Color Res. Appl. 27(3):147-151, 2002",
    )
