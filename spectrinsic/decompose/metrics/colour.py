"""Colour error measures of intrinsic-image estimates: the chromatic angular error (thesis Eq.
4.31) on reflectance and on coloured shading, and the MAW split of reflectance error into
intensity and chromaticity (Wu et al., ICCP 2023).

Every metric takes ``(truth, estimate, *, mask=None, ...)`` in the thesis' order (``I_1`` =
ground truth, ``I_2`` = estimate), accepts grey ``(H, W)`` or colour ``(H, W, C)`` linear images
of the same shape, and a boolean ``(H, W)`` mask of valid pixels; see
:mod:`spectrinsic.decompose.metrics` for the conventions and the registry.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal

import numpy as np
import numpy.typing as npt

from ...errors import DecomposeError, validate_choice
from ...spectra import angular_error
from .._validation import ImageShapeError, as_image, as_mask, image_pair
from .scale import least_squares_scale

__all__ = [
    "angular_error_map",
    "angular_error_mean",
    "angular_error_median",
    "shading_chromaticity_error",
    "reflectance_intensity_error",
    "reflectance_chromaticity_error",
]


def angular_error_map(
    truth: npt.ArrayLike, estimate: npt.ArrayLike, *, mask: npt.ArrayLike | None = None
) -> np.ndarray:
    """Per-pixel chromatic angular error in degrees, thesis Eq. 4.31.

    Returns a ``(H, W)`` float64 map, NaN outside the mask and where either colour is zero.
    Uses :func:`spectrinsic.spectra.angular_error`.
    """
    t, e, m = image_pair(truth, estimate, mask)
    if t.shape[2] != 3:
        raise ImageShapeError(f"angular error needs (H, W, 3) colour images; got {t.shape}")
    out = angular_error(t, e)
    zero = (np.linalg.norm(t, axis=-1) == 0.0) | (np.linalg.norm(e, axis=-1) == 0.0)
    return np.where(m & ~zero, out, np.nan)


def _angular_stat(truth, estimate, mask, stat: Callable[[np.ndarray], float]) -> float:
    errors = angular_error_map(truth, estimate, mask=mask)
    errors = errors[np.isfinite(errors)]
    if errors.size == 0:
        return float("nan")
    return float(stat(errors))


def angular_error_mean(
    truth: npt.ArrayLike, estimate: npt.ArrayLike, *, mask: npt.ArrayLike | None = None
) -> float:
    """Mean chromatic angular error (degrees, Eq. 4.31) over masked non-zero pixels."""
    return _angular_stat(truth, estimate, mask, np.mean)


def angular_error_median(
    truth: npt.ArrayLike, estimate: npt.ArrayLike, *, mask: npt.ArrayLike | None = None
) -> float:
    """Median chromatic angular error (degrees, Eq. 4.31) over masked non-zero pixels."""
    return _angular_stat(truth, estimate, mask, np.median)


def _statistic(values: np.ndarray, statistic: str, what: str) -> float:
    """Mean or median of *values* (degrees); NaN when empty."""
    validate_choice(statistic, ("mean", "median"), f"{what} statistic", error=DecomposeError)
    if values.size == 0:
        return float("nan")
    return float(np.mean(values) if statistic == "mean" else np.median(values))


def _colour_or_grey(a: np.ndarray, what: str) -> np.ndarray:
    """``(H, W, 3)`` unchanged; ``(H, W, 1)`` repeated to 3 achromatic channels; else an error."""
    if a.shape[2] == 1:
        return np.repeat(a, 3, axis=2)
    if a.shape[2] != 3:
        raise ImageShapeError(f"{what} must be (H, W, 3) colour or (H, W) grey; got {a.shape}")
    return a


def shading_chromaticity_error(
    truth: npt.ArrayLike,
    estimate: npt.ArrayLike,
    *,
    mask: npt.ArrayLike | None = None,
    statistic: Literal["mean", "median"] = "mean",
) -> float:
    """Angular error (degrees) of the shading's colour, Eq. 4.31 applied to shading.

    ``e_p = acos(S_p . S'_p / (|S_p| |S'_p|))`` per pixel ``p`` between the true coloured
    shading ``S`` (the colour of the light arriving, e.g. the dataset's ``shading`` layer, linear)
    and the estimate ``S'``; the mean (or median) over the masked pixels where light arrives
    (``|S_p| > 0``). The error does not depend on the intensity of either shading.

    Parameters
    ----------
    truth
        ``(H, W, 3)`` linear coloured shading.
    estimate
        ``(H, W, 3)`` estimate, or ``(H, W)`` / ``(H, W, 1)`` grey shading, which is taken as
        achromatic ``(s, s, s)``: a method that assumes white light is scored as such.
    statistic
        ``"mean"`` or ``"median"`` over the scored pixels.

    Notes
    -----
    Where the estimate is the zero vector but light arrives, the angle is undefined; it counts
    as 90 degrees, the largest angle between non-negative colours, so that zeroing pixels never
    lowers the error. NaN when no masked pixel receives light.
    """
    t = _colour_or_grey(as_image(truth, "truth shading"), "truth shading")
    e = _colour_or_grey(as_image(estimate, "estimate shading"), "estimate shading")
    if t.shape != e.shape:
        raise ImageShapeError(
            f"estimate shading shape {np.shape(estimate)} differs from truth shape {np.shape(truth)}"
        )

    m = as_mask(mask, t.shape[:2])
    lit = m & (np.linalg.norm(t, axis=-1) > 0.0)
    zero = np.linalg.norm(e, axis=-1) == 0.0
    errors = np.where(zero, 90.0, angular_error(t, np.where(zero[..., None], 1.0, e)))
    return _statistic(errors[lit], statistic, "shading chromaticity error")


def _intensity(a: np.ndarray) -> np.ndarray:
    """Mean over channels, ``(H, W, 1)``."""
    return a.mean(axis=2, keepdims=True)


def reflectance_intensity_error(
    truth: npt.ArrayLike, estimate: npt.ArrayLike, *, mask: npt.ArrayLike | None = None
) -> float:
    """Scale-invariant relative error of the reflectance intensity (MAW-style split).

    As Wu et al. (MAW, ICCP 2023) separate albedo error into intensity and chromaticity, the
    intensity part compares ``I = mean over channels`` of both images:
    ``min_alpha sum_p (I_p - alpha I'_p)^2 / sum_p I_p^2`` over the masked pixels. 0 is best;
    an estimate with the right colours but flat intensity scores ``1 - (sum I)^2 / (N sum I^2)``.
    Chromatic errors that keep the channel mean do not change it.

    Raises
    ------
    ImageShapeError
        When the masked truth intensity is all zero.
    """
    t, e, m = image_pair(truth, estimate, mask)
    ti, ei = _intensity(t)[m], _intensity(e)[m]
    energy = float((ti * ti).sum())
    if energy <= 0.0:
        raise ImageShapeError("reflectance intensity error undefined: the masked truth is zero")
    alpha = least_squares_scale(ti, ei, np.ones_like(ti), axis=None)
    return float(((ti - alpha * ei) ** 2).sum() / energy)


def reflectance_chromaticity_error(
    truth: npt.ArrayLike,
    estimate: npt.ArrayLike,
    *,
    mask: npt.ArrayLike | None = None,
    statistic: Literal["mean", "median"] = "mean",
) -> float:
    """Angular error (degrees) of the reflectance colour, the chromaticity half of the MAW split.

    ``acos(R_p . R'_p / (|R_p| |R'_p|))`` per masked pixel with non-zero truth (Eq. 4.31), its
    mean or median. Independent of the intensity of either image, pixel by pixel, so together with
    :func:`reflectance_intensity_error` it separates "wrong lightness" from "wrong colour".
    Zero estimates where the truth is not zero count as 90 degrees, as in
    :func:`shading_chromaticity_error`.
    """
    t, e, m = image_pair(truth, estimate, mask)
    if t.shape[2] != 3:
        raise ImageShapeError(
            f"reflectance chromaticity error needs (H, W, 3) images; got {t.shape}"
        )
    return shading_chromaticity_error(t, e, mask=m, statistic=statistic)
