"""The record every decomposer returns, and the input checks they share.

A decomposer is a callable ``decomposer(image, mask=None) -> Decomposition`` taking a linear
``(H, W, 3)`` image (any positive scale) and returning reflectance and shading with
``image = reflectance * shading`` per channel inside the mask (thesis Eq. 3.1). Both are defined
up to a scale; outside the mask both are 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from ._validation import ImageShapeError, as_image, as_mask

__all__ = ["Decomposition", "Decomposer", "prepare_input", "finish"]


@dataclass(frozen=True)
class Decomposition:
    """Reflectance and shading estimates of one image.

    Attributes
    ----------
    reflectance
        ``(H, W, 3)`` float32 linear reflectance (relative scale), 0 outside the mask.
    shading
        ``(H, W, 3)`` float32 linear shading-illumination, ``image / reflectance``.
    info
        Method diagnostics (label counts, timings...), JSON-serialisable.
    specular
        ``(H, W, 3)`` float32 linear specular estimate, for a method that predicts one (scored
        against a glossy sample's ``specular`` layer); None otherwise.
    """

    reflectance: np.ndarray
    shading: np.ndarray
    info: dict[str, Any] = field(default_factory=dict)
    specular: np.ndarray | None = None


class Decomposer(Protocol):
    """What the registry holds: a named callable with its parameters as attributes."""

    name: str

    def __call__(
        self, image: npt.ArrayLike, mask: npt.ArrayLike | None = None
    ) -> Decomposition: ...


def prepare_input(
    image: npt.ArrayLike, mask: npt.ArrayLike | None
) -> tuple[np.ndarray, np.ndarray]:
    """Validate a decomposer input: float64 ``(H, W, 3)`` >= 0 image and bool ``(H, W)`` mask.

    Negative values (Monte Carlo or colour-conversion undershoot) are clipped to 0.
    """
    img = as_image(image, "image", channels=3)
    m = as_mask(mask, img.shape[:2])
    if not m.any():
        raise ImageShapeError("mask selects no pixel")
    return np.clip(img, 0.0, None), m


def finish(
    image: np.ndarray, reflectance: np.ndarray, mask: np.ndarray, info: dict[str, Any]
) -> Decomposition:
    """Build a :class:`Decomposition` whose shading is ``image / reflectance`` inside the mask."""
    refl = np.where(mask[:, :, None], reflectance, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        shading = np.where(refl > 0.0, image / np.where(refl > 0.0, refl, 1.0), 0.0)
    return Decomposition(refl.astype(np.float32), shading.astype(np.float32), info)
