"""The shading's texture: the image's fine detail that a region-wise reflectance leaves in it.

Issue 48 names two signs of a degenerate decomposition: a reflectance with almost no
variation where the image has strong edges (:mod:`spectrinsic.decompose.methods.collapse`)
and a *shading that reproduces the image's texture*. Names-and-shades gives each region one
colour (sec. 3.3.3) and one scale (sec. 3.4), and its shading is ``image / reflectance``, so
whatever the regions do not explain lands in the shading pixel by pixel: the optically mixed
pixels along a print's boundary, the steps a wrong region scale leaves at a boundary (issue
48's teabag1: 79 % of its excess), a crease cut into many small regions, sensor noise.

By thesis Eq. 3.1, ``log I = log R + log S`` at every pixel, so the image's *fine detail*,
what remains of ``log I`` after a Gaussian of :data:`DETAIL_SIGMA` pixels, splits exactly
between the two layers. The Retinex regularity the thesis builds on (sec. 2.2.1: "brusque
changes indicate reflectance variations while smooth variations are due to shading";
"although sharp shading edges can be found in natural images, shading variations are still
smooth in most of the images") gives that detail to the reflectance. :func:`return_fine_detail`
does so after the method: the shading is replaced by its Gaussian average over the mask
(normalised convolution, so the mask's border is not darkened) and the reflectance is
``image / shading`` (Eq. 3.1). The shading at every coarser scale is the method's; what
moves is only detail within about two pixels. Its cost is the cue's own limit: a sharp
shading edge (an occluder's hard shadow, a crease) loses its sharpest part to the
reflectance. It always acts, and ``info["texture"]`` says what it moved
(:class:`TextureShare` before and after).

:data:`DETAIL_SIGMA` comes from round 5's rule, not from a benchmark: a step is *sharp* when
it is made within 2 pixels (:data:`spectrinsic.decompose.methods.sharp_edges.SHARPNESS`, the
blur width of the lens and the sensor), and the constant was set so before any measurement
(docs/names-shades-mit.md, round 7).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace

import numpy as np

from ..decomposition import Decomposition, finish
from .sharp_edges import log_luminance

__all__ = [
    "DETAIL_SIGMA",
    "TextureShare",
    "masked_gaussian",
    "return_fine_detail",
    "smooth_shading",
    "texture_share",
]

logger = logging.getLogger(__name__)

#: Gaussian scale (pixels) below which log-luminance detail is "sharp": the 2-pixel blur width
#: of round 5's sharp-edge test (:mod:`spectrinsic.decompose.methods.sharp_edges`).
DETAIL_SIGMA = 2.0


@dataclass(frozen=True)
class TextureShare:
    """How much of the image's fine detail a shading carries (module docstring).

    Attributes
    ----------
    shading_share
        ``sum(d_S d_I) / sum(d_I^2)`` over the mask, ``d`` the log luminance minus its masked
        Gaussian average (:data:`DETAIL_SIGMA`): the share of the image's fine detail the
        shading carries; the reflectance carries the rest (Eq. 3.1). 0 for an image without
        detail.
    detail_rms
        Root mean square of the image's fine detail ``d_I`` (natural log units).
    """

    shading_share: float
    detail_rms: float


def masked_gaussian(values: np.ndarray, mask: np.ndarray, sigma: float) -> np.ndarray:
    """``(H, W)`` Gaussian average (*sigma* pixels) of *values* over the mask only (normalised
    convolution: pixels outside the mask neither count nor darken the border); 0 outside."""
    from scipy.ndimage import gaussian_filter

    num = gaussian_filter(np.where(mask, values, 0.0), sigma, mode="constant")
    den = gaussian_filter(mask.astype(np.float64), sigma, mode="constant")
    return np.where(mask, num / np.maximum(den, 1e-12), 0.0)


def texture_share(image: np.ndarray, shading: np.ndarray, mask: np.ndarray) -> TextureShare:
    """:class:`TextureShare` of a ``(H, W, 3)`` *shading* estimated from *image*.

    >>> y, x = np.mgrid[0:32, 0:32]
    >>> refl = np.where((x // 4 + y // 4) % 2 == 0, 0.8, 0.1)
    >>> light = 0.2 + 0.8 * x / 31.0
    >>> image = np.repeat((refl * light)[:, :, None], 3, axis=2)
    >>> mask = np.ones(refl.shape, bool)
    >>> round(texture_share(image, np.repeat(light[:, :, None], 3, axis=2), mask).shading_share, 2)
    0.0
    >>> texture_share(image, image, mask).shading_share
    1.0
    """
    detail_image = _detail(log_luminance(image, mask), mask)
    detail_shading = _detail(log_luminance(np.maximum(shading, 0.0), mask), mask)
    energy = float((detail_image * detail_image).sum())
    share = float((detail_shading * detail_image).sum()) / energy if energy > 0.0 else 0.0
    return TextureShare(share, float(np.sqrt(energy / max(detail_image.size, 1))))


def _detail(log_lum: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``(N,)`` fine detail of a log luminance over the mask (minus its masked Gaussian)."""
    return (log_lum - masked_gaussian(log_lum, mask, DETAIL_SIGMA))[mask]


def smooth_shading(image: np.ndarray, shading: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``(H, W, 3)`` reflectance ``image / G * shading``: each channel of the ``(H, W, 3)``
    *shading* averaged over the mask by a Gaussian of :data:`DETAIL_SIGMA` pixels; 0 outside
    the mask and where the averaged shading is 0."""
    smooth = np.stack(
        [masked_gaussian(shading[:, :, c], mask, DETAIL_SIGMA) for c in range(3)], axis=2
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        refl = np.where(smooth > 0.0, image / np.where(smooth > 0.0, smooth, 1.0), 0.0)
    return np.where(mask[:, :, None], refl, 0.0)


def return_fine_detail(result: Decomposition, image: np.ndarray, mask: np.ndarray) -> Decomposition:
    """*result* with its shading's fine detail returned to the reflectance (module docstring);
    ``info["texture"]`` holds the shading's share of the image's fine detail before and after,
    the scale and one line saying what was done."""
    shading = np.asarray(result.shading, np.float64)
    before = texture_share(image, shading, mask)
    refl = smooth_shading(image, shading, mask)
    out = finish(image, refl, mask, dict(result.info))
    after = texture_share(image, np.asarray(out.shading, np.float64), mask)
    detail = (
        f"shading averaged over a {DETAIL_SIGMA:g}-pixel Gaussian, reflectance = image / it: "
        f"the shading's share of the image's fine detail {before.shading_share:.3f} -> "
        f"{after.shading_share:.3f} (an approximation: sharp shading edges lose their sharpest "
        "part to the reflectance)"
    )
    logger.debug("shading texture: %s", detail)
    out.info["texture"] = {
        "shading_share_before": round(before.shading_share, 4),
        "shading_share_after": round(after.shading_share, 4),
        "detail_rms": round(before.detail_rms, 4),
        "sigma_px": DETAIL_SIGMA,
        "action": "smoothed",
        "detail": detail,
    }
    return replace(out, specular=result.specular)
