"""Trivial decompositions that bound the scale of the scores (Grosse et al. 2009 baselines)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..decomposition import Decomposition, finish, prepare_input

__all__ = ["ImageAsReflectance", "ImageAsShading"]


@dataclass(frozen=True)
class ImageAsReflectance:
    """Reflectance = image, constant (unit) shading."""

    name: str = "image-as-reflectance"

    def __call__(self, image: npt.ArrayLike, mask: npt.ArrayLike | None = None) -> Decomposition:
        img, m = prepare_input(image, mask)
        return finish(img, img, m, {})


@dataclass(frozen=True)
class ImageAsShading:
    """Constant (unit) reflectance, shading = image."""

    name: str = "image-as-shading"

    def __call__(self, image: npt.ArrayLike, mask: npt.ArrayLike | None = None) -> Decomposition:
        img, m = prepare_input(image, mask)
        return finish(img, np.ones_like(img), m, {})
