"""The per-sample figure of an evaluation (``figures/<sample>.png``): the input and the ground
truth's reflectance and shading, then each method's, tone-mapped for display (99th percentile to
1, sRGB encoding; display only, never scored)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...file_writes import replacing
from ...spectra.colorimetry import encode_srgb

__all__ = ["sample_figure"]


def _display(a: np.ndarray) -> np.ndarray:
    """Tone-map a linear image for display: 99th percentile to 1, sRGB encoding."""
    a = np.asarray(a, dtype=np.float64)
    if a.ndim == 2:
        a = np.repeat(a[:, :, None], 3, axis=2)
    top = np.percentile(a, 99.0)
    return encode_srgb(a / (top if top > 0 else 1.0))


def sample_figure(path: Path, sid: str, image, reflectance, shading, rows) -> None:
    """Write the figure of sample *sid* to *path*: one row for the ground truth (*image*,
    *reflectance*, *shading*), then one per ``(method, Decomposition)`` of *rows*."""
    from matplotlib.figure import Figure  # no pyplot: no global backend state

    panels = [("ground truth", image, reflectance, shading)]
    panels += [(m, None, r.reflectance, r.shading) for m, r in rows]
    fig = Figure(figsize=(7.5, 2.4 * len(panels)))
    axes = fig.subplots(len(panels), 3, squeeze=False)
    for row, (label, img, refl, shad) in enumerate(panels):
        for col, (title, data) in enumerate(
            (("input", img), ("reflectance", refl), ("shading", shad))
        ):
            ax = axes[row, col]
            ax.set_axis_off()
            if data is not None:
                ax.imshow(_display(data), interpolation="nearest")
                ax.set_title(f"{label}: {title}" if col else f"{title}", fontsize=8)
            elif col == 0:
                ax.text(0.5, 0.5, label, ha="center", va="center", fontsize=10)
    fig.suptitle(sid, fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=80)
