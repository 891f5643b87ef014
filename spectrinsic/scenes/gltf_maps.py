"""glTF opacity (``alphaMode``) and normal textures as a mesh's
:class:`~spectrinsic.scenes.surface_maps.MeshMaps`.

Per named material (glTF 2.0 spec, section 3.9):

* ``alphaMode`` ``MASK``: the alpha (``baseColorFactor[3]`` times the ``baseColorTexture``'s
  alpha channel, linear) against ``alphaCutoff`` (default 0.5): opacity 1 at or above it, 0
  below, a cut-out; ``BLEND``: the alpha itself is the opacity (partial coverage); ``OPAQUE``
  (the default): no mask. The alpha image becomes a single-channel 8-bit PNG written here
  (recorded by its bytes and SHA-256 like any image), the thresholded one for ``MASK``.
* ``normalTexture``: a raw tangent-space normal map with its ``scale`` (default 1) on the
  tangent components. The tangent frame is Mitsuba's, ``s`` along ∂p/∂u and ``t = n × s``:
  glTF's +Y (up in the image) on UV layouts that are not mirrored; on faces whose uv are
  mirrored (glTF's bitangent sign −1) the green channel is read the same way, said in one line.

Textures use ``TEXCOORD_0`` and the sampler's wrap mode and filter, as base colours do.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError, SpectrinsicWarning
from .gltf_colours import (
    GLTF_SUFFIXES,
    gltf_document,
    gltf_image,
    gltf_image_bytes,
    named_materials,
)
from .image_textures import ImageTexture
from .surface_maps import MeshMaps, alpha_values, opacity_image

__all__ = ["gltf_maps", "warn_mirrored_uv"]

_MODES = ("OPAQUE", "MASK", "BLEND")


def _opacity(
    path: Path, doc: dict[str, Any], binary: bytes, material: dict[str, Any]
) -> MeshMaps | None:
    """The opacity part of *material*'s maps (module docstring), or ``None`` (opaque)."""
    name = material["name"]
    mode = material.get("alphaMode", "OPAQUE")
    if mode not in _MODES:
        raise SceneError(f"{path}: material {name!r} alphaMode {mode!r}; expected one of {_MODES}")
    if mode == "OPAQUE":
        return None
    pbr = material.get("pbrMetallicRoughness") or {}
    factor = pbr.get("baseColorFactor", [1.0, 1.0, 1.0, 1.0])
    alpha = float(factor[3]) if isinstance(factor, list) and len(factor) == 4 else 1.0
    cutoff = float(material.get("alphaCutoff", 0.5))
    empty = np.zeros((0, 3, 2))
    if "baseColorTexture" not in pbr:
        opacity = float(alpha >= cutoff) if mode == "MASK" else alpha
        return None if opacity >= 1.0 else MeshMaps(empty, opacity=opacity)
    data, index, wrap, filt = gltf_image_bytes(path, doc, binary, pbr["baseColorTexture"])
    where = f"{path}: material {name!r} baseColorTexture"
    values = alpha_values(data, where, luminance_without_alpha=False)
    if mode == "MASK":  # the cut-out's test on the 8-bit alpha times the factor
        values = np.where(alpha * values / 255.0 >= cutoff, 255, 0).astype(np.uint8)
        alpha = 1.0
    if alpha >= 1.0 and values.min() == 255:
        return None
    source = f"{path.name}#images/{index}/alpha" + ("-mask" if mode == "MASK" else "")
    image = opacity_image(values, source, wrap, filt)
    return MeshMaps(empty, opacity=alpha, opacity_image=image)


def _normal(
    path: Path, doc: dict[str, Any], binary: bytes, material: dict[str, Any]
) -> tuple[ImageTexture, float] | None:
    ref = material.get("normalTexture")
    if ref is None:
        return None
    image = gltf_image(path, doc, binary, ref, [1, 1, 1], key="normalTexture", srgb=False)
    return image, float(ref.get("scale", 1.0))


def gltf_maps(path: str | Path) -> dict[str, MeshMaps]:
    """``{material name: MeshMaps}`` (without uv: the mesh sets its own) for every named
    material of the ``.gltf``/``.glb`` file at *path* with a mask or a normal texture (module
    docstring); ``{}`` for other files."""
    path = Path(path)
    if path.suffix.lower() not in GLTF_SUFFIXES:
        return {}
    doc, binary = gltf_document(path)
    out = {}
    for name, material in named_materials(doc):
        maps = _opacity(path, doc, binary, material)
        normal = _normal(path, doc, binary, material)
        if normal is not None:
            maps = maps or MeshMaps(np.zeros((0, 3, 2)))
            maps = replace(maps, normal_image=normal[0], normal_scale=normal[1])
        if maps is not None:
            out[name] = maps
    return out


def warn_mirrored_uv(maps: MeshMaps, what: str) -> None:
    """Say in one line how many faces of a normal-mapped mesh have mirrored uv (wound against
    the face, which glTF meshes wind outwards), whose green channel Mitsuba's frame does not
    flip."""
    if maps.normal_image is None:
        return
    uv = np.asarray(maps.uv, float)
    du1, du2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    mirrored = int(np.count_nonzero(du1[:, 0] * du2[:, 1] - du2[:, 0] * du1[:, 1] < 0))
    if mirrored:
        warnings.warn(
            f"{what}: {mirrored} faces have mirrored uv; their normal map's green channel is "
            "read along t = n × s (Mitsuba's frame), not flipped",
            SpectrinsicWarning,
            stacklevel=2,
        )
