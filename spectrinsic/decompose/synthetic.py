"""Synthetic Mondrian images with exact ground truth, for tests and benchmarks of decomposers.

A Mondrian (Land's Retinex experiments) is a patchwork of flat-coloured rectangles; multiplied by
a smooth shading it obeys the image model of thesis Eq. 3.1 exactly, with piecewise-constant
reflectance, which is what Retinex and the names-and-shades method assume.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..rng import generator

__all__ = ["Mondrian", "mondrian"]


@dataclass(frozen=True)
class Mondrian:
    """A synthetic image and its ground truth.

    Attributes
    ----------
    image
        ``(H, W, 3)`` float64 linear RGB, ``reflectance * shading * light`` (+ noise).
    reflectance
        ``(H, W, 3)`` float64 piecewise-constant reflectance in (0, 1).
    shading
        ``(H, W, 3)`` float64 shading-illumination, ``image / reflectance`` without noise.
    material_ids
        ``(H, W)`` int32 id of the rectangle (palette entry) at each pixel.
    """

    image: np.ndarray
    reflectance: np.ndarray
    shading: np.ndarray
    material_ids: np.ndarray


def mondrian(
    height: int = 96,
    width: int = 96,
    *,
    seed: int | np.random.Generator,
    n_patches: int = 14,
    light: tuple[float, float, float] = (1.0, 1.0, 1.0),
    shading_range: tuple[float, float] = (0.15, 1.0),
    noise: float = 0.0,
) -> Mondrian:
    """Draw a Mondrian of *n_patches* rectangles under smooth shading.

    Parameters
    ----------
    seed
        Seed or Generator (explicit; same seed, same image).
    n_patches
        Rectangles painted over a background patch (so ``n_patches + 1`` materials).
    light
        Linear RGB colour of the (single) light.
    shading_range
        Minimum and maximum of the grey shading, a smooth field (a tilted plane plus a wide
        bump, like a Lambertian surface under a nearby light).
    noise
        Standard deviation of multiplicative Gaussian noise on the image (0 = none).
    """
    rng = generator(seed)
    hue = rng.uniform(0.0, 1.0, n_patches + 1)
    # Saturated-to-mid colours of varied lightness: a colour-wheel point mixed with grey.
    phases = 2.0 * np.pi * (hue[:, None] + np.array([0.0, 1.0 / 3.0, 2.0 / 3.0]))
    chroma = rng.uniform(0.3, 0.9, (n_patches + 1, 1))
    value = rng.uniform(0.25, 0.9, (n_patches + 1, 1))
    palette = value * (1.0 - chroma + chroma * 0.5 * (1.0 + np.cos(phases)))
    palette = np.clip(palette, 0.03, 0.95)
    ids = np.zeros((height, width), dtype=np.int32)
    for k in range(1, n_patches + 1):
        h = rng.integers(height // 6, height // 2)
        w = rng.integers(width // 6, width // 2)
        y0 = rng.integers(0, height - h)
        x0 = rng.integers(0, width - w)
        ids[y0 : y0 + h, x0 : x0 + w] = k
    reflectance = palette[ids]
    yy, xx = np.mgrid[0:height, 0:width] / max(height, width)
    cy, cx = rng.uniform(0.2, 0.8, 2)
    field = 0.6 * (0.5 * xx + 0.3 * yy) + np.exp(-((yy - cy) ** 2 + (xx - cx) ** 2) / 0.08)
    field = (field - field.min()) / (field.max() - field.min())
    lo, hi = shading_range
    grey = lo + (hi - lo) * field
    shading = grey[:, :, None] * np.asarray(light, dtype=np.float64)
    image = reflectance * shading
    if noise > 0.0:
        image = image * (1.0 + noise * rng.standard_normal(image.shape))
    return Mondrian(np.clip(image, 0.0, None), reflectance, shading, ids)
