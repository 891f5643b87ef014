"""Diversity report of a dataset: the distributions that matter for learning, as a figure.

Per sample, from ``meta.json`` and the image layer: the energy ratio r (Eq. 5.8, recorded in
``scene_metadata.energy_ratio_r`` when the build rendered direct light), the lights' CIE 1931
xy and correlated colour temperature (McCamy), the number of materials and their colours, the
object coverage of the camera (generated scenes) and the image's luminance range; the lights'
|Duv| and the materials' CIELAB chroma, and the set's colour-spread figures
(:func:`~spectrinsic.gt_export.dataset.colour_spread.spread_summary`: xy hull area, distances from
D65 and between paired lights, patterned and framed fractions) in the titles. The figure is
built with matplotlib's object API (``Figure``, no pyplot state) and saved as ``diversity.png``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ...file_writes import replacing
from ...scenes.generators.materials import PIXEL_TEXTURE
from ...spectra.colorimetry import luminance
from ..sample.meta import SampleMeta
from .colour_spread import recorded_chromas, shown, spread_summary
from .loader import load_sample

__all__ = [
    "DIVERSITY_NAME",
    "diversity_stats",
    "diversity_figure",
    "spread_record",
    "write_diversity",
]

DIVERSITY_NAME = "diversity.png"
#: Luminance percentiles whose ratio is the "luminance range" (decades).
_RANGE_PERCENTILES = (1.0, 99.0)
#: Generator pattern names of spectral textures: face-resolution mixes and per-pixel textures.
_TEXTURED = ("texture", PIXEL_TEXTURE)


def _cct(xy: Sequence[float]) -> float:
    """McCamy's CCT in K from CIE 1931 xy (``colour.temperature.xy_to_CCT``)."""
    import colour

    return float(colour.temperature.xy_to_CCT(np.asarray(xy, float), method="McCamy 1992"))


def _luminance_decades(image: np.ndarray, mask: np.ndarray | None) -> float:
    y = luminance(image)
    y = y[mask] if mask is not None and mask.any() else y.ravel()
    y = y[y > 0]  # unlit pixels (no Monte Carlo sample reached a light) have no decade
    if y.size == 0:
        return 0.0
    lo, hi = np.percentile(y, _RANGE_PERCENTILES)
    return float(np.log10(max(hi, 1e-12) / max(lo, 1e-12)))


def spread_record(meta: SampleMeta) -> dict[str, Any]:
    """One sample's record for :func:`~spectrinsic.gt_export.dataset.colour_spread.spread_summary`."""
    extra = meta.scene_metadata
    return {
        "lights": [tuple(light.xy) for light in meta.lights],
        "materials": list(meta.materials.values()),
        "patterned": len(extra.get("patterns", [])),
        "textured": sum(p in _TEXTURED for p in extra.get("patterns", [])),
        "objects": int(extra.get("n_objects", 0) or 0),
        "coverage": extra.get("object_coverage"),
    }


def diversity_stats(
    sample_dirs: Sequence[Path], metas: Sequence[SampleMeta]
) -> dict[str, list[Any]]:
    """Per-sample statistics (lists aligned with *sample_dirs*; ``r`` only where recorded).

    Returns
    -------
    dict
        ``r`` (unitless), ``light_xy`` (one ``(x, y)`` per light), ``light_cct`` (K),
        ``n_materials``, ``material_chroma`` (C*ab of each material under D65), ``coverage``
        (fraction), ``luminance_decades`` (log10 of p99/p1), and ``samples``: one record per
        sample for :func:`~spectrinsic.gt_export.dataset.colour_spread.spread_summary`.
    """
    out: dict[str, list[Any]] = {
        k: []
        for k in (
            "r",
            "light_xy",
            "light_cct",
            "n_materials",
            "material_chroma",
            "coverage",
            "luminance_decades",
            "samples",
        )
    }
    for folder, meta in zip(sample_dirs, metas, strict=True):
        extra = meta.scene_metadata
        if isinstance(extra.get("energy_ratio_r"), float) and np.isfinite(extra["energy_ratio_r"]):
            out["r"].append(extra["energy_ratio_r"])
        for light in meta.lights:
            out["light_xy"].append(light.xy)
            out["light_cct"].append(_cct(light.xy))
        out["n_materials"].append(len(meta.materials))
        out["material_chroma"] += recorded_chromas(meta.materials.values())
        out["samples"].append(spread_record(meta))
        if isinstance(extra.get("object_coverage"), float):
            out["coverage"].append(extra["object_coverage"])
        sample = load_sample(
            folder, layers=[k for k in ("image", "mask") if k in meta.layers], space="srgb"
        )
        out["luminance_decades"].append(_luminance_decades(sample["image"], sample.get("mask")))
    return out


def diversity_figure(stats: Mapping[str, Sequence[Any]]) -> Any:
    """A 2 x 4 :class:`matplotlib.figure.Figure` of the statistics (empty panels say why)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(16, 7), layout="constrained")
    axes = fig.subplots(2, 4).ravel()
    summary = spread_summary(list(stats.get("samples", [])))
    panels = [
        ("r", "energy ratio r (direct / total)", "needs a build with --direct"),
        ("light_cct", "light CCT (K, McCamy)", "no lights"),
        ("n_materials", "materials per image", "no materials"),
        (
            "material_chroma",
            f"material chroma C*ab (median {shown(summary['chroma_median'], '.1f')})",
            "no materials",
        ),
        (
            "coverage",
            f"object coverage (framed {shown(summary['framed_fraction'], '.0%')})",
            "library scenes: not recorded",
        ),
        ("luminance_decades", "luminance range, log10(p99/p1)", "no images"),
    ]
    for ax, (key, title, empty) in zip(axes[[0, 1, 4, 5, 6, 7]], panels, strict=True):
        values = list(stats.get(key, []))
        ax.set_title(title, fontsize=10)
        if values:
            ax.hist(values, bins=min(20, max(3, len(values))), color="0.35")
        else:
            ax.text(0.5, 0.5, empty, ha="center", va="center", transform=ax.transAxes)
    xy = np.asarray(stats.get("light_xy", []), float).reshape(-1, 2)
    ax = axes[2]
    ax.scatter(xy[:, 0], xy[:, 1], s=12, c="k")
    ax.plot(*_planckian_xy(), color="tab:orange", lw=1, label="Planckian 1000-25000 K")
    ax.scatter([0.31271], [0.32902], marker="+", s=80, c="tab:red", label="D65")
    ax.set(
        title=f"light xy (hull area {shown(summary['xy_hull_area'], '.3f')})",
        xlabel="x",
        ylabel="y",
        xlim=(0.0, 0.75),
        ylim=(0.0, 0.85),
    )
    ax.legend(fontsize=7)
    ax = axes[3]
    d65 = np.linalg.norm(xy - np.array([0.31271, 0.32902]), axis=1) if len(xy) else []
    ax.hist(d65, bins=20, color="0.35")
    ax.set_title(
        f"light xy distance from D65\n(tinted, |Duv| >= 0.02: {shown(summary['tinted_fraction'], '.0%')}; "
        f"pairs >= {shown(summary['pair_distance_min'], '.3f')} apart)",
        fontsize=9,
    )
    return fig


def _planckian_xy() -> tuple[np.ndarray, np.ndarray]:
    import colour

    uv = colour.temperature.CCT_to_uv_Ohno2013(
        np.stack([np.geomspace(1000, 25000, 60), np.zeros(60)], -1)
    )
    xy = colour.UCS_uv_to_xy(uv)
    return xy[:, 0], xy[:, 1]


def write_diversity(
    dataset_dir: str | os.PathLike[str], sample_dirs: Sequence[Path], metas: Sequence[SampleMeta]
) -> Path:
    """Compute the statistics and save the figure as ``<dataset>/diversity.png``."""
    path = Path(dataset_dir) / DIVERSITY_NAME
    figure = diversity_figure(diversity_stats(sample_dirs, metas))
    with replacing(path) as tmp:  # a full disk names the file and leaves no part of it
        figure.savefig(tmp, dpi=90)
    return path
