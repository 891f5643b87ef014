"""The network's input and targets in log space, one definition for training and inference.

The input is the log of the linear image with the masked mean of its log luminance removed, so a
global exposure change leaves it unchanged (an image is known only up to scale). Targets are
the logs of reflectance and shading; the loss (:mod:`.loss`) is blind to their scale.
"""

from __future__ import annotations

import numpy as np

__all__ = ["EPS", "log_layer", "log_input"]

#: Floor of linear values before the log (linear, relative units): black pixels and the
#: Monte Carlo undershoot of a shading estimate would otherwise give -inf.
EPS = 1e-4


def log_layer(value: np.ndarray) -> np.ndarray:
    """``log(max(value, EPS))`` of a linear ``(H, W, 3)`` layer, float32.

    >>> float(log_layer(np.array([np.e]))[0])
    1.0
    """
    return np.log(np.maximum(np.asarray(value, np.float64), EPS)).astype(np.float32)


def log_input(image: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """The network's input: ``(H, W, 3)`` float32 log image, exposure-normalised.

    Parameters
    ----------
    image
        ``(H, W, 3)`` linear RGB, any positive scale.
    mask
        ``(H, W)`` bool, the pixels whose mean log luminance (the mean of the three log
        channels) is subtracted; an empty mask uses every pixel.

    >>> img = np.full((2, 2, 3), 0.5)
    >>> bool(np.allclose(log_input(img, np.ones((2, 2), bool)), log_input(8 * img, None)))
    True
    """
    logs = log_layer(image)
    where = np.ones(logs.shape[:2], bool) if mask is None or not np.any(mask) else mask
    return (logs - np.float32(logs[where].mean())).astype(np.float32)
