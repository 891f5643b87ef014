"""The dataset card's residual figure: the distribution of the residual share by light family,
saved beside ``DATASET.md`` as ``residual.png`` (matplotlib's object API, no pyplot state).

One box per light family (:func:`~spectrinsic.gt_export.layers.spectral_intrinsics.light_family`,
most to least saturated) of the samples' RGB residual share (``meta.json["residual_share"]``,
``Σ|residual| / Σ|image|`` over the mask, in % on a log axis), each sample a dot on it; the
per-band share beside it where the samples hold spectral layers. The card's table gives the
same figures as median / p95 / max.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ...file_writes import replacing
from ..layers.spectral_intrinsics import LIGHT_FAMILIES, residual_rows

__all__ = ["RESIDUAL_FIGURE_NAME", "residual_by_family", "residual_figure", "write_residual_figure"]

#: File name of the figure, beside ``DATASET.md``.
RESIDUAL_FIGURE_NAME = "residual.png"
#: Shares below this (fractions) are drawn at it on the log axis (the per-band layers' ~1e-8).
_FLOOR = 1e-9


def residual_by_family(metas: Sequence[Any]) -> dict[str, dict[str, list[float]]]:
    """``{family: {"rgb": [...], "bands": [...]}}`` of parsed ``meta.json`` objects (fractions),
    in :data:`LIGHT_FAMILIES` order; samples without a share are left out.

    >>> m = {"lights": [{"spectrum": "led:540/31"}], "residual_share": {"image": 0.2}}
    >>> residual_by_family([m])
    {'narrow-led': {'rgb': [0.2], 'bands': []}}
    """
    rows = residual_rows(metas)
    return {
        f: {"rgb": rows[f]["rgb"], "bands": rows[f]["spectral"]}
        for f in LIGHT_FAMILIES
        if f in rows
    }


def residual_figure(by_family: Mapping[str, Mapping[str, list[float]]], space: str) -> Any:
    """A :class:`matplotlib.figure.Figure`: boxes and dots of the residual share (%) per family."""
    from matplotlib.figure import Figure  # noqa: PLC0415 - heavy; only here

    families = list(by_family)
    fig = Figure(figsize=(max(4.0, 1.1 * len(families) + 1.5), 3.4), layout="constrained")
    ax = fig.add_subplot()
    series = (("rgb", f"RGB ({space})", "tab:red", -0.18), ("bands", "per band", "tab:blue", 0.18))
    for key, label, colour, shift in series:
        data = [100 * np.maximum(by_family[f][key], _FLOOR) for f in families]
        where = [i + shift for i, d in enumerate(data) if len(d)]
        if not where:
            continue
        shown = [d for d in data if len(d)]
        ax.boxplot(shown, positions=where, widths=0.3, showfliers=False, manage_ticks=False)
        for x, d in zip(where, shown):
            jitter = np.linspace(-0.08, 0.08, len(d)) if len(d) > 1 else np.zeros(1)
            ax.scatter(
                x + jitter, d, s=8, color=colour, alpha=0.7, label=label if x == where[0] else None
            )
    ax.set_yscale("log")
    ax.set_xticks(range(len(families)), [f"{f}\n({len(by_family[f]['rgb'])})" for f in families])
    ax.set_ylabel("residual share Σ|residual| / Σ|image| (%)")
    ax.set_title("Residual share by light family (samples)")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)
    return fig


def write_residual_figure(
    dataset_dir: str | os.PathLike[str], metas: Sequence[Any], space: str
) -> Path | None:
    """Save :func:`residual_figure` as ``<dataset>/residual.png``; ``None`` (nothing written)
    when no sample records a residual share."""
    by_family = residual_by_family(metas)
    if not by_family:
        return None
    path = Path(dataset_dir) / RESIDUAL_FIGURE_NAME
    with replacing(path) as tmp:
        residual_figure(by_family, space).savefig(tmp, dpi=90)
    return path
