"""A static HTML gallery of a dataset and a contact sheet of all its images.

``index.html`` (in the dataset folder) shows, per sample, the image and its ground-truth layers
side by side (the PNG previews of the sample folder) and the chromaticities of the sample's
lights on a CIE 1931 xy diagram drawn as inline SVG (spectral locus, sRGB gamut, D65).
``contact_sheet.png`` tiles every sample's image preview with its id. Neither needs a server
nor scripts: open ``index.html`` in a browser.
"""

from __future__ import annotations

import html
import json
import os
import string
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import png
from spectrinsic.gt_export.writer import META_NAME, read_template, sample_dirs

__all__ = ["build_gallery", "chromaticity_svg", "contact_sheet", "GALLERY_LAYERS"]

#: Layers shown per sample, in order (those a sample lacks are left out), then camera images.
GALLERY_LAYERS: tuple[str, ...] = (
    "image", "reflectance", "shading", "illuminant", "shading_grey", "depth", "normals",
    "material_id", "object_id", "image_rgb3", "error_rgb3", "image_rgb6", "error_rgb6",
    "image_spectral", "error_spectral",
)
#: Contact-sheet tile width in pixels and number of columns.
TILE = 160
COLUMNS = 8
_CAPTION_HEIGHT = 14
#: Plot window of the xy diagram.
_X_RANGE, _Y_RANGE = (0.0, 0.8), (0.0, 0.9)
_SVG_W, _SVG_H, _PAD = 200, 220, 22


def _spectral_locus() -> np.ndarray:
    """``(N, 2)`` xy of the CIE 1931 spectral locus, 380–700 nm."""
    from spectrinsic.spectra import get_sensors, xyz_to_xy

    cmf = get_sensors("cie1931")
    keep = (cmf.wavelengths >= 380) & (cmf.wavelengths <= 700)
    return xyz_to_xy(cmf.curves[:, keep].T)


def _hex(rgb_linear: Sequence[float]) -> str:
    rgb = np.clip(np.asarray(rgb_linear, float), 0.0, None)
    peak = rgb.max()
    encoded = png.encode_srgb8((rgb / peak if peak > 0 else rgb)[None, None, :])[0, 0]
    return "#" + "".join(f"{int(v):02x}" for v in encoded)


def chromaticity_svg(lights: Sequence[Mapping[str, Any]], *, locus: np.ndarray | None = None) -> str:
    """Inline SVG of a CIE 1931 xy diagram with one dot per light (filled with its sRGB colour).

    Parameters
    ----------
    lights
        Records with ``"xy"``, ``"srgb"`` and ``"spectrum"`` (as in ``meta.json["lights"]``).
    locus
        Precomputed spectral locus (``(N, 2)`` xy); computed when omitted.
    """
    import colour

    locus = _spectral_locus() if locus is None else locus
    sx = (_SVG_W - 2 * _PAD) / (_X_RANGE[1] - _X_RANGE[0])
    sy = (_SVG_H - 2 * _PAD) / (_Y_RANGE[1] - _Y_RANGE[0])

    def pt(x: float, y: float) -> str:
        return f"{_PAD + (x - _X_RANGE[0]) * sx:.1f},{_SVG_H - _PAD - (y - _Y_RANGE[0]) * sy:.1f}"

    primaries = np.asarray(colour.RGB_COLOURSPACES["sRGB"].primaries, float)
    white = np.asarray(colour.RGB_COLOURSPACES["sRGB"].whitepoint, float)
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{_SVG_W}" height="{_SVG_H}" '
        f'viewBox="0 0 {_SVG_W} {_SVG_H}" role="img" aria-label="CIE 1931 xy chromaticities">',
        f'<rect x="0" y="0" width="{_SVG_W}" height="{_SVG_H}" fill="#fff"/>',
        f'<polyline points="{pt(_X_RANGE[0], _Y_RANGE[1])} {pt(_X_RANGE[0], _Y_RANGE[0])} '
        f'{pt(_X_RANGE[1], _Y_RANGE[0])}" fill="none" stroke="#999"/>',
        '<polygon points="' + " ".join(pt(x, y) for x, y in locus) + '" fill="#f2f2f2" stroke="#333"/>',
        '<polygon points="' + " ".join(pt(x, y) for x, y in primaries)
        + '" fill="none" stroke="#888" stroke-dasharray="3,2"><title>sRGB gamut</title></polygon>',
        f'<circle cx="{pt(*white).split(",")[0]}" cy="{pt(*white).split(",")[1]}" r="2" '
        'fill="#000"><title>D65</title></circle>',
        f'<text x="{_PAD}" y="{_SVG_H - 5}" font-size="9">x</text>',
        f'<text x="4" y="{_PAD}" font-size="9">y</text>',
    ]
    for light in lights:
        x, y = light["xy"]
        cx, cy = pt(x, y).split(",")
        label = html.escape(f'{light.get("name", "light")}: {light["spectrum"]} (x={x:.4f}, y={y:.4f})')
        parts.append(
            f'<circle cx="{cx}" cy="{cy}" r="5" fill="{_hex(light["srgb"])}" stroke="#000">'
            f"<title>{label}</title></circle>"
        )
    parts.append("</svg>")
    return "".join(parts)


def _figure(src: str, caption: str) -> str:
    src_q, cap = html.escape(src, quote=True), html.escape(caption)
    return f'<figure><img src="{src_q}" alt="{cap}"><figcaption>{cap}</figcaption></figure>'


def _sample_section(sample: Path, meta: Mapping[str, Any], locus: np.ndarray) -> str:
    records = meta.get("layers", {})
    keys = [k for k in GALLERY_LAYERS if k in records]
    keys += [k for k in records if k.startswith("image_camera/")]
    figures = []
    for key in keys:
        preview = records[key].get("preview")
        if preview:
            figures.append(_figure(f"{sample.name}/{preview}", key))
    lights = meta.get("lights", [])
    light_text = "; ".join(
        f'<span class="swatch" style="background:{_hex(light["srgb"])}"></span> '
        f'{html.escape(str(light.get("name", "")))} {html.escape(light["spectrum"])} '
        f'(xy {light["xy"][0]:.3f}, {light["xy"][1]:.3f}; share {light.get("share", 1):.2f})'
        for light in lights
    )
    figures.append(
        f"<figure>{chromaticity_svg(lights, locus=locus)}"
        "<figcaption>light chromaticities (CIE 1931 xy)</figcaption></figure>"
    )
    sid = html.escape(sample.name)
    return (
        f'<section class="sample" id="{html.escape(sample.name, quote=True)}"><h2>{sid}</h2>'
        f'<p class="lights">scene {html.escape(str(meta.get("scene")))} · render '
        f'{html.escape(str(meta.get("reference_mode")))} · {light_text}</p>'
        f'<div class="row">{"".join(figures)}</div></section>'
    )


def contact_sheet(dataset_dir: str | os.PathLike[str], *, out: str | os.PathLike[str] | None = None) -> Path:
    """Tile every sample's ``image`` preview, captioned with its id, into one PNG."""
    from PIL import Image, ImageDraw, ImageFont

    root = Path(dataset_dir)
    samples = sample_dirs(root)
    if not samples:
        raise DatasetError(f"dataset folder {str(root)!r} has no complete samples for a contact sheet")
    font = ImageFont.load_default()
    cols = min(COLUMNS, len(samples))
    rows = -(-len(samples) // cols)
    sheet = Image.new("RGB", (cols * TILE, rows * (TILE + _CAPTION_HEIGHT)), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    for i, sample in enumerate(samples):
        meta = json.loads((sample / META_NAME).read_text(encoding="utf-8"))
        preview = meta["layers"]["image"]["preview"]
        with Image.open(sample / preview) as img:
            tile = img.convert("RGB")
            tile.thumbnail((TILE, TILE), Image.Resampling.LANCZOS)
        x0, y0 = (i % cols) * TILE, (i // cols) * (TILE + _CAPTION_HEIGHT)
        sheet.paste(tile, (x0 + (TILE - tile.width) // 2, y0 + (TILE - tile.height) // 2))
        caption = sample.name if len(sample.name) <= 26 else sample.name[:25] + "…"
        draw.text((x0 + 2, y0 + TILE + 1), caption, fill=(0, 0, 0), font=font)
    path = Path(out) if out is not None else root / "contact_sheet.png"
    sheet.save(path, format="PNG")
    return path


def build_gallery(dataset_dir: str | os.PathLike[str], *, title: str | None = None) -> Path:
    """Write ``index.html`` and ``contact_sheet.png`` into *dataset_dir*; return the HTML path."""
    root = Path(dataset_dir)
    samples = sample_dirs(root)
    if not samples:
        raise DatasetError(f"dataset folder {str(root)!r} has no complete samples for a gallery")
    locus = _spectral_locus()
    sections = []
    scenes = set()
    for sample in samples:
        meta = json.loads((sample / META_NAME).read_text(encoding="utf-8"))
        scenes.add(str(meta.get("scene")))
        sections.append(_sample_section(sample, meta, locus))
    contact_sheet(root)
    title = title or f"spectrinsic dataset: {root.resolve().name}"
    summary = (
        f"{len(samples)} samples of {len(scenes)} scenes. Previews are tone-mapped sRGB for "
        "viewing; the data are the float32 EXR files in each sample folder (see DATASET.md)."
    )
    page = string.Template(read_template("gallery.html")).substitute(
        title=html.escape(title), summary=html.escape(summary), samples="\n".join(sections)
    )
    path = root / "index.html"
    path.write_text(page, encoding="utf-8")
    return path
