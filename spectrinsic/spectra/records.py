"""Frozen records for spectra and sensor sets."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ..arrays import SensorCurves, SpectralValues, Wavelengths
from ..errors import SpectralDataError
from .grid import resample

__all__ = ["Spectrum", "SensorSet", "SpectrumKind"]

SpectrumKind = Literal["reflectance", "illuminant"]


@dataclass(frozen=True, eq=False)
class Spectrum:
    """A measured or computed spectrum on its own wavelength grid.

    Attributes
    ----------
    name
        Canonical registry name, e.g. ``"munsell:5R 4/14"``.
    kind
        ``"reflectance"`` (fraction in [0, 1]) or ``"illuminant"`` (relative spectral power,
        normalised to unit luminance-weighted mean: ``Σ L ȳ = Σ ȳ`` on its grid).
    wavelengths
        ``(W,)`` nm, strictly increasing.
    values
        ``(W,)`` float64.
    source
        Citation of the data.
    """

    name: str
    kind: SpectrumKind
    wavelengths: Wavelengths
    values: SpectralValues
    source: str = field(default="", repr=False)

    def __repr__(self) -> str:
        lo, hi = float(np.min(self.wavelengths)), float(np.max(self.wavelengths))
        return f"Spectrum({self.name!r}, {self.kind}, {self.wavelengths.size} samples, {lo:g}-{hi:g} nm)"

    def __post_init__(self) -> None:
        # validated wherever the data came from (package data, colour-science, a data
        # directory): a NaN would reach the pixels, a negative value crash Mitsuba
        values = np.asarray(self.values)
        if values.shape != np.shape(self.wavelengths) or values.size == 0:
            raise SpectralDataError(
                f"spectrum {self.name!r}: {values.shape} values for {np.shape(self.wavelengths)} "
                "wavelengths; expected one value per wavelength"
            )
        if not np.isfinite(values).all() or (values < 0).any():
            raise SpectralDataError(
                f"spectrum {self.name!r} ({self.source or 'no source'}): expected finite values "
                f">= 0, got min {np.nanmin(values) if not np.isnan(values).all() else 'nan'}"
                f"{' and NaN/inf' if not np.isfinite(values).all() else ''}"
            )
        if self.kind == "reflectance" and values.max() > 1.0:
            raise SpectralDataError(
                f"spectrum {self.name!r} ({self.source or 'no source'}): a reflectance reflects "
                f"at most all the light; expected values in [0, 1], got max {values.max():g}"
            )

    def on(self, wavelengths: Wavelengths) -> SpectralValues:
        """Values resampled onto *wavelengths* (nm), edge values held beyond the data."""
        return resample(self.wavelengths, self.values, wavelengths, outside="hold")


@dataclass(frozen=True, eq=False)
class SensorSet:
    """K sensor sensitivity curves (a camera, an observer, Gaussian or box bands).

    Attributes
    ----------
    name
        Canonical registry name, e.g. ``"gaussian:6@400-700"``.
    channels
        One label per curve, e.g. ``("R", "G", "B")``.
    wavelengths
        ``(W,)`` nm.
    curves
        ``(K, W)`` float64 relative sensitivities (may be negative for ``"srgb"``, whose curves
        are a linear transform of the CIE 1931 colour-matching functions).
    source
        Citation of the data.
    """

    name: str
    channels: tuple[str, ...]
    wavelengths: Wavelengths
    curves: SensorCurves
    source: str = field(default="", repr=False)

    def __post_init__(self) -> None:
        if not np.isfinite(np.asarray(self.curves)).all():
            raise SpectralDataError(
                f"sensor set {self.name!r} ({self.source}): NaN or inf in its curves"
            )

    @property
    def n(self) -> int:
        """Number of sensors K."""
        return len(self.channels)

    def on(self, wavelengths: Wavelengths) -> SensorCurves:
        """``(K, W')`` curves resampled onto *wavelengths*, zero outside the measured range."""
        return resample(self.wavelengths, self.curves, wavelengths, outside="zero")

    def __repr__(self) -> str:
        lo, hi = float(np.min(self.wavelengths)), float(np.max(self.wavelengths))
        return f"SensorSet({self.name!r}, channels={self.channels}, {lo:g}-{hi:g} nm)"
