"""The trained U-Net of ``spectrinsic train`` as a decomposer: ``evaluate --methods unet:WEIGHTS``.

The network predicts log reflectance and log shading (:mod:`spectrinsic.learn.unet`). The two
heads need not multiply back to the image, while every decomposer here returns
``image = reflectance * shading`` (thesis Eq. 3.1); the reflectance returned is the geometric
mean of the reflectance head and of the image over the shading head,
``log R = (log R̂ + log I - log Ŝ) / 2`` (both known up to scale, so only their shapes meet),
and the shading is ``I / R``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ...learn.infer import Network, load_network, predict
from ...learn.logspace import log_input
from ..decomposition import Decomposition, finish, prepare_input

__all__ = ["UNetDecomposer"]


@dataclass(frozen=True)
class UNetDecomposer:
    """A U-Net weights file as a decomposer (the file is read once, when it is built).

    Attributes
    ----------
    weights
        Path of a ``weights.pt`` written by ``spectrinsic train``.
    """

    weights: str
    name: str = "unet"
    network: Network = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "network", load_network(self.weights))

    def __call__(self, image: npt.ArrayLike, mask: npt.ArrayLike | None = None) -> Decomposition:
        img, m = prepare_input(image, mask)
        began = time.perf_counter()
        log_r, log_s = predict(self.network, img, m)
        log_rec = 0.5 * (log_r + log_input(img, m) - log_s)
        # a common scale so the reflectance's masked mean log is 0 (values near 1, finite)
        refl = np.exp(log_rec - log_rec[m].mean()).astype(np.float64)
        info: dict[str, Any] = {
            "weights": str(self.network.path),
            "seconds": round(time.perf_counter() - began, 4),
        }
        return finish(img, refl, m, info)
