"""Mitsuba XML ``bitmap`` textures as exact image textures.

A ``diffuse`` BSDF (bare or in a ``twosided``) whose ``reflectance`` is a
``<texture type="bitmap">`` becomes an :class:`~spectrinsic.scenes.image_textures.ImageTexture`
over the 8 RGB-cube corner materials (:func:`~spectrinsic.scenes.textures.make_image_texture`),
so every texel's reflectance is the exact upsampling of its linear RGB (issue 41).

The bitmap's parameters read: ``filename`` (confined to the scene's folder, 8-bit images),
``raw`` (Mitsuba's default ``false`` decodes an 8-bit image's sRGB transfer function, as
Mitsuba does; ``true`` takes the values as linear), ``wrap_mode`` and ``filter_type`` (the same
names as ours; ``bilinear``, Mitsuba's default, is rendered with the nearest texel, said in one
line). ``to_uv`` other than the identity has no counterpart and is refused; ``accel`` only
speeds up Mitsuba's lookups and changes nothing.

Texture coordinates (:func:`~spectrinsic.scenes.mitsuba_shapes.textured_triangles`): Mitsuba's bitmap
puts the image's *top* row at v = 0, ours the bottom row (OpenGL), so a Mitsuba ``(u, v)``
is ours ``(u, 1 − v)``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import SceneError
from .image_textures import FILTERS, WRAP_MODES, ImageTexture, image_texture_from_file
from .mitsuba_bsdfs import WRAPPERS, inner_bsdf
from .mitsuba_files import confined_file
from .mitsuba_tree import XmlNode

__all__ = ["diffuse_bitmap", "read_bitmap"]

_PARAMS = {"filename", "raw", "wrap_mode", "filter_type", "to_uv", "accel"}


def diffuse_bitmap(bsdf: XmlNode, what: str, base: Path) -> ImageTexture | None:
    """The image of *bsdf* when it is a ``diffuse`` (bare, two-sided or wrapped) whose ``reflectance``
    is a ``bitmap``; ``None`` for any other BSDF (read by
    :func:`~spectrinsic.scenes.mitsuba_bsdfs.material_of`).

    Raises
    ------
    SceneError
        One line naming the bitmap: an unknown parameter, a ``to_uv``, a wrap mode or filter
        Mitsuba does not have, or the image file (outside the folder, unreadable, too large).
    """
    node = bsdf
    while node.plugin == "twosided" or node.plugin in WRAPPERS:  # wrappers: mitsuba_maps
        node = inner_bsdf(node, what)
    texture = node.props.get("reflectance")
    if node.plugin != "diffuse" or not isinstance(texture, XmlNode):
        return None
    if texture.plugin != "bitmap" or set(node.props) != {"reflectance"} or node.children:
        return None  # material_of refuses it in its own words
    return read_bitmap(texture, f"{what} {texture.label()}", base)


def read_bitmap(texture: XmlNode, where: str, base: Path) -> ImageTexture:
    """The image of ``bitmap`` *texture* (module docstring: its parameters as Mitsuba reads
    them, ``raw`` included), named *where* in messages.

    Raises
    ------
    SceneError
        One line naming the bitmap: not a bitmap, an unknown parameter, a ``to_uv``, a wrap
        mode or filter Mitsuba does not have, or the image file (outside the folder,
        unreadable, too large).
    """
    if texture.kind != "texture" or texture.plugin != "bitmap":
        raise SceneError(f"{where}: expected a <texture type='bitmap'>")
    extra = set(texture.props) - _PARAMS
    if extra:
        raise SceneError(f"{where}: unsupported parameter {sorted(extra)[0]!r}")
    to_uv = texture.props.get("to_uv")
    if to_uv is not None and not np.allclose(np.asarray(to_uv, float), np.eye(4)):
        raise SceneError(f"{where}: to_uv is not read; expected none (transform the uv instead)")
    wrap = texture.props.get("wrap_mode", "repeat")
    filt = texture.props.get("filter_type", "bilinear")
    if wrap not in WRAP_MODES or filt not in FILTERS[:2]:
        raise SceneError(
            f"{where}: wrap_mode {wrap!r} and filter_type {filt!r}; expected one of "
            f"{', '.join(WRAP_MODES)} and nearest or bilinear"
        )
    rel = texture.props.get("filename")
    path = confined_file(rel if isinstance(rel, str) else "", base, where)
    raw = texture.props.get("raw", False)
    if not isinstance(raw, bool):
        raise SceneError(f"{where}: raw {raw!r}; expected true or false")
    return image_texture_from_file(
        path,
        root=base,
        srgb=not raw,
        wrap=wrap,  # type: ignore[arg-type]
        filter=filt,  # type: ignore[arg-type]
    )
