"""Stress variants of an MIT object: exposure, white balance, noise and half resolution.

Each variant changes the input photograph the way a camera would and keeps the ground truth
(the benchmark's LMSE fits one scale per window, so an exposure or a gain needs no change to
the truth; the half-resolution variant averages the truth like the image). Inputs stay linear
in [0, 1] and are quantised to the dataset's 16-bit codes after the change, so a brighter
exposure saturates at 1 as a sensor does.

* ``exposure-x0.25``, ``exposure-x4``: the image times 0.25 or 4, clipped at 1;
* ``white-balance``: channel gains (1.25, 1, 0.75) (a wrong camera white balance, warm),
  clipped at 1;
* ``noise``: shot and read noise, ``sigma(x) = sqrt(1e-4 x + 0.002^2)`` (a sensor of 10^4
  electrons at full scale and a read noise of 0.2 % of it), seeded by the object's name;
* ``downscale-0.5``: 2 x 2 box averages of image and truth (an odd last row or column is
  dropped), a pixel kept in the mask when all four of its pixels were.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable, Mapping
from dataclasses import replace

import numpy as np

from .mit import MitObject

__all__ = ["VARIANTS", "apply_variant"]

#: Full scale of the dataset's 16-bit codes.
_CODES = 65535.0
#: Channel gains of the white-balance variant (R, G, B).
_WHITE_BALANCE = (1.25, 1.0, 0.75)
#: Shot-noise variance per unit signal and read-noise sigma of the noise variant.
_SHOT, _READ = 1e-4, 0.002


def _quantised(image: np.ndarray) -> np.ndarray:
    return np.round(np.clip(image, 0.0, 1.0) * _CODES) / _CODES


def _gain(gain: tuple[float, float, float]) -> Callable[[MitObject], MitObject]:
    def vary(obj: MitObject) -> MitObject:
        return replace(obj, image=_quantised(obj.image * np.asarray(gain)))

    return vary


def _noise(obj: MitObject) -> MitObject:
    rng = np.random.default_rng(zlib.crc32(obj.name.encode("utf-8")))
    sigma = np.sqrt(_SHOT * obj.image + _READ**2)
    return replace(obj, image=_quantised(obj.image + sigma * rng.standard_normal(obj.image.shape)))


def _half(a: np.ndarray) -> np.ndarray:
    h, w = (a.shape[0] // 2) * 2, (a.shape[1] // 2) * 2
    a = a[:h, :w]
    return a.reshape(h // 2, 2, w // 2, 2, *a.shape[2:]).mean(axis=(1, 3))


def _downscale(obj: MitObject) -> MitObject:
    return MitObject(
        obj.name,
        _quantised(_half(obj.image)),
        _half(obj.reflectance),
        _half(obj.shading),
        _half(obj.mask.astype(np.float64)) == 1.0,
    )


#: The variants by name (module docstring); ``original`` is the object as it is.
VARIANTS: Mapping[str, Callable[[MitObject], MitObject]] = {
    "original": lambda obj: obj,
    "exposure-x0.25": _gain((0.25, 0.25, 0.25)),
    "exposure-x4": _gain((4.0, 4.0, 4.0)),
    "white-balance": _gain(_WHITE_BALANCE),
    "noise": _noise,
    "downscale-0.5": _downscale,
}


def apply_variant(name: str, obj: MitObject) -> MitObject:
    """*obj* under the variant *name* (:data:`VARIANTS`); ``KeyError`` naming the choices."""
    if name not in VARIANTS:
        raise KeyError(f"unknown MIT variant {name!r}; expected one of {', '.join(VARIANTS)}")
    return VARIANTS[name](obj)
