"""A small U-Net: log image in, log reflectance and log shading out.

Ronneberger, Fischer and Brox, "U-Net", MICCAI 2015: an encoder of ``levels`` stages (two 3x3
convolutions with ReLU, then 2x2 max-pooling), a bottleneck, and a decoder that upsamples
(transposed 2x2 convolution), concatenates the encoder's features of the same size and convolves
again. ``width`` channels at the first stage, doubling at each. The last 1x1 convolution gives 6
channels: log reflectance (RGB) and log shading (RGB). Inputs are padded to a multiple of
``2 ** levels`` by :func:`spectrinsic.learn.infer.predict`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from .torch_import import require_torch

__all__ = ["FORMAT", "UNetConfig", "make_unet"]

#: The ``format`` tag of a weights file (written by :mod:`.card`, read by :mod:`.infer`).
FORMAT = "spectrinsic-unet/1"


@dataclass(frozen=True)
class UNetConfig:
    """The network's shape (stored with the weights, so a file rebuilds its own network).

    Attributes
    ----------
    width
        Channels of the first stage.
    levels
        Down-sampling stages (input sizes must be a multiple of ``2 ** levels``).
    """

    width: int = 16
    levels: int = 3

    def to_dict(self) -> dict[str, int]:
        return asdict(self)


def make_unet(config: UNetConfig) -> Any:
    """A fresh ``torch.nn.Module`` U-Net of *config*, mapping ``(B, 3, H, W)`` log images to
    ``(B, 6, H, W)``: channels 0-2 log reflectance, 3-5 log shading."""
    torch = require_torch("the U-Net")
    nn = torch.nn

    def block(c_in: int, c_out: int) -> Any:
        return nn.Sequential(
            nn.Conv2d(c_in, c_out, 3, padding=1),
            nn.ReLU(inplace=True),
            nn.Conv2d(c_out, c_out, 3, padding=1),
            nn.ReLU(inplace=True),
        )

    class UNet(nn.Module):  # type: ignore[misc, name-defined]
        def __init__(self) -> None:
            super().__init__()
            widths = [config.width * 2**k for k in range(config.levels + 1)]
            self.down = nn.ModuleList(
                block(3 if k == 0 else widths[k - 1], widths[k]) for k in range(config.levels)
            )
            self.bottom = block(widths[-2], widths[-1])
            self.up = nn.ModuleList(
                nn.ConvTranspose2d(widths[k + 1], widths[k], 2, stride=2)
                for k in reversed(range(config.levels))
            )
            self.merge = nn.ModuleList(
                block(2 * widths[k], widths[k]) for k in reversed(range(config.levels))
            )
            self.head = nn.Conv2d(widths[0], 6, 1)

        def forward(self, x: Any) -> Any:
            skips = []
            for stage in self.down:
                x = stage(x)
                skips.append(x)
                x = torch.nn.functional.max_pool2d(x, 2)
            x = self.bottom(x)
            for up, merge, skip in zip(self.up, self.merge, reversed(skips), strict=True):
                x = merge(torch.cat([up(x), skip], dim=1))
            return self.head(x)

    return UNet()
