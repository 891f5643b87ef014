"""``DATASET.md``: the dataset card (what each layer is, its units, how to load it).

Filled from ``spectrinsic/gt_export/templates/DATASET.md`` with the samples' validated ``meta.json``
records, and its "Size and build time" section with the set's own bytes (measured from the
folder, :mod:`.disk_use`) and its build's time (:mod:`.build_time`). Everything taken
from the data (scene and layer names, units) is HTML-escaped, so a scene called
``<script>...`` shows as text in a Markdown viewer instead of running.
"""

from __future__ import annotations

import html
import json
import os
import string
from collections.abc import Mapping, Sequence
from importlib import resources
from pathlib import Path
from typing import Any

from ...errors import DatasetError
from ...file_writes import write_text_file
from ...provenance import software_versions
from ..layers.spectral_intrinsics import gamut_key, residual_summary
from ..sample import CARD_NAME, META_NAME, config_hash, plain_data, sample_dirs
from ..sample.meta import LayerRecord, SampleMeta, read_meta
from ..sample.working_view import space_of
from .build_time import read_build_record
from .card_residual import write_residual_figure
from .card_sizes import size_section
from .card_text import colour_conventions, percent
from .colour_spread import shown, spread_summary
from .disk_use import disk_use
from .diversity import DIVERSITY_NAME, spread_record, write_diversity
from .manifest import noise_summary, read_manifest, splits_by_scene, variants_of

__all__ = ["write_dataset_card", "read_template"]


def read_template(name: str) -> str:
    """Text of a package template (``gt_export/templates/<name>``)."""
    return resources.files("spectrinsic.gt_export").joinpath("templates", name).read_text("utf-8")


def _text(value: object) -> str:
    """*value* as Markdown-safe text: HTML special characters escaped (quotes kept)."""
    return html.escape(str(value), quote=False)


def _diversity_section(root: Path, samples: Sequence[Path], metas: Sequence[SampleMeta]) -> str:
    """The card's diversity section: splits by scene and ``diversity.png`` (written here)."""
    figure = root / DIVERSITY_NAME
    newest = max((s / META_NAME).stat().st_mtime_ns for s in samples)
    if not figure.is_file() or figure.stat().st_mtime_ns < newest:  # a resumed build: keep it
        write_diversity(root, samples, metas)
    manifest = read_manifest(root)  # the splits the build wrote (its --split-fractions)
    scenes = {m.sample_id: m.scene for m in metas}
    splits = (
        manifest.splits if manifest is not None and manifest.splits else splits_by_scene(scenes)
    )
    counts = ", ".join(
        f"{k} {len(v)} samples ({len({scenes[i] for i in v if i in scenes})} scenes)"
        for k, v in splits.items()
    )
    spread = spread_summary([spread_record(m) for m in metas])
    return (
        f"\n## Splits and diversity\n\nSplits by scene (no scene in two splits; "
        f'`manifest.json["splits"]`; every split holds a scene from as many scenes as '
        f"splits on): {counts}.\n\n"
        f"Colour spread: lights cover {shown(spread['xy_hull_area'], '.3f')} of CIE 1931 xy (hull area), "
        f"{shown(spread['d65_distance_median'], '.3f')} median xy distance from D65, "
        f"{shown(spread['tinted_fraction'], '.0%')} of non-D65 lights tinted (|Duv| >= 0.02, Ohno 2013), "
        f"paired lights at least {shown(spread['pair_distance_min'], '.3f')} apart in xy; material chroma "
        f"C*ab median {shown(spread['chroma_median'], '.1f')} (p90 {shown(spread['chroma_p90'], '.1f')}); "
        f"{shown(spread['patterned_fraction'], '.0%')} of generated objects patterned "
        f"({shown(spread['textured_fraction'], '.0%')} spectrally textured), "
        f"{shown(spread['framed_fraction'], '.0%')} of views framed (>= 30 % objects).\n\n"
        f"![r, light CCT and xy, materials per image, object coverage, luminance range]"
        f"({DIVERSITY_NAME})\n"
    )


def _noise_table(summary: Mapping[str, Any]) -> str:
    if not summary:
        return "Rendered as a single batch: no noise estimate (build with `batches` ≥ 2)."
    lines = [
        "Relative standard error of the raw Monte Carlo layers, per pixel, from the spread of "
        "independent batches (the denoised layers are measured against converged renders "
        "in `make bench`). Per sample: median, 95th percentile and RMS over its pixels; with two "
        "batches a pixel's estimate has one degree of freedom, so the RMS is the unbiased "
        "figure and the median reads about 0.67 of it.",
        "",
        "| layer | scenes | samples | median of medians | median of p95 | median of RMS | worst median (sample) |",
        "|---|---|---|---|---|---|---|",
    ]
    for layer, kinds in sorted(summary.items()):
        for kind, row in sorted(kinds.items()):
            lines.append(
                f"| `{layer}` | {_text(kind)} | {row['samples']} | {100 * row['median_of_medians']:.1f} % "
                f"| {100 * row['median_of_p95']:.1f} % | {100 * row['median_of_rms']:.1f} % "
                f"| {100 * row['worst_median']:.1f} % "
                f"(`{row['worst_sample']}`) |"
            )
    return "\n".join(lines)


def _residual_table(summary: Mapping[str, Any], root: Path, metas: Sequence[SampleMeta]) -> str:
    if not summary:
        return "The samples record no residual share (built before it was measured)."
    spaces = sorted({space_of(m.raw).colourspace for m in metas})
    space = spaces[0] if len(spaces) == 1 else "working space"
    figure = write_residual_figure(root, [m.raw for m in metas], space)
    clips = any(gamut_key(m.raw) == "clipped_pixels" for m in metas)
    gamut = (
        "linear sRGB clips it into the residual"
        if clips
        else f"{_text(', '.join(spaces))} keeps it in the shading"
    )
    lines = [
        "Share of the image the intrinsic product does not explain, Σ|residual| / Σ|image| over "
        "the mask, per sample; median / 95th percentile / max over the samples of each light "
        "family (a sample's family is its most saturated light's). The RGB layers' residual "
        f"(working space: {_text(', '.join(spaces))}) holds the spectral non-commutativity a "
        "3-channel product cannot represent; out-of-gamut pixels are the share of lit pixels "
        f"whose shading has a negative channel in the working space ({gamut}). The per-band "
        "layers (`--spectral-layers`) multiply out band by band. `spectrinsic check "
        "--max-residual-share F` and the loaders' `max_residual_share` select samples by the "
        "RGB figure.",
        "",
        f"![Residual share by light family]({figure.name})" if figure is not None else "",
        "",
        "| light family | samples | RGB residual | per-band residual | shading out-of-gamut pixels |",
        "|---|---|---|---|---|",
    ]

    def cell(row: Mapping[str, Any], *keys: str) -> str:
        fig = next((row[k] for k in keys if row.get(k)), None)
        if not fig:
            return "–"
        return " / ".join(percent(fig[k]) for k in ("median", "p95", "max"))

    for family, row in summary.items():
        lines.append(
            f"| {_text(family)} | {row['samples']} | {cell(row, 'rgb')} | "
            f"{cell(row, 'spectral')} | {cell(row, 'out_of_gamut_share', 'clipped_pixels')} |"
        )
    return "\n".join(lines)


def _layer_table(metas: Sequence[SampleMeta]) -> str:
    rows: dict[str, LayerRecord] = {}
    for meta in metas:
        for name, rec in meta.layers.items():
            rows.setdefault(name, rec)
    return "\n".join(
        f"| `{_text(name)}` | `{_text(rec.file)}` | {_text(', '.join(rec.channels))} | {_text(rec.units)} |"
        for name, rec in rows.items()
    )


def write_dataset_card(
    dataset_dir: str | os.PathLike[str], config: Mapping[str, Any] | None = None
) -> Path:
    """Write ``DATASET.md``: what each layer is, its units, colour space, and how to load it."""
    root = Path(dataset_dir)
    samples = sample_dirs(root)
    if not samples:
        raise DatasetError(f"dataset folder {str(root)!r} has no complete samples to describe")
    metas = [read_meta(s) for s in samples]
    scenes = sorted({m.scene for m in metas})
    chash = config_hash(config) if config is not None else metas[0].config_hash
    variants = variants_of(metas)
    text = string.Template(read_template("DATASET.md")).substitute(
        **colour_conventions([space_of(m.raw) for m in metas]),
        noise_table=_noise_table(noise_summary(metas)),
        residual_table=_residual_table(residual_summary([m.raw for m in metas]), root, metas),
        n_samples=len(samples),
        n_scenes=len(scenes),
        scenes=", ".join(_text(s) for s in scenes),
        layer_table=_layer_table(metas),
        config_hash=chash,
        config=json.dumps(
            plain_data(config or {}), indent=2, sort_keys=True, allow_nan=False
        ),  # a code block
        versions=json.dumps(software_versions(), indent=2, sort_keys=True, allow_nan=False),
        variants=", ".join(_text(v) for v in variants),
        size_section=size_section(
            disk_use(samples), read_build_record(root, chash), [_text(v) for v in variants]
        ),
    ) + _diversity_section(root, samples, metas)
    path = root / CARD_NAME
    write_text_file(path, text)
    return path
