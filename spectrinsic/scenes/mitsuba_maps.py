"""Mitsuba XML ``mask``, ``bumpmap`` and ``normalmap`` wrappers as a mesh's
:class:`~spectrinsic.scenes.surface_maps.MeshMaps`.

Read exactly, in any nesting with ``twosided`` (the renderer always nests them
``mask(normalmap | bumpmap(twosided(…)))``, which Mitsuba renders alike for a two-sided
material):

* ``mask``: ``opacity``, a number in [0, 1] (Mitsuba's default 0.5) or a ``bitmap`` (its
  luminance, as Mitsuba's ``eval_1`` reads it);
* ``bumpmap``: one ``bitmap`` texture, named or not (the height), and ``scale`` (default 1);
* ``normalmap``: the ``bitmap`` named ``normalmap``.

Bitmaps are read as Mitsuba reads them (:func:`~spectrinsic.scenes.mitsuba_bitmaps.read_bitmap`:
confined to the scene's folder, bounded, hashed; ``raw`` as the file says: a height map of an
old-version file is read raw, :mod:`~spectrinsic.scenes.mitsuba_tree`), by the shape's texture
coordinates. One line refuses anything else: another texture type, an unknown parameter, two
masks, both a bump and a normal map.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from ..errors import SceneError
from .image_textures import ImageTexture
from .mitsuba_bitmaps import read_bitmap
from .mitsuba_bsdfs import WRAPPERS, inner_bsdf
from .mitsuba_tree import XmlNode
from .surface_maps import MeshMaps

__all__ = ["shape_maps"]

_PARAMS = {"mask": {"opacity"}, "bumpmap": {"scale"}, "normalmap": {"normalmap"}}


def _textures(node: XmlNode) -> list[tuple[str, XmlNode]]:
    """The textures *node* holds, named (``props``) or not (``children``)."""
    named = [(k, v) for k, v in node.props.items() if isinstance(v, XmlNode)]
    return named + [("", c) for c in node.children if c.kind == "texture"]


def _one_texture(node: XmlNode, where: str, base: Path) -> ImageTexture:
    textures = _textures(node)
    if len(textures) != 1:
        raise SceneError(f"{where}: expected one <texture type='bitmap'>, found {len(textures)}")
    key, texture = textures[0]
    return read_bitmap(texture, f"{where} {texture.label()}", base)


def _opacity(node: XmlNode, where: str, base: Path) -> tuple[float, ImageTexture | None]:
    value = node.props.get("opacity", 0.5)
    if isinstance(value, XmlNode):
        return 1.0, read_bitmap(value, f"{where} opacity {value.label()}", base)
    opacity = node.number("opacity", 0.5)
    if not 0.0 <= opacity <= 1.0:
        raise SceneError(f"{where}: opacity {opacity}; expected a number in [0, 1]")
    return opacity, None


def _wrapper(node: XmlNode, where: str, base: Path, maps: MeshMaps) -> MeshMaps:
    """*maps* with wrapper *node*'s part added."""
    extra = {k for k in node.props if not isinstance(node.props[k], XmlNode)}
    extra -= _PARAMS[node.plugin]
    if extra:
        raise SceneError(f"{where}: unsupported parameter {sorted(extra)[0]!r}")
    if node.plugin == "mask":
        if maps.masked:
            raise SceneError(f"{where}: a mask inside a mask; expected one")
        opacity, image = _opacity(node, where, base)
        return replace(maps, opacity=opacity, opacity_image=image)
    if maps.perturbed:
        raise SceneError(f"{where}: a second bump or normal map; expected at most one")
    if node.plugin == "normalmap":
        texture = node.props.get("normalmap")
        if not isinstance(texture, XmlNode) or len(_textures(node)) != 1:
            raise SceneError(f"{where}: expected one <texture type='bitmap' name='normalmap'>")
        return replace(maps, normal_image=read_bitmap(texture, f"{where} {texture.label()}", base))
    image = _one_texture(node, where, base)
    return replace(maps, bump_image=image, bump_scale=node.number("scale", 1.0))


def shape_maps(bsdf: XmlNode, what: str, base: Path) -> MeshMaps | None:
    """The maps of the wrappers around BSDF *bsdf* of a shape named *what* (module docstring),
    with no texture coordinates yet (``uv`` of shape ``(0, 3, 2)``: the caller sets the
    shape's); ``None`` without wrappers.

    Raises
    ------
    SceneError
        One line naming the wrapper (module docstring).
    """
    maps = MeshMaps(np.zeros((0, 3, 2)))
    node = bsdf
    while node.plugin == "twosided" or node.plugin in WRAPPERS:
        if node.plugin in WRAPPERS:
            maps = _wrapper(node, f"{what} {node.label()}", base, maps)
        node = inner_bsdf(node, what)
    return maps if maps.masked or maps.perturbed else None
