"""Inference: a weights file read back into its U-Net, and one image decomposed.

On 256² the network runs in well under a second on one CPU thread (measured in
``tests/learn/test_infer.py``).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DecomposeError
from .logspace import log_input
from .torch_import import require_torch
from .unet import FORMAT, UNetConfig, make_unet

__all__ = ["Network", "load_network", "predict"]


@dataclass(frozen=True)
class Network:
    """A trained U-Net in eval mode, with its shape and the weights file it came from."""

    module: Any
    config: UNetConfig
    path: Path


def load_network(path: str | os.PathLike[str]) -> Network:
    """The U-Net of a ``weights.pt`` written by ``spectrinsic train``.

    Raises
    ------
    DecomposeError
        The file is missing or is not a spectrinsic U-Net weights file.
    """
    torch = require_torch("the unet decomposer")
    weights = Path(path)
    if not weights.is_file():
        raise DecomposeError(f"unet: weights file {str(weights)!r} does not exist")
    try:  # our own record only: tensors, numbers, strings (no arbitrary objects)
        record = torch.load(weights, map_location="cpu", weights_only=True)
    except Exception as exc:  # any unpickling failure of a foreign file
        raise DecomposeError(
            f"unet: {str(weights)!r} is not a weights file of spectrinsic train ({exc})"
        ) from exc
    if not isinstance(record, dict) or record.get("format") != FORMAT:
        raise DecomposeError(f"unet: {str(weights)!r} is not a {FORMAT} weights file")
    config = UNetConfig(**record["net"])
    module = make_unet(config)
    module.load_state_dict(record["state_dict"])
    module.eval()
    return Network(module, config, weights)


def predict(network: Network, image: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Log reflectance and log shading, each ``(H, W, 3)`` float32, of a linear ``(H, W, 3)``
    *image* (any scale) with its bool *mask*; the image is padded (edge values) to a multiple
    of ``2 ** levels`` and the padding cropped off again."""
    torch = require_torch("the unet decomposer")
    h, w = image.shape[:2]
    unit = 2**network.config.levels
    ph, pw = -h % unit, -w % unit
    x = np.pad(log_input(image, mask), ((0, ph), (0, pw), (0, 0)), mode="edge")
    with torch.inference_mode():
        out = network.module(torch.from_numpy(np.moveaxis(x, -1, 0)[None].copy()))
    y = np.moveaxis(out[0].numpy(), 0, -1)[:h, :w]
    return np.ascontiguousarray(y[..., :3]), np.ascontiguousarray(y[..., 3:])
