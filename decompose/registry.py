"""Registry of the bundled decomposers, with validated dispatch."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy.typing as npt

from spectrinsic.decompose.baselines import ImageAsReflectance, ImageAsShading
from spectrinsic.decompose.decomposition import Decomposer, Decomposition
from spectrinsic.decompose.names_shades import NamesAndShades
from spectrinsic.decompose.retinex import ColourRetinex
from spectrinsic.errors import validate_choice

__all__ = ["DECOMPOSERS", "get_decomposer", "decompose"]

#: Name -> factory (keyword parameters -> decomposer), in the order tables list them.
DECOMPOSERS: Mapping[str, Callable[..., Any]] = {
    "names-shades": NamesAndShades,
    "colour-retinex": ColourRetinex,
    "image-as-reflectance": ImageAsReflectance,
    "image-as-shading": ImageAsShading,
}


def get_decomposer(name: str, **params: Any) -> Decomposer:
    """The decomposer called *name*, built with *params* (e.g. ``threshold_grey=0.1``)."""
    return DECOMPOSERS[validate_choice(name, DECOMPOSERS, "decomposer")](**params)


def decompose(
    image: npt.ArrayLike, mask: npt.ArrayLike | None = None, *, method: str, **params: Any
) -> Decomposition:
    """Decompose a linear ``(H, W, 3)`` image with the registered *method*."""
    return get_decomposer(method, **params)(image, mask)
