"""Image-space helpers of ground truth: coverage-weighted colour, the ratio shading, relative
error maps and light shares (pure functions on arrays). Luminance is
:func:`spectrinsic.spectra.colorimetry.luminance`.
"""

from __future__ import annotations

import numpy as np

from ...errors import DatasetError
from ...spectra import relative_error
from .records import ERROR_FLOOR, REFLECTANCE_FLOOR

# Responses with the light's white at Y = 1; under D65 with sRGB sensors, the canonical p^{s,c}.

__all__ = ["coverage_weighted", "shading_ratio", "relative_error_map", "light_shares"]


def coverage_weighted(coverage: np.ndarray, colours: np.ndarray) -> np.ndarray:
    """``Σ_m coverage[..., m] · colours[m]``: box-filtered (anti-aliased) per-pixel colour.

    Parameters
    ----------
    coverage
        ``(H, W, M)`` fraction of each pixel covered by material m (background: all 0).
    colours
        ``(M, C)`` colour of each material.

    Returns
    -------
    ``(H, W, C)`` float64.
    """
    coverage = np.asarray(coverage, float)
    colours = np.asarray(colours, float)
    if coverage.shape[-1] != colours.shape[0]:
        raise DatasetError(
            f"coverage has {coverage.shape[-1]} materials but the scene has {colours.shape[0]}"
        )
    return coverage @ colours


def shading_ratio(image: np.ndarray, reflectance: np.ndarray) -> np.ndarray:
    """The per-channel ratio ``image / reflectance`` (thesis Fig. 5.8), layer ``shading_ratio``.

    Ill-conditioned: where a reflectance channel is near 0 (saturated colours), or the light
    arriving is not D65, it depends on the material and can reach thousands. Where
    ``|reflectance| <= REFLECTANCE_FLOOR`` (background, black) it is 0; elsewhere
    ``image = reflectance ∘ shading_ratio`` holds to float precision. Same shape as *image*.
    """
    image = np.asarray(image, float)
    reflectance = np.asarray(reflectance, float)
    valid = np.abs(reflectance) > REFLECTANCE_FLOOR
    return np.where(valid, image / np.where(valid, reflectance, 1.0), 0.0)


def relative_error_map(approx: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Per-pixel ``‖p̂ − p‖₂ / ‖p‖₂`` over channels (the ε of thesis Table 5.2, Eq. 5.7).

    :func:`spectrinsic.spectra.relative_error` with ``dark_fraction=ERROR_FLOOR``: pixels whose
    reference norm is at most ``ERROR_FLOOR`` times its 99th percentile get 0.
    Returns ``(H, W)`` float64.
    """
    return relative_error(approx, reference, dark_fraction=ERROR_FLOOR, fill=0.0)


def light_shares(per_light_y: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
    """Fraction of the image luminance due to each light, ``(L,)`` summing to 1.

    *per_light_y* is ``(L, H, W)`` luminance of each light's render; restricted to *mask*.
    """
    y = np.clip(np.asarray(per_light_y, float), 0.0, None)
    if mask is not None:
        y = y[:, mask]
    totals = y.reshape(y.shape[0], -1).sum(axis=1)
    total = totals.sum()
    if not total > 0:
        return np.full(y.shape[0], 1.0 / y.shape[0])
    return totals / total
