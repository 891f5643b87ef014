"""The photometric study's figure (matplotlib's object API: no pyplot, no backend state)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...spectra import ESTIMATE_SCENARIOS
from .compute import PhotometricResult, mean_error_table

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["photometric_figure"]


def photometric_figure(result: PhotometricResult) -> Figure:
    """Bars of the mean angular error (degrees, Eq. 4.31) of SC1..SC4 per camera, one panel per
    illuminant set."""
    from matplotlib.figure import Figure

    table = mean_error_table(result)
    cams = list(table)
    sets = result.settings.illuminant_sets
    fig = Figure(figsize=(max(8.0, 0.42 * len(cams) + 2), 3.4 * len(sets)), layout="constrained")
    axes = fig.subplots(len(sets), 1, squeeze=False)
    x = np.arange(len(cams))
    w = 0.2
    for ax, s in zip(axes[:, 0], sets):
        for i, sc in enumerate(ESTIMATE_SCENARIOS):
            ax.bar(x + (i - 1.5) * w, [table[c][s][sc] for c in cams], w, label=sc)
        ax.set_xticks(
            x, [c.removeprefix("camera:") for c in cams], rotation=60, ha="right", fontsize=7
        )
        ax.set_ylabel("mean angular error (°)")
        ax.set_title(f"{s} illuminants")
        ax.legend(ncol=4, fontsize=8)
        ax.grid(axis="y", alpha=0.3)
    return fig
