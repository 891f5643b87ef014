"""The registry of error measures for intrinsic-image estimates (thesis section 2.4.3 and Eq.
4.31), and the weighted human disagreement rate.

Every image metric takes ``(truth, estimate, *, mask=None, ...)`` in the thesis' order
(``I_1`` = ground truth, ``I_2`` = estimate), accepts grey ``(H, W)`` or colour ``(H, W, C)``
linear images of the same shape, and a boolean ``(H, W)`` mask of valid pixels. Pixels outside
the mask take part in nothing. Options are keyword-only.

The measures live by kind: :mod:`spectrinsic.decompose.metrics.scale` (scale-invariant and
windowed MIT-benchmark measures, Eqs. 2.4-2.11) and :mod:`spectrinsic.decompose.metrics.colour`
(chromatic angular error, Eq. 4.31, and the MAW intensity/chromaticity split).

:data:`METRICS` is the registry of image metrics; :func:`whdr` works on pairwise judgements
(:mod:`spectrinsic.decompose.metrics.judgements`) instead of a ground-truth image.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy.typing as npt

from ...errors import DecomposeError, validate_choice
from .._validation import ImageShapeError, as_image
from .colour import (
    angular_error_mean,
    angular_error_median,
    reflectance_chromaticity_error,
    reflectance_intensity_error,
    shading_chromaticity_error,
)
from .judgements import predict_judgements
from .scale import almse, correlation, dssim, lmse, local_correlation, si_mse

if TYPE_CHECKING:
    from .judgements import Judgements

__all__ = ["WHDR_DELTA", "Metric", "METRICS", "get_metric", "compute_metrics", "whdr"]

logger = logging.getLogger(__name__)

#: Reflectance-ratio threshold of WHDR (Bell et al. 2014; thesis Eq. 2.13).
WHDR_DELTA = 0.10


def whdr(reflectance: npt.ArrayLike, judgements: Judgements, *, delta: float = WHDR_DELTA) -> float:
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
        :func:`spectrinsic.decompose.metrics.judgements.sample_judgements`).
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
        Metric("angular_median", angular_error_median, "Eq. 4.31", "lower", True, ("reflectance",)),
        Metric(
            "intensity_error",
            reflectance_intensity_error,
            "MAW intensity (Wu et al. 2023)",
            "lower",
            True,
            ("reflectance",),
        ),
        Metric(
            "chromaticity_error",
            reflectance_chromaticity_error,
            "MAW chromaticity (Wu et al. 2023), Eq. 4.31",
            "lower",
            True,
            ("reflectance",),
        ),
        Metric(
            "shading_chromaticity",
            shading_chromaticity_error,
            "Eq. 4.31 on shading",
            "lower",
            True,
            ("shading",),
        ),
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
