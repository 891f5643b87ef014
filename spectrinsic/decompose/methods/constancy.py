"""Global colour constancy for decomposers: the light's colour leaves the reflectance.

Both bundled methods recover reflectance up to what they take as shading. Grosse et al.'s colour
Retinex and the thesis' names-and-shades both keep the image's colour in the reflectance, so a
coloured light tints the whole reflectance and every colour metric counts the tint as error
(LMSE fits one scale per window, not one per channel). The dataset's coloured ``shading``
layer carries the light's colour; estimating it is colour constancy.

:func:`illuminant_colour` estimates one RGB light colour per image with the Minkowski family of
Finlayson & Trezzi (2004): ``L_c ∝ (mean_p I_c(p)^p)^(1/p)`` over the masked pixels; ``p = 1``
is grey-world (Buchsbaum 1980), ``p = ∞`` max-RGB (white patch, Land); ``p = 6`` is the
"shades of grey" value they recommend. The estimate is normalised to mean channel 1, so the
reflectance keeps its intensity and only its colour changes. The light is estimated over every
pixel of the image that received light, not only the decomposer's mask: the surroundings of a
masked object (its ground, walls) tell the light's colour better than the object alone, whose
own colour grey-world would take for the light's.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ...errors import DecomposeError, validate_choice
from ..decomposition import Decomposition, finish

__all__ = ["CONSTANCY", "illuminant_colour", "discount_illuminant", "with_constancy"]

#: Registry: name -> Minkowski norm ``p`` (``None``: no correction; ``inf``: max-RGB).
CONSTANCY: Mapping[str, float | None] = {
    "none": None,
    "grey-world": 1.0,
    "shades-of-grey": 6.0,
    "max-rgb": float("inf"),
}
#: Max-RGB uses this percentile rather than the maximum (robust to a few hot pixels).
MAX_RGB_PERCENTILE = 99.5


def illuminant_colour(image: np.ndarray, mask: np.ndarray, method: str) -> np.ndarray:
    """The light colour ``(3,)`` of a linear ``(H, W, 3)`` image, mean channel 1.

    ``(1, 1, 1)`` for ``method="none"`` and for an image that is black in a channel.

    >>> img = np.ones((2, 2, 3)) * np.array([2.0, 1.0, 0.0])
    >>> illuminant_colour(img + 1.0, np.ones((2, 2), bool), "grey-world").tolist()
    [1.5, 1.0, 0.5]
    """
    p = CONSTANCY[validate_choice(method, CONSTANCY, "colour constancy", error=DecomposeError)]
    if p is None:
        return np.ones(3)
    values = np.clip(image[mask], 0.0, None)
    if np.isinf(p):
        light = np.percentile(values, MAX_RGB_PERCENTILE, axis=0)
    else:
        light = np.mean(values**p, axis=0) ** (1.0 / p)
    if not np.all(light > 0.0):
        return np.ones(3)
    return light / light.mean()


def discount_illuminant(
    reflectance: np.ndarray, image: np.ndarray, mask: np.ndarray, method: str
) -> tuple[np.ndarray, list[float]]:
    """Divide *reflectance* per channel by the light colour estimated from *image*.

    The estimate uses every pixel of *image* with a positive channel (module docstring);
    *mask* only when none has.

    Returns the corrected reflectance and the light colour (for the method's ``info``).
    """
    lit = np.asarray(image).max(axis=-1) > 0.0
    light = illuminant_colour(image, lit if lit.any() else mask, method)
    return reflectance / light, [round(float(v), 6) for v in light]


def with_constancy(
    result: Decomposition, image: np.ndarray, mask: np.ndarray, *, colour_constancy: str
) -> Decomposition:
    """*result* (made with ``colour_constancy="none"``) as the method would give it with
    *colour_constancy*: the reflectance divided by the light colour, ``shading = image / R``."""
    refl, light = discount_illuminant(
        np.asarray(result.reflectance, np.float64), image, mask, colour_constancy
    )
    return finish(np.clip(image, 0.0, None), refl, mask, {**result.info, "light_colour": light})
