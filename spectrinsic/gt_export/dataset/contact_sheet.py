"""Contact sheets: one PNG tiling every sample's denoised image with its id (the gallery's
overview, and one sheet per lighting condition)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ...errors import DatasetError
from ...file_writes import guarded_write, replacing
from ...scenes.sample_id import SEPARATOR
from ..sample import META_NAME, sample_dirs
from ..sample.meta import read_meta

__all__ = ["contact_sheet", "tile_sheet", "COLUMNS", "TILE"]

#: Tile size in pixels (the preview is scaled to fill it) and tiles per row.
TILE = 160
COLUMNS = 8
_CAPTION_HEIGHT = 14


def contact_sheet(
    dataset_dir: str | os.PathLike[str],
    *,
    out: str | os.PathLike[str] | None = None,
    samples: Sequence[Path] | None = None,
) -> Path:
    """Tile the ``image_denoised`` preview (``image`` where there is none) of every sample (or
    of *samples*) with its id into one PNG, each scaled to fill a :data:`TILE`-pixel tile.

    Ids longer than a tile are written on two lines, never truncated.
    """
    root = Path(dataset_dir)
    samples = sample_dirs(root) if samples is None else list(samples)
    if not samples:
        raise DatasetError(
            f"dataset folder {str(root)!r} has no complete samples for a contact sheet"
        )
    tiles = [(sample.name, sample / _sheet_preview(sample)) for sample in samples]
    return tile_sheet(tiles, root / "contact_sheet.png" if out is None else out)


def tile_sheet(tiles: Sequence[tuple[str, Path]], out: str | os.PathLike[str]) -> Path:
    """Tile the PNG images of *tiles* (``(caption, path)``, in order) into one PNG at *out*,
    :data:`COLUMNS` to a row, each scaled to fill a :data:`TILE`-pixel tile over its caption
    (two lines where it is long, never truncated)."""
    from PIL import Image, ImageDraw, ImageFont

    font = ImageFont.load_default()
    cols = min(COLUMNS, len(tiles))
    rows = -(-len(tiles) // cols)
    cell = TILE + 2 * _CAPTION_HEIGHT
    sheet = Image.new("RGB", (cols * TILE, rows * cell), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    for i, (caption, image) in enumerate(tiles):
        with Image.open(image) as img:
            tile = _fit(img.convert("RGB"), Image.Resampling)
        x0, y0 = (i % cols) * TILE, (i // cols) * cell
        sheet.paste(tile, (x0 + (TILE - tile.width) // 2, y0 + (TILE - tile.height) // 2))
        for line_no, line in enumerate(_wrap(caption, draw, font)):
            draw.text(
                (x0 + 2, y0 + TILE + 1 + line_no * _CAPTION_HEIGHT), line, fill=(0, 0, 0), font=font
            )
    path = Path(out)
    with guarded_write(path):
        path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as tmp:
        sheet.save(tmp, format="PNG")
    return path


def _sheet_preview(sample: Path) -> str:
    """The preview a contact sheet shows: the denoised image's, else the raw image's."""
    layers = read_meta(sample).layers
    for name in ("image_denoised", "image"):
        if name in layers and layers[name].preview is not None:
            return str(layers[name].preview)
    raise DatasetError(f"{sample / META_NAME}: layers.image.preview: expected a preview")


def _fit(tile: Any, resampling: Any) -> Any:
    """*tile* scaled to fit :data:`TILE` (enlarged too: pixels stay square blocks)."""
    scale = TILE / max(tile.width, tile.height)
    size = (max(1, round(tile.width * scale)), max(1, round(tile.height * scale)))
    method = resampling.NEAREST if scale > 1 else resampling.LANCZOS
    return tile.resize(size, method)


def _wrap(text: str, draw: Any, font: Any) -> list[str]:
    """*text* in at most two lines that fit a tile, split after a sample id's ``__`` where
    possible (:data:`spectrinsic.scenes.sample_id.SEPARATOR`)."""
    if draw.textlength(text, font=font) <= TILE - 4:
        return [text]
    cut = text.rfind(SEPARATOR, 0, len(text) // 2 + 8)
    cut = cut + len(SEPARATOR) if cut > 0 else len(text) // 2
    return [text[:cut], text[cut:]]
