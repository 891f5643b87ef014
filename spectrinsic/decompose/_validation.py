"""Input checks shared by the metrics and decomposers (one-line errors naming the input)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..errors import SpectrinsicError

__all__ = ["ImageShapeError", "as_image", "as_mask", "image_pair"]


class ImageShapeError(SpectrinsicError, ValueError):
    """An image or mask whose shape, dtype or values do not fit what was asked."""


def as_image(image: npt.ArrayLike, what: str, *, channels: int | None = None) -> np.ndarray:
    """Return *image* as float64 ``(H, W, C)`` (a ``(H, W)`` grey image gets ``C = 1``).

    Raises :class:`ImageShapeError` for other ranks, a wrong channel count, or NaN/Inf.
    """
    arr = np.asarray(image, dtype=np.float64)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3 or arr.shape[0] == 0 or arr.shape[1] == 0:
        raise ImageShapeError(
            f"{what} must be an (H, W) or (H, W, C) image; got shape {np.shape(image)}"
        )
    if channels is not None and arr.shape[2] != channels:
        raise ImageShapeError(f"{what} must have {channels} channels; got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ImageShapeError(f"{what} contains NaN or Inf values")
    return arr


def as_mask(mask: npt.ArrayLike | None, shape: tuple[int, ...], what: str = "mask") -> np.ndarray:
    """Return *mask* as a bool ``(H, W)`` array (all True when None); check its shape."""
    if mask is None:
        return np.ones(shape, dtype=bool)
    arr = np.asarray(mask)
    if arr.shape != shape:
        raise ImageShapeError(f"{what} must have shape {shape}; got {arr.shape}")
    return arr.astype(bool)


def image_pair(
    truth: npt.ArrayLike, estimate: npt.ArrayLike, mask: npt.ArrayLike | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validate a (truth, estimate, mask) triple: same ``(H, W, C)`` shape, mask ``(H, W)``."""
    t = as_image(truth, "truth")
    e = as_image(estimate, "estimate")
    if t.shape != e.shape:
        raise ImageShapeError(
            f"estimate shape {np.shape(estimate)} differs from truth shape {np.shape(truth)}"
        )
    m = as_mask(mask, t.shape[:2])
    if not m.any():
        raise ImageShapeError("mask selects no pixel")
    return t, e, m
