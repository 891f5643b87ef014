"""Scale-invariant error measures of intrinsic-image estimates (thesis section 2.4.3, Eqs.
2.4-2.11): :func:`si_mse`, :func:`lmse` (and the MIT benchmark's :func:`mit_score`),
:func:`almse`, :func:`correlation`, :func:`local_correlation` and :func:`dssim`.

Every metric takes ``(truth, estimate, *, mask=None, ...)`` in the thesis' order (``I_1`` =
ground truth, ``I_2`` = estimate), accepts grey ``(H, W)`` or colour ``(H, W, C)`` linear images
of the same shape, and a boolean ``(H, W)`` mask of valid pixels; see
:mod:`spectrinsic.decompose.metrics` for the conventions and the registry.

Windowed metrics use the MIT benchmark's windows (Grosse et al., ICCV 2009): ``window x window``
squares whose top-left corners lie every ``step`` pixels, entirely inside the image
(``range(0, H - window + 1, step)``), 20 and 10 by default.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from .._validation import ImageShapeError, image_pair

__all__ = [
    "WINDOW",
    "STEP",
    "least_squares_scale",
    "si_mse",
    "lmse",
    "mit_score",
    "almse",
    "correlation",
    "local_correlation",
    "dssim",
]

#: MIT benchmark window side (pixels) and spacing of window corners (Grosse et al. 2009).
WINDOW = 20
STEP = 10


def least_squares_scale(
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
    alpha = least_squares_scale(t, e, w, axis=None)
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
        ``1e-5`` on images in [0, 1] (:mod:`spectrinsic.decompose.evaluation.mit`); the default 0 leaves
        only an all-zero estimate at ``alpha = 0``, since linear renderings have no fixed scale.

    Raises
    ------
    ImageShapeError
        If the image is smaller than the window or the ground truth has no energy in the
        masked windows.
    """
    t, e, m = _windowed(truth, estimate, mask, window, step)
    axis = 1 if per_channel else (1, 2)
    alpha = least_squares_scale(t, e, m, axis=axis, floor=energy_floor)
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
    alpha = least_squares_scale(tc, ec, m, axis=(1, 2))
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
        e = least_squares_scale(t, e, w, axis=None) * e
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
