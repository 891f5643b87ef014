"""Denoising of the white-surface radiance with Intel Open Image Denoise (``pyoidn``).

What is denoised is ``W = E / π`` (:mod:`spectrinsic.gt_export.layers.irradiance`): the image divided
by the exact reflectance, so it has no texture for a denoiser to blur, and the reflectance never
enters the denoiser. OIDN filters 3-channel float32 images, in HDR mode (``W`` is unbounded
radiance), with two guides (:class:`Guides`) that carry the edges of the geometry:

* the world-space normals: creases;
* as OIDN's "albedo" (an image whose edges it keeps), not the reflectance but a grey level
  falling with the distance from the camera, ``d_near / depth``: outlines, where a surface
  passes in front of another with the same normal. ``W`` is already demodulated, so the
  albedo OIDN would divide by is not needed; the reflectance never enters the denoiser.

Both are box-filtered over every sample of the pixel (:mod:`spectrinsic.render.passes.aovs`), so OIDN
is told they are clean (``clean_aux``) and does not blur them, nor ``W`` across their edges.

The K bands are denoised in two steps (a luminance/chroma split):

1. *broad bands*: the sums of ``W`` over three contiguous thirds of the bands
   (``B_g = Σ_{k∈g} W_k``, about 400–490, 500–590 and 600–700 nm for 31 bands) carry most of
   the signal and every edge; they go through OIDN together at :data:`BROAD_QUALITY`;
2. *detail*: every band, three at a time (the last block zero-padded), at the cheaper
   *quality*, gives each band's share of its third, ``W_k / B_g``.

``W_k = share_k · B̂_g``, so the denoised bands of a third sum to its denoised broad band.
Every band shares its light paths with the others (common random numbers), so the blocks see
the same noise pattern and a share is much less noisy than its band.

Against a 16384-spp crop of a room at 2 × 32 spp (``make bench``,
``bench_crop_reference.json`` at that preset) the 95th percentile of the shading error went from 14.3 %
(every band through ``fast``, normals only, not marked clean) to 12.0 %, the median from
2.2 % to 2.0 %, for one more OIDN call per image; on an analytic outline (a lit card above a
floor, tests/gt_export/layers/test_denoise_edges.py) the 95th percentile beside the outline went
from 10–12 % to 5–7 %.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import DatasetError
from .irradiance import WhiteRadiance

__all__ = [
    "DENOISE_QUALITY",
    "BROAD_QUALITY",
    "Denoiser",
    "Guides",
    "depth_guide",
    "band_thirds",
    "denoise_blocks",
    "denoise_rgb",
    "denoise_white_radiance",
]

#: OIDN quality of the per-band detail pass: ``"fast"`` takes 0.06 s per 256² block on 2
#: cores against 0.29 s for ``"high"`` (``make bench`` compares their errors).
DENOISE_QUALITY = "fast"
#: OIDN quality of the broad-band pass (one call per image, where the edges are decided).
BROAD_QUALITY = "high"


@dataclass(frozen=True, eq=False)
class Guides:
    """The first-hit maps OIDN is guided by (either may be ``None``).

    Attributes
    ----------
    normals
        ``(H, W, 3)`` unit world-space normals, 0 where nothing is hit.
    depth
        ``(H, W)`` mean distance from the camera (scene units), 0 where nothing is hit.
    """

    normals: np.ndarray | None = field(default=None, repr=False)
    depth: np.ndarray | None = field(default=None, repr=False)


#: A denoiser of ``W``: the raw record and its guides to the denoised record.
Denoiser = Callable[[WhiteRadiance, Guides], WhiteRadiance]


def depth_guide(depth: np.ndarray | None, shape: tuple[int, ...]) -> np.ndarray:
    """``(H, W, 3)`` grey ``d_near / depth`` in [0, 1] (``d_near`` the 1st percentile of the hit
    depths), 0 where nothing is hit; white without a depth map.

    >>> depth_guide(np.array([[1.0, 2.0], [4.0, 0.0]]), (2, 2, 3))[..., 0].round(2).tolist()
    [[1.0, 0.51], [0.26, 0.0]]
    """
    if depth is None:
        return np.ones(shape)
    d = np.asarray(depth, np.float64)
    hit = d > 0
    if not hit.any():
        return np.ones(shape)
    near = np.percentile(d[hit], 1)
    grey = np.where(hit, np.clip(near / np.where(hit, d, 1.0), 0.0, 1.0), 0.0)
    return np.repeat(grey[..., None], 3, axis=-1)


def _oidn() -> Any:
    try:
        import pyoidn
    except ImportError as exc:  # pragma: no cover - pyoidn is a declared dependency
        raise DatasetError(
            "denoising needs pyoidn (Intel Open Image Denoise): pip install pyoidn, or build "
            "with denoise=False"
        ) from exc
    return pyoidn


def denoise_rgb(
    colour: np.ndarray,
    normals: np.ndarray | None = None,
    *,
    albedo: np.ndarray | None = None,
    quality: str = DENOISE_QUALITY,
    clean_aux: bool = True,
) -> np.ndarray:
    """One OIDN pass over a non-negative ``(H, W, 3)`` HDR image, guided by *normals* and the
    edge image *albedo* (white if ``None``), both taken as noise-free when *clean_aux*."""
    oidn = _oidn()
    colour = np.ascontiguousarray(np.clip(colour, 0.0, None), np.float32)
    albedo = (
        np.ones_like(colour)
        if albedo is None
        else np.ascontiguousarray(np.clip(albedo, 0.0, 1.0), np.float32)
    )
    normal = (
        None if normals is None else np.ascontiguousarray(np.clip(normals, -1.0, 1.0), np.float32)
    )
    out = oidn.denoise(
        colour,
        albedo,
        normal,
        hdr=True,
        quality=quality,
        clean_aux=clean_aux and normal is not None,
    )
    return np.clip(np.asarray(out, np.float64), 0.0, None)


def band_thirds(k: int) -> np.ndarray:
    """``(K, 3)`` 0/1 matrix putting band k in one of three contiguous thirds (fewer than three
    bands: one band per column, the other columns empty).

    >>> band_thirds(5).astype(int).tolist()
    [[1, 0, 0], [1, 0, 0], [0, 1, 0], [0, 1, 0], [0, 0, 1]]
    """
    groups = np.zeros((k, 3))
    for g, bands in enumerate(np.array_split(np.arange(k), 3)):
        groups[bands, g] = 1.0
    return groups


def denoise_blocks(
    bands: np.ndarray,
    normals: np.ndarray | None,
    *,
    albedo: np.ndarray | None = None,
    quality: str,
    clean_aux: bool = True,
) -> np.ndarray:
    """``(H, W, K)`` bands denoised three at a time (the last block zero-padded)."""
    k = bands.shape[-1]
    padded = np.zeros(bands.shape[:-1] + (-(-k // 3) * 3,))
    padded[..., :k] = bands
    blocks = [
        denoise_rgb(
            padded[..., i : i + 3], normals, albedo=albedo, quality=quality, clean_aux=clean_aux
        )
        for i in range(0, padded.shape[-1], 3)
    ]
    return np.concatenate(blocks, axis=-1)[..., :k]


def denoise_white_radiance(
    radiance: WhiteRadiance, guides: Guides | None = None, *, quality: str = DENOISE_QUALITY
) -> WhiteRadiance:
    """``W`` denoised as broad bands times per-band shares (module docstring), ≥ 0; 0 where it
    is undefined, as before. *quality* is the detail pass's."""
    guides = guides or Guides()
    bands = radiance.bands
    groups = band_thirds(bands.shape[-1])
    edges = depth_guide(guides.depth, bands.shape[:-1] + (3,))
    normals = guides.normals
    broad = denoise_rgb(bands @ groups, normals, albedo=edges, quality=BROAD_QUALITY) @ groups.T
    detail = denoise_blocks(bands, normals, albedo=edges, quality=quality)
    total = detail @ groups @ groups.T
    # a third that the detail pass zeroed keeps the broad value, spread evenly over its bands
    even = np.broadcast_to(1.0 / groups.sum(axis=0).clip(1.0) @ groups.T, bands.shape)
    share = np.divide(detail, total, out=np.array(even), where=total > 0)
    return radiance.with_bands(share * broad)
