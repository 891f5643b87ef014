"""The rendering study's per-sample figure (matplotlib's object API: no pyplot, no backend)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...spectra import xyz_to_linear_srgb
from ...spectra.colorimetry import encode_srgb

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["error_figure"]


def _display(xyz: np.ndarray) -> np.ndarray:
    """sRGB-encoded ``(H, W, 3)`` in [0, 1] of linear XYZ, scaled so its 99th-percentile Y is 1."""
    scale = float(np.percentile(xyz[..., 1], 99)) or 1.0
    return encode_srgb(xyz_to_linear_srgb(xyz) / scale)


def error_figure(title: str, reference: np.ndarray, errors: dict[str, np.ndarray]) -> Figure:
    """The reference (``(H, W, 3)`` linear XYZ, shown sRGB-encoded) beside each compared mode's
    ε map (``(H, W)`` fractions, shown in percent, Eq. 5.7 on XYZ) on one colour scale."""
    from matplotlib.figure import Figure

    top = (
        max(float(np.nanmax(e)) if np.isfinite(e).any() else 0.0 for e in errors.values()) * 100
        or 1.0
    )
    fig = Figure(figsize=(3.2 * (1 + len(errors)), 3.4))
    axes = fig.subplots(1, 1 + len(errors))
    axes[0].imshow(_display(reference))
    axes[0].set_title("reference (31 bands, sRGB)", fontsize=9)
    image = None
    for ax, (mode, err) in zip(axes[1:], errors.items(), strict=True):
        image = ax.imshow(100 * err, cmap="magma", vmin=0.0, vmax=top)
        ax.set_title(f"{mode}: mean {100 * np.nanmean(err):.2f} %", fontsize=9)
    for ax in axes:
        ax.set_axis_off()
    if image is not None:
        fig.colorbar(image, ax=list(axes[1:]), shrink=0.8, label="ε (%) Eq. 5.7 on XYZ")
    fig.suptitle(title, fontsize=10)
    return fig
