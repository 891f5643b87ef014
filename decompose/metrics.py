"""Error measures for intrinsic-image estimates (thesis section 2.4.3 and Eq. 4.31).

Every image metric takes ``(truth, estimate, *, mask=None, ...)`` in the thesis' order
(``I_1`` = ground truth, ``I_2`` = estimate), accepts grey ``(H, W)`` or colour ``(H, W, C)``
linear images of the same shape, and a boolean ``(H, W)`` mask of valid pixels. Pixels outside
the mask take part in nothing. Options are keyword-only.

Windowed metrics use the MIT benchmark's windows (Grosse et al., ICCV 2009): ``window x window``
squares whose top-left corners lie every ``step`` pixels, entirely inside the image
(``range(0, H - window + 1, step)``), 20 and 10 by default.

:data:`METRICS` is the registry of image metrics; :func:`whdr` works on pairwise judgements
(:mod:`spectrinsic.decompose.judgements`) instead of a ground-truth image.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np
import numpy.typing as npt

from spectrinsic.decompose._validation import ImageShapeError, as_image, as_mask, image_pair
from spectrinsic.decompose.judgements import predict_judgements
from spectrinsic.errors import DecomposeError, validate_choice
from spectrinsic.spectra import angular_error

if TYPE_CHECKING:
    from spectrinsic.decompose.judgements import Judgements

__all__ = [
    "WINDOW",
    "STEP",
    "WHDR_DELTA",
    "Metric",
    "METRICS",
    "get_metric",
    "compute_metrics",
    "si_mse",
    "lmse",
    "mit_score",
    "almse",
    "correlation",
    "local_correlation",
    "dssim",
    "angular_error_map",
    "angular_error_mean",
    "angular_error_median",
    "shading_chromaticity_error",
    "reflectance_intensity_error",
    "reflectance_chromaticity_error",
    "whdr",
]

logger = logging.getLogger(__name__)

#: MIT benchmark window side (pixels) and spacing of window corners (Grosse et al. 2009).
WINDOW = 20
STEP = 10
#: Reflectance-ratio threshold of WHDR (Bell et al. 2014; thesis Eq. 2.13).
WHDR_DELTA = 0.10


def _scale(
    truth: np.ndarray, estimate: np.ndarray, weight: np.ndarray, axis, floor: float = 0.0
) -> np.ndarray:
    """Least-squares ``alpha = sum(w t e) / sum(w e^2)`` (0 where ``sum(w e^2) <= floor``)."""
    num = (weight * truth * estimate).sum(axis=axis, keepdims=True)
    den = (weight * estimate * estimate).sum(axis=axis, keepdims=True)
    ok = den > floor
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(ok, num / np.where(ok, den, 1.0), 0.0)


def si_mse(
    truth: npt.ArrayLike, estimate: npt.ArrayLike, *, mask: npt.ArrayLike | None = None
) -> float:
    """Scale-invariant mean squared error, thesis Eq. 2.4 (Tappen et al.).

    ``MSE = min_alpha ||I_1 - alpha I_2||^2 / |I_1|`` over the masked pixels, with ``|I_1|``
    the number of masked values (pixels x channels) and one ``alpha`` for all channels.
    """
    t, e, m = image_pair(truth, estimate, mask)
    w = np.broadcast_to(m[:, :, None], t.shape).astype(np.float64)
    alpha = _scale(t, e, w, axis=None)
    return float((w * (t - alpha * e) ** 2).sum() / w.sum())


def _windows(a: np.ndarray, window: int, step: int) -> np.ndarray:
    """``(H, W, C)`` -> ``(n_windows, window * window, C)`` view-derived copy of MIT windows."""
    h, w, c = a.shape
    if window < 1 or step < 1:
        raise ImageShapeError(f"window and step must be >= 1; got window={window}, step={step}")
    if h < window or w < window:
        raise ImageShapeError(f"image of size {h}x{w} is smaller than the {window}x{window} window")
    view = np.lib.stride_tricks.sliding_window_view(a, (window, window), axis=(0, 1))  # type: ignore[call-overload]
    view = view[::step, ::step]  # (ny, nx, C, window, window)
    return np.moveaxis(view, 2, -1).reshape(-1, window * window, c)


def _windowed(truth, estimate, mask, window, step):
    t, e, m = image_pair(truth, estimate, mask)
    mw = _windows(m[:, :, None].astype(np.float64), window, step)
    mw = np.broadcast_to(mw, mw.shape[:2] + (t.shape[2],))
    return _windows(t, window, step), _windows(e, window, step), mw


def lmse(
    truth: npt.ArrayLike,
    estimate: npt.ArrayLike,
    *,
    mask: npt.ArrayLike | None = None,
    window: int = WINDOW,
    step: int = STEP,
    per_channel: bool = False,
    energy_floor: float = 0.0,
) -> float:
    """Local mean squared error, thesis Eq. 2.5, as the MIT benchmark computes it.

    ``LMSE = sum_w min_alpha ||I_1^w - alpha I_2^w||^2 / sum_w ||I_1^w||^2`` over the windows
    ``w`` (module docstring), each sum over the window's masked pixels only; ``alpha`` is fitted
    per window by least squares (Grosse et al. 2009, ``local_error``).

    Parameters
    ----------
    per_channel
        Fit one ``alpha`` per window and channel instead of one per window (thesis section
        5.2.5: "an alpha factor fitted for each local patch").
    energy_floor
        ``alpha = 0`` in a window whose masked ``sum(e^2)`` is at most this. The MIT code uses
        ``1e-5`` on images in [0, 1] (:mod:`spectrinsic.decompose.mit`); the default 0 leaves
        only an all-zero estimate at ``alpha = 0``, since linear renderings have no fixed scale.

    Raises
    ------
    ImageShapeError
        If the image is smaller than the window or the ground truth has no energy in the
        masked windows.
    """
    t, e, m = _windowed(truth, estimate, mask, window, step)
    axis = 1 if per_channel else (1, 2)
    alpha = _scale(t, e, m, axis=axis, floor=energy_floor)
    residual = (m * (t - alpha * e) ** 2).sum()
    energy = (m * t * t).sum()
    if energy <= 0.0:
        raise ImageShapeError("LMSE undefined: the ground truth is zero in every masked window")
    return float(residual / energy)


def mit_score(
    true_shading: npt.ArrayLike,
    true_reflectance: npt.ArrayLike,
    estimated_shading: npt.ArrayLike,
    estimated_reflectance: npt.ArrayLike,
    *,
    mask: npt.ArrayLike | None = None,
    window: int = WINDOW,
    step: int = STEP,
) -> float:
    """MIT benchmark score: the mean of the shading and reflectance :func:`lmse` (Grosse 2009)."""
    shading = lmse(true_shading, estimated_shading, mask=mask, window=window, step=step)
    reflectance = lmse(true_reflectance, estimated_reflectance, mask=mask, window=window, step=step)
    return 0.5 * shading + 0.5 * reflectance


def _centred(a: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Subtract the masked mean of each window (all channels pooled)."""
    n = m.sum(axis=(1, 2), keepdims=True)
    mean = (m * a).sum(axis=(1, 2), keepdims=True) / np.maximum(n, 1.0)
    return m * (a - mean)


def almse(
    truth: npt.ArrayLike,
    estimate: npt.ArrayLike,
    *,
    mask: npt.ArrayLike | None = None,
    window: int = WINDOW,
    step: int = STEP,
) -> float:
    """Absolute LMSE, thesis Eq. 2.6 (Jiang et al. 2010).

    As :func:`lmse` after subtracting each window's masked mean ``mu^w`` (all channels pooled)
    from both images: ``sum_w min_alpha ||(I_1^w - mu_1^w) - alpha (I_2^w - mu_2^w)||^2 /
    sum_w ||I_1^w - mu_1^w||^2``.
    """
    t, e, m = _windowed(truth, estimate, mask, window, step)
    tc, ec = _centred(t, m), _centred(e, m)
    alpha = _scale(tc, ec, m, axis=(1, 2))
    residual = (m * (tc - alpha * ec) ** 2).sum()
    energy = (m * tc * tc).sum()
    if energy <= 0.0:
        raise ImageShapeError("aLMSE undefined: the ground truth is constant in every window")
    return float(residual / energy)


def _pearson(t: np.ndarray, e: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Per-window Pearson correlation of ``(n, h, w)`` stacks over the mask *m* (NaN where
    either is constant)."""
    tc, ec = _centred(t, m), _centred(e, m)
    axis = (1, 2)
    cov = (tc * ec).sum(axis=axis)
    var = (tc * tc).sum(axis=axis) * (ec * ec).sum(axis=axis)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(var > 0.0, cov / np.sqrt(np.where(var > 0.0, var, 1.0)), np.nan)


def correlation(
    truth: npt.ArrayLike, estimate: npt.ArrayLike, *, mask: npt.ArrayLike | None = None
) -> float:
    """Pearson correlation over the masked values, thesis Eq. 2.7 (1 is best).

    NaN when either image is constant over the mask.
    """
    t, e, m = image_pair(truth, estimate, mask)
    w = np.broadcast_to(m[:, :, None], t.shape).astype(np.float64)
    r = _pearson(t.reshape(1, -1, 1), e.reshape(1, -1, 1), w.reshape(1, -1, 1))
    return float(r[0])


def local_correlation(
    truth: npt.ArrayLike,
    estimate: npt.ArrayLike,
    *,
    mask: npt.ArrayLike | None = None,
    window: int = WINDOW,
    step: int = STEP,
) -> float:
    """Mean over windows of the Pearson correlation, thesis Eq. 2.8 (1 is best).

    Windows where either image is constant over the masked pixels (correlation undefined) are
    left out of the mean; NaN when no window remains.
    """
    t, e, m = _windowed(truth, estimate, mask, window, step)
    r = _pearson(t, e, m)
    if not np.isfinite(r).any():
        return float("nan")
    return float(np.nanmean(r))


def dssim(
    truth: npt.ArrayLike,
    estimate: npt.ArrayLike,
    *,
    mask: npt.ArrayLike | None = None,
    data_range: float | None = None,
    fit_scale: bool = True,
    win_size: int | None = None,
) -> float:
    """Structural dissimilarity ``(1 - MSSIM) / 2``, thesis Eqs. 2.9-2.11 (Chen & Koltun 2013).

    MSSIM is scikit-image's :func:`skimage.metrics.structural_similarity` (7x7 uniform
    windows, channels averaged).

    Parameters
    ----------
    data_range
        Dynamic range of the images; default ``max - min`` of the masked ground truth.
    fit_scale
        First multiply the estimate by the least-squares ``alpha`` of Eq. 2.4, since intrinsic
        estimates are defined up to scale.
    win_size
        SSIM window side (odd); default scikit-image's 7.

    Notes
    -----
    Without a mask the result is exactly scikit-image's mean SSIM (borders cropped as it does);
    with a mask the SSIM map is averaged over the masked pixels away from the border.
    """
    from skimage.metrics import structural_similarity

    t, e, m = image_pair(truth, estimate, mask)
    if fit_scale:
        w = np.broadcast_to(m[:, :, None], t.shape).astype(np.float64)
        e = _scale(t, e, w, axis=None) * e
    if data_range is None:
        values = t[m]
        data_range = float(values.max() - values.min())
    if data_range <= 0.0:
        raise ImageShapeError("DSSIM needs data_range > 0 (the masked ground truth is constant)")
    kwargs = {"data_range": data_range, "win_size": win_size, "full": True}
    if t.shape[2] == 1:
        mssim, smap = structural_similarity(t[:, :, 0], e[:, :, 0], **kwargs)
    else:
        mssim, smap = structural_similarity(t, e, channel_axis=-1, **kwargs)
        smap = smap.mean(axis=-1)
    if mask is None:
        return float((1.0 - mssim) / 2.0)
    pad = ((win_size or 7) - 1) // 2
    inner = np.zeros_like(m)
    inner[pad : m.shape[0] - pad, pad : m.shape[1] - pad] = True
    sel = m & inner
    if not sel.any():
        raise ImageShapeError("DSSIM: the mask selects no pixel away from the image border")
    return float((1.0 - smap[sel].mean()) / 2.0)


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
    alpha = _scale(ti, ei, np.ones_like(ti), axis=None)
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
        raise ImageShapeError(f"reflectance chromaticity error needs (H, W, 3) images; got {t.shape}")
    return shading_chromaticity_error(t, e, mask=m, statistic=statistic)


def whdr(
    reflectance: npt.ArrayLike, judgements: Judgements, *, delta: float = WHDR_DELTA
) -> float:
    """Weighted human disagreement rate, thesis Eqs. 2.12-2.13 (Bell et al. 2014).

    Each judgement compares points 1 and 2; the estimate predicts ``1`` (point 1 darker) when
    ``R_2 / R_1 > 1 + delta``, ``2`` when ``R_1 / R_2 > 1 + delta``, else ``E``, with ``R`` the
    reflectance intensity (mean over channels). The result is the weighted fraction of
    judgements the prediction disagrees with.

    Parameters
    ----------
    reflectance
        ``(H, W)`` or ``(H, W, C)`` estimated reflectance.
    judgements
        Point pairs, labels and weights (e.g. from
        :func:`spectrinsic.decompose.judgements.sample_judgements`).
    """
    r = as_image(reflectance, "reflectance")
    predicted = predict_judgements(r, judgements.points1, judgements.points2, delta=delta)
    w = judgements.weights
    if w.sum() <= 0.0:
        raise ImageShapeError("WHDR needs at least one judgement with positive weight")
    return float((w * (predicted != judgements.labels)).sum() / w.sum())


ImageMetric = Callable[..., float]


@dataclass(frozen=True)
class Metric:
    """A registered image metric.

    Attributes
    ----------
    name
        Registry key.
    func
        ``func(truth, estimate, *, mask=None) -> float``.
    equation
        Where it is defined (thesis equation).
    better
        ``"lower"`` or ``"higher"``.
    scale_invariant
        Whether scaling the estimate leaves the value unchanged.
    layers
        The layers the evaluation scores with it (``"reflectance"``, ``"shading"`` for the
        coloured shading, ``"shading_grey"`` for the grey one).
    """

    name: str
    func: ImageMetric
    equation: str
    better: Literal["lower", "higher"]
    scale_invariant: bool
    layers: tuple[str, ...] = ("reflectance", "shading", "shading_grey")


METRICS: Mapping[str, Metric] = {
    m.name: m
    for m in (
        Metric("si_mse", si_mse, "Eq. 2.4", "lower", True),
        Metric("lmse", lmse, "Eq. 2.5", "lower", True),
        Metric("almse", almse, "Eq. 2.6", "lower", True),
        Metric("corr", correlation, "Eq. 2.7", "higher", True),
        Metric("lcorr", local_correlation, "Eq. 2.8", "higher", True),
        Metric("dssim", dssim, "Eq. 2.11", "lower", True),
        Metric("angular_mean", angular_error_mean, "Eq. 4.31", "lower", True, ("reflectance",)),
        Metric("angular_median", angular_error_median, "Eq. 4.31", "lower", True,
               ("reflectance",)),
        Metric("intensity_error", reflectance_intensity_error, "MAW intensity (Wu et al. 2023)",
               "lower", True, ("reflectance",)),
        Metric("chromaticity_error", reflectance_chromaticity_error,
               "MAW chromaticity (Wu et al. 2023), Eq. 4.31", "lower", True, ("reflectance",)),
        Metric("shading_chromaticity", shading_chromaticity_error, "Eq. 4.31 on shading",
               "lower", True, ("shading",)),
    )
}


def get_metric(name: str) -> Metric:
    """The registered :class:`Metric` called *name* (one-line error with close matches)."""
    return METRICS[validate_choice(name, METRICS, "metric", error=DecomposeError)]


def compute_metrics(
    truth: npt.ArrayLike,
    estimate: npt.ArrayLike,
    names: Iterable[str] | None = None,
    *,
    mask: npt.ArrayLike | None = None,
) -> dict[str, float]:
    """Evaluate several registered metrics (default: all) on one image pair."""
    selected = [get_metric(n) for n in (METRICS if names is None else names)]
    return {m.name: m.func(truth, estimate, mask=mask) for m in selected}
