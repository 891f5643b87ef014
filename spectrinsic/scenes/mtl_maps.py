"""OBJ/MTL dissolve (``d``, ``Tr``, ``map_d``) as a mesh's opacity mask.

Per ``newmtl`` material of the OBJ's MTL files (the same files :mod:`~spectrinsic.scenes.mtl_colours`
reads): ``d`` is the opacity in [0, 1] (1 opaque; ``Tr`` is 1 − d), and ``map_d FILE`` an image
whose alpha channel (or, without one, its grey level: the MTL scalar texture) multiplies it,
read raw, by the mesh's ``vt``, wrap ``repeat`` (``-clamp on``: ``clamp``), nearest texel
(MTL names no filter). Rendered as an opacity mask with the ground truth of
``scenes/FORMAT.md`` ("Ground truth on masks and bump maps"). ``bump``/``map_bump`` are not
read (their ``-bm`` scale has no one meaning across renderers), said in one line.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..errors import SceneError, SpectrinsicWarning
from .image_textures import Wrap
from .mtl_colours import file_inside, mtl_files, mtl_statements
from .surface_maps import MeshMaps, alpha_values, opacity_image

__all__ = ["mtl_maps"]


def _number(words: list[str], where: str) -> float:
    try:
        value = float(words[0])
    except (ValueError, IndexError):
        value = float("nan")
    if not 0.0 <= value <= 1.0:
        raise SceneError(f"{where}: {' '.join(words)!r}; expected a number in [0, 1]")
    return value


def _image(words: list[str], where: str) -> tuple[str, Wrap]:
    wrap: Wrap = "repeat"
    if len(words) > 2 and words[0] == "-clamp":
        wrap, words = ("clamp" if words[1] == "on" else "repeat"), words[2:]
    if not words or words[0].startswith("-"):
        raise SceneError(f"{where}: map_d {' '.join(words)!r}; expected a file (and -clamp)")
    return " ".join(words), wrap


def _parse(mtl: Path) -> dict[str, tuple[float, str, Wrap]]:
    """``{material: (d, map_d file or "", wrap)}`` of one MTL file's materials with either."""
    out: dict[str, tuple[float, str, Wrap]] = {}
    name, bumps = "", []
    for number, words in mtl_statements(mtl):
        if not name and words[0] != "newmtl":
            continue
        where = f"{mtl.name} line {number} (material {name!r})"
        d, image, wrap = out.get(name, (1.0, "", "repeat"))
        if words[0] == "newmtl" and len(words) > 1:
            name = " ".join(words[1:])
        elif words[0] == "d":
            out[name] = (_number(words[1:], where), image, wrap)
        elif words[0] == "Tr":
            out[name] = (1.0 - _number(words[1:], where), image, wrap)
        elif words[0] == "map_d":
            out[name] = (d, *_image(words[1:], where))
        elif words[0] in ("bump", "map_bump"):
            bumps.append(name)
    if bumps:
        warnings.warn(
            f"{mtl.name}: bump maps of {len(bumps)} materials (first {bumps[0]!r}) are not read",
            SpectrinsicWarning,
            stacklevel=3,
        )
    return out


def mtl_maps(path: str | Path) -> dict[str, MeshMaps]:
    """``{material name: MeshMaps}`` (without uv: the mesh sets its own) for every material of
    the ``.obj`` file's MTL files with ``d`` < 1 or a ``map_d`` (module docstring); ``{}`` for
    other files."""
    path = Path(path)
    if path.suffix.lower() != ".obj":
        return {}
    base = path.parent.resolve()
    out = {}
    for mtl in mtl_files(path):
        for name, (d, file, wrap) in _parse(mtl).items():
            where = f"{mtl.name} (material {name!r})"
            image = None
            if file:
                full = file_inside(base, file, f"{where}: map_d")
                values = alpha_values(full.read_bytes(), where, luminance_without_alpha=True)
                source = full.relative_to(base).as_posix() + "#opacity"
                image = (
                    None if values.min() == 255 else opacity_image(values, source, wrap, "nearest")
                )
            if d < 1.0 or image is not None:
                out[name] = MeshMaps(np.zeros((0, 3, 2)), opacity=d, opacity_image=image)
    return out
