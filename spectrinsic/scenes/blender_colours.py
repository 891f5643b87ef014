"""Blender base colours: a Principled BSDF's Base Color as an ``rgb:`` colour or, fed by an
image-texture node, an exact spectral texture (issue 41).

:func:`base_colour` reads an unlinked Base Color as ``rgb:R,G,B`` in linear Rec. 709 (converted
from the file's working colour space, :mod:`~spectrinsic.scenes.blender_working_space`). An
*Image Texture* node linked straight into a Principled BSDF's Base Color is read as an
:class:`~spectrinsic.scenes.image_textures.ImageTexture` (the upsampling, limits and decoding of
that module): the image's colour space says its encoding (``sRGB`` is decoded; ``Linear
Rec.709``, ``Linear`` (Blender 3's name) and ``Non-Color`` are read as linear,
:data:`LINEAR_SPACES`, ``Non-Color`` only in a Linear Rec.709 file; others, ``Linear CIE-XYZ
D65`` among them, are refused; an image's colour does not depend on the working space), the
node's extension its wrap (``REPEAT`` → ``repeat``, ``EXTEND`` → ``clamp``, ``MIRROR`` →
``mirror``; ``CLIP`` is refused) and its interpolation the filter the asset asks for
(``Closest`` → ``nearest``, ``Linear`` → ``bilinear``, ``Cubic``/``Smart`` → ``cubic``; the
band path reads the nearest texel and says so). The node's coordinates must be a UV map: its
Vector input unlinked (the mesh's active render UV map), or linked from a *UV Map* node or a
*Texture Coordinate* node's UV output; its projection must be ``FLAT``. The image is the
file's packed copy or a file inside the ``.blend``'s folder. The node's Color output must feed
the Base Color (its Alpha is refused), through a link and a node that are not muted. Anything
else feeding the Base Color (a mix, a procedural texture) is not read: the material then needs
a spectrum, as before.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError
from .blender_working_space import check_raw_values, rec709_colour
from .image_textures import Filter, ImageTexture, Wrap, image_texture_from_bytes
from .image_textures import image_texture_from_file as _from_file

__all__ = [
    "LINEAR_SPACES",
    "principled_node",
    "base_colour",
    "base_colour_image",
    "corner_uvs",
    "object_texture",
]

#: Image colour spaces read as linear Rec. 709 (``Non-Color``: the working space's values,
#: :func:`~spectrinsic.scenes.blender_working_space.check_raw_values`).
LINEAR_SPACES = ("Linear Rec.709", "Linear", "Non-Color")

_WRAP: dict[str, Wrap] = {"REPEAT": "repeat", "EXTEND": "clamp", "MIRROR": "mirror"}
_FILTER: dict[str, Filter] = {
    "Closest": "nearest",
    "Linear": "bilinear",
    "Cubic": "cubic",
    "Smart": "cubic",
}


def principled_node(mat: Any) -> Any:
    """*mat*'s first Principled BSDF node, or None."""
    tree = getattr(mat, "node_tree", None)
    if tree is None:
        return None
    return next((n for n in tree.nodes if n.type == "BSDF_PRINCIPLED"), None)


def base_colour(mat: Any) -> str | None:
    """``"rgb:R,G,B"`` of *mat*'s Principled Base Color (module docstring); None without the
    node or when a texture (any link) feeds the colour."""
    node = principled_node(mat)
    if node is None or node.inputs["Base Color"].is_linked:
        return None
    rgb = rec709_colour(node.inputs["Base Color"].default_value, f"material {mat.name!r}")
    return "rgb:" + ",".join(f"{c:.9g}" for c in rgb)


def _uv_map(node: Any, where: str) -> str:
    """The UV map the image node reads: ``""`` for the mesh's active render map."""
    vector = node.inputs["Vector"]
    if not vector.is_linked:
        return ""
    link = vector.links[0]
    source = link.from_node
    if source.type == "UVMAP":
        return str(source.uv_map)
    if source.type == "TEX_COORD" and link.from_socket.name == "UV":
        return ""
    raise SceneError(
        f"{where}: image texture coordinates come from a {source.type} node; "
        "expected a UV map (unlinked, a UV Map node or Texture Coordinate UV)"
    )


def _image(node: Any, blend: Path, where: str) -> ImageTexture:
    image = node.image
    if image is None or image.source != "FILE":
        raise SceneError(f"{where}: image texture node holds no image file")
    space = str(image.colorspace_settings.name)
    if space != "sRGB" and space not in LINEAR_SPACES:
        raise SceneError(
            f"{where}: image {image.name!r} in colour space {space!r}; expected sRGB or "
            f"{', '.join(LINEAR_SPACES)}"
        )
    if space == "Non-Color":
        check_raw_values(f"{where}: image {image.name!r}")
    wrap, filt = _WRAP.get(str(node.extension)), _FILTER.get(str(node.interpolation), "bilinear")
    if wrap is None or node.projection != "FLAT":
        raise SceneError(
            f"{where}: image texture with extension {node.extension!r} and projection "
            f"{node.projection!r}; expected REPEAT, EXTEND or MIRROR and FLAT"
        )
    srgb = space == "sRGB"
    if image.packed_file is not None:
        data = bytes(image.packed_file.data)
        source = f"{blend.name}#images/{image.name}"
        return image_texture_from_bytes(data, source=source, srgb=srgb, wrap=wrap, filter=filt)
    if image.library is not None:
        raise SceneError(f"{where}: image {image.name!r} is linked from another .blend")
    name = str(image.filepath)  # "//" starts a path relative to the .blend (Blender's rule)
    path = blend.parent / name[2:] if name.startswith("//") else Path(name)
    return _from_file(path, root=blend.parent, srgb=srgb, wrap=wrap, filter=filt)


def base_colour_image(principled: Any, blend: Path, where: str) -> tuple[ImageTexture, str] | None:
    """The image of the Image Texture node linked into the Principled BSDF node *principled*'s
    Base Color and the UV map it reads (``""``: the active render map), or ``None`` when no
    image node feeds it (module docstring); *blend* is the ``.blend`` file."""
    if principled is None or not principled.inputs["Base Color"].is_linked:
        return None
    link = principled.inputs["Base Color"].links[0]
    node = link.from_node
    if node.type != "TEX_IMAGE":
        return None
    if link.is_muted or node.mute:
        raise SceneError(
            f"{where}: the Image Texture node {node.name!r} or its link to the Base Color is "
            "muted; unmute or remove it"
        )
    if link.from_socket.name != "Color":
        raise SceneError(
            f"{where}: the Image Texture node {node.name!r} feeds the Base Color from its "
            f"{link.from_socket.name} output; expected its Color output"
        )
    return _image(node, blend, where), _uv_map(node, where)


def corner_uvs(mesh: Any, loops: np.ndarray) -> dict[str, np.ndarray]:
    """``{UV map name: (F, 3, 2)}`` texture coordinates of the corners of Blender *mesh*'s
    loop triangles (their ``(F, 3)`` *loops*); the active render map also under ``""``."""
    out = {}
    for layer in mesh.uv_layers:
        data = np.empty(2 * len(mesh.loops), dtype=np.float64)
        layer.data.foreach_get("uv", data)
        out[str(layer.name)] = data.reshape(-1, 2)[loops]
        if layer.active_render:
            out[""] = out[str(layer.name)]
    return out


def object_texture(
    materials: Sequence[Any],
    n_slots: int,
    uvs: Mapping[str, np.ndarray],
    blend: Path,
    where: str,
) -> tuple[Any, ImageTexture, np.ndarray] | None:
    """``(material, image, corner uv)`` of the first of Blender *materials* (those of an
    object's *n_slots* slots that take the file's colour) whose Base Color an image feeds, or
    ``None``; a one-line :class:`SceneError` naming *where* if that material shares the object
    with others or the object lacks its UV map. *blend* is the ``.blend`` file."""
    for mat in materials:
        hit = base_colour_image(principled_node(mat), blend, f"{where}: {mat.name!r}")
        if hit is None:
            continue
        image, uv_name = hit
        if n_slots > 1:
            raise SceneError(
                f"{where}: textured material {mat.name!r} shares the object with other "
                "materials; separate them (Mesh > Separate > By Material)"
            )
        if uv_name not in uvs:
            raise SceneError(f"{where}: no UV map {uv_name or '(active render)'!r} for its image")
        return mat, image, uvs[uv_name]
    return None
