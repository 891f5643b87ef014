"""OBJ/MTL diffuse colours and ``map_Kd`` textures as reflectance spectra.

An OBJ file's ``mtllib`` lines name MTL files; in each, ``newmtl NAME`` starts a material whose
``Kd R G B`` is its diffuse colour and ``map_Kd FILE`` its diffuse texture. :func:`mtl_colours`
reads them for the mesh reader (:mod:`spectrinsic.scenes.meshes`):

- ``Kd`` is read as linear sRGB (the MTL format states no encoding; renderers treat it as
  linear). A channel outside [0, 1] is clipped, with one line naming the material.
- ``map_Kd`` is an sRGB-encoded image, multiplied by ``Kd`` as the MTL format says (a material
  with a texture and no ``Kd`` takes the texture alone). It wraps with ``repeat``
  (``-clamp on`` gives ``clamp``); its other options (``-o``, ``-s``, ``-bm``...) are refused
  in one line, since they would move the texels.

Every file named (MTL and image) must lie inside the OBJ's folder; an MTL file is at most
:data:`MTL_BYTES_MAX`.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ..errors import SceneError, SpectrinsicWarning
from .image_textures import AssetColour, Wrap, image_texture_from_file

__all__ = ["MTL_BYTES_MAX", "mtl_colours", "mtl_files", "mtl_statements", "file_inside"]

#: Largest MTL file read (bytes).
MTL_BYTES_MAX = 4 << 20


def file_inside(base: Path, name: str, what: str) -> Path:
    """The file *name* (relative to the resolved folder *base*), refused unless it is a file
    inside *base* (no path escapes); *what* names the statement for the message."""
    full = (base / name).resolve()
    if not full.is_relative_to(base) or not full.is_file():
        raise SceneError(f"{what}: {name!r} is not a file inside {base}")
    return full


def mtl_files(obj: Path) -> list[Path]:
    """The MTL files the OBJ's ``mtllib`` lines name (streamed, one line at a time)."""
    base = obj.parent.resolve()
    out = []
    with obj.open("rb") as fh:
        for line in fh:
            if line.lstrip().startswith(b"mtllib"):
                name = line.split(None, 1)[1].decode("utf-8", "replace").strip()
                out.append(file_inside(base, name, str(obj)))
    return out


def _map(words: list[str], where: str) -> tuple[str, Wrap]:
    """The file name and wrap mode of a ``map_Kd`` statement's *words* (after the keyword)."""
    wrap: Wrap = "repeat"
    while len(words) > 1 and words[0].startswith("-"):
        if words[0] == "-clamp" and len(words) > 2:
            wrap = "clamp" if words[1] == "on" else "repeat"
            words = words[2:]
            continue
        raise SceneError(f"{where}: map_Kd option {words[0]!r} is not supported; expected none")
    return " ".join(words), wrap


def _colour(words: list[str], where: str) -> tuple[float, float, float]:
    try:
        rgb = np.array([float(w) for w in words[:3]])
    except ValueError:
        rgb = np.zeros(0)
    if rgb.shape != (3,) or not np.all(np.isfinite(rgb)):
        raise SceneError(f"{where}: Kd {' '.join(words)!r}; expected three numbers")
    if np.any((rgb < 0) | (rgb > 1)):
        warnings.warn(
            f"{where}: Kd {' '.join(words)} outside [0, 1] clipped to [0, 1]",
            SpectrinsicWarning,
            stacklevel=3,
        )
    return tuple(float(c) for c in np.clip(rgb, 0.0, 1.0))  # type: ignore[return-value]


def mtl_statements(mtl: Path) -> Iterator[tuple[int, list[str]]]:
    """``(line number, words)`` of every statement of the MTL file *mtl* (comments and blank
    lines left out), refused above :data:`MTL_BYTES_MAX` before it is read."""
    if mtl.stat().st_size > MTL_BYTES_MAX:
        raise SceneError(f"{mtl}: {mtl.stat().st_size:,} bytes; expected at most {MTL_BYTES_MAX:,}")
    for number, line in enumerate(mtl.read_text("utf-8", "replace").splitlines(), 1):
        words = line.split("#", 1)[0].split()
        if words:
            yield number, words


def _parse(mtl: Path) -> dict[str, tuple[tuple[float, float, float] | None, str, Wrap]]:
    """``{material: (Kd or None, map_Kd file or "", wrap)}`` of one MTL file."""
    out: dict[str, tuple[tuple[float, float, float] | None, str, Wrap]] = {}
    name = ""
    for number, words in mtl_statements(mtl):
        where = f"{mtl.name} line {number}"
        if words[0] == "newmtl" and len(words) > 1:
            name = " ".join(words[1:])
            out[name] = (None, "", "repeat")
        elif words[0] == "Kd" and name:
            out[name] = (_colour(words[1:], f"{where} (material {name!r})"), *out[name][1:])
        elif words[0] == "map_Kd" and name and len(words) > 1:
            out[name] = (out[name][0], *_map(words[1:], where))
    return out


def mtl_colours(path: str | Path) -> dict[str, AssetColour]:
    """``{material name: AssetColour}`` for every material of the ``.obj`` file's MTL files
    with a ``Kd`` or a ``map_Kd`` (module docstring); ``{}`` for other files."""
    path = Path(path)
    if path.suffix.lower() != ".obj":
        return {}
    base = path.parent.resolve()
    out = {}
    for mtl in mtl_files(path):
        for name, (kd, image, wrap) in _parse(mtl).items():
            if image:
                full = file_inside(base, image, f"{mtl.name} (material {name!r})")
                out[name] = AssetColour(
                    image=image_texture_from_file(
                        full, root=base, srgb=True, wrap=wrap, factor=kd or (1.0, 1.0, 1.0)
                    )
                )
            elif kd is not None:
                out[name] = AssetColour(spectrum="rgb:" + ",".join(f"{c:.9g}" for c in kd))
    return out
