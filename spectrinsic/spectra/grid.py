"""Wavelength grids and resampling.

Every wavelength in spectrinsic is in nm. Two grids matter:

* :data:`DEFAULT_WAVELENGTHS`, 380–780 nm at 5 nm, on which renders and studies work;
* :data:`COLORIMETRIC_WAVELENGTHS`, 360–830 nm at 1 nm, the native grid of the CIE 1931
  colour-matching functions, on which exact ground-truth colours are integrated.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from ..arrays import SpectralValues, Wavelengths
from ..errors import SpectralDataError

__all__ = [
    "DEFAULT_WAVELENGTHS",
    "COLORIMETRIC_WAVELENGTHS",
    "wavelength_grid",
    "validate_wavelengths",
    "integration_weights",
    "resample",
]


def wavelength_grid(start: float = 380.0, end: float = 780.0, step: float = 5.0) -> Wavelengths:
    """Return the grid ``start, start + step, ..., end`` in nm (end included).

    >>> wavelength_grid(400, 700, 100).tolist()
    [400.0, 500.0, 600.0, 700.0]
    """
    if not (step > 0 and end > start):
        raise SpectralDataError(
            f"wavelength grid {start}-{end} nm step {step}: expected end > start and step > 0"
        )
    n = int(round((end - start) / step)) + 1
    return start + step * np.arange(n, dtype=np.float64)


DEFAULT_WAVELENGTHS: Wavelengths = wavelength_grid(380.0, 780.0, 5.0)
COLORIMETRIC_WAVELENGTHS: Wavelengths = wavelength_grid(360.0, 830.0, 1.0)


def validate_wavelengths(wavelengths: object, what: str = "wavelengths") -> Wavelengths:
    """Return *wavelengths* as a float64 array, or raise if empty or not strictly increasing."""
    wl = np.asarray(wavelengths, dtype=np.float64)
    if wl.ndim != 1 or wl.size < 2:
        raise SpectralDataError(
            f"{what}: expected at least 2 wavelengths in nm, got shape {wl.shape}"
        )
    if not np.all(np.isfinite(wl)):
        raise SpectralDataError(f"{what}: wavelengths must be finite numbers (nm)")
    if not np.all(np.diff(wl) > 0):
        bad = int(np.argmin(np.diff(wl) > 0)) + 1
        raise SpectralDataError(
            f"{what}: wavelengths must be strictly increasing; value {wl[bad]:g} nm at "
            f"position {bad} follows {wl[bad - 1]:g} nm"
        )
    return wl


def integration_weights(wavelengths: Wavelengths) -> np.ndarray:
    """Per-sample Δλ (nm) of the rectangle rule ``∫ f dλ ≈ Σ f_i Δλ_i``.

    On a uniform grid every weight is the step, as in colour-science's ``"Integration"`` method
    of ``sd_to_XYZ``; on a non-uniform grid, the local spacing (``numpy.gradient``).
    """
    wl = np.asarray(wavelengths, dtype=np.float64)
    return np.gradient(wl)


def resample(
    wavelengths: Wavelengths,
    values: SpectralValues,
    target: Wavelengths,
    *,
    outside: Literal["hold", "zero"] = "hold",
) -> SpectralValues:
    """Linearly interpolate ``values`` (``(W,)`` or ``(N, W)``) from *wavelengths* onto *target*.

    Parameters
    ----------
    outside
        ``"hold"`` repeats the edge values beyond the measured range (reflectances,
        illuminants); ``"zero"`` sets them to 0 (sensor sensitivities).
    """
    wl = np.asarray(wavelengths, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    tgt = np.asarray(target, dtype=np.float64)
    flat = v.reshape(-1, wl.size)
    out = np.empty((flat.shape[0], tgt.size))
    for i, row in enumerate(flat):
        if outside == "zero":
            out[i] = np.interp(tgt, wl, row, left=0.0, right=0.0)
        else:
            out[i] = np.interp(tgt, wl, row)
    return out.reshape(v.shape[:-1] + (tgt.size,))
