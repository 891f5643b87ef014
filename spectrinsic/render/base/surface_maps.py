"""Opacity masks and bump or normal maps in the renderer: Mitsuba's wrapper BSDFs, and the
perturbed shading normal the band path's normal layer holds.

A mesh's :class:`~spectrinsic.scenes.surface_maps.MeshMaps` become Mitsuba BSDF wrappers around
its material's two-sided BSDF (:func:`wrap_bsdf`): ``mask(normalmap | bumpmap(twosided(…)))``.
The images are raw ``bitmap`` textures with the asset's wrap mode and filter (nearest, or
bilinear for anything else: a bump map needs a gradient), so Mitsuba's own BSDF samples the
cut-outs and shades with the perturbed frame, in every variant and pass alike.

The band path's normal layer must hold that perturbed normal, which Mitsuba does not expose
from a BSDF; :func:`perturbed_normal` recomputes it with the *same* texture objects, found in
the loaded scene (:func:`map_textures`), by the formulas of Mitsuba 3's ``normalmap.cpp`` and
``bumpmap.cpp`` (checked against the BSDFs' own evaluation in
``tests/test_surface_maps_render.py``):

* normal map: ``n' = normalize(frame.to_world(2 t − 1))`` with ``frame`` the hit's shading
  frame and ``t`` the texel;
* bump map: ``g = scale ∇h``, ``∂p'/∂u = ∂p/∂u + n (g_u − n·∂p/∂u)`` (likewise v),
  ``n' = normalize(∂p'/∂u × ∂p'/∂v)``, flipped to the side of the geometric normal.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ...errors import RenderError
from ...scenes.image_textures import ImageTexture
from ...scenes.model import Scene
from ...scenes.surface_maps import MeshMaps, luminance
from .plugins import raw_bitmap

__all__ = [
    "MapKind",
    "wrap_bsdf",
    "map_scales",
    "map_textures",
    "perturbed_normal",
]

#: Which perturbation a mesh's map applies: ``"normal"`` or ``"bump"``.
MapKind = str


def _bitmap(mi: Any, image: ImageTexture, values: np.ndarray) -> dict[str, Any]:
    """:func:`raw_bitmap` of *values* with *image*'s wrap mode and filter (module docstring)."""
    filter_type = "nearest" if image.filter == "nearest" else "bilinear"
    return raw_bitmap(mi, values, filter_type, image.wrap)


def wrap_bsdf(mi: Any, maps: MeshMaps, bsdf: dict[str, Any]) -> dict[str, Any]:
    """*bsdf* inside Mitsuba's ``normalmap`` or ``bumpmap`` and ``mask`` wrappers of *maps*
    (module docstring); *bsdf* itself where *maps* change nothing."""
    out = bsdf
    if maps.normal_image is not None:
        scale = np.array([maps.normal_scale, maps.normal_scale, 1.0])
        texels = (np.asarray(maps.normal_image.texels, np.float64) * 2.0 - 1.0) * scale
        texels = (texels + 1.0) / 2.0  # Mitsuba normalises 2 t − 1 itself
        out = {
            "type": "normalmap",
            "normalmap": _bitmap(mi, maps.normal_image, texels),
            "bsdf": out,
        }
    elif maps.bump_image is not None:
        height = luminance(maps.bump_image.texels)[..., None]
        out = {
            "type": "bumpmap",
            "height": _bitmap(mi, maps.bump_image, height),
            "scale": float(maps.bump_scale),
            "bsdf": out,
        }
    if maps.opacity_image is not None:
        alpha = maps.opacity * luminance(maps.opacity_image.texels)[..., None]
        out = {"type": "mask", "opacity": _bitmap(mi, maps.opacity_image, alpha), "bsdf": out}
    elif maps.opacity < 1.0:
        out = {"type": "mask", "opacity": float(maps.opacity), "bsdf": out}
    return out


def _children(mi: Any, obj: Any) -> dict[str, Any]:
    """An object's named children, collected through Mitsuba's ``traverse``."""
    found: dict[str, Any] = {}

    class Callback(mi.TraversalCallback):  # type: ignore[misc, name-defined]
        def put(self, name: str, value: Any, *rest: Any) -> None:
            found[name] = value

    obj.traverse(Callback())
    return found


def _map_texture(mi: Any, bsdf: Any) -> tuple[MapKind, Any]:
    """The perturbation and texture of a BSDF built by :func:`wrap_bsdf` (inside a mask)."""
    if bsdf.class_name() == "MaskBSDF":
        bsdf = _children(mi, bsdf)["nested_bsdf"]
    children = _children(mi, bsdf)
    if bsdf.class_name() == "NormalMap":
        return "normal", children["normalmap"]
    if bsdf.class_name() == "BumpMap":
        return "bump", children["nested_texture"]
    raise RenderError(f"BSDF {bsdf.class_name()} carries no bump or normal map")


def map_scales(scene: Scene, surfaces: Sequence[Any]) -> dict[str, float]:
    """``{shape key: bump scale}`` of the *surfaces* (:class:`~spectrinsic.render.base.translate.Surface`
    records: ``key``, ``mesh``) whose mesh has a bump or normal map."""
    out = {}
    for s in surfaces:
        maps = scene.meshes[s.mesh].maps if s.mesh >= 0 else None
        if maps is not None and maps.perturbed:
            out[s.key] = float(maps.bump_scale)
    return out


def map_textures(
    mi: Any, loaded: Any, scales: dict[str, float]
) -> tuple[dict[str, int], list[tuple[MapKind, Any, float]]]:
    """``{shape id: map index}`` and the maps ``(kind, texture, bump scale)`` of the shapes of
    the loaded scene named in *scales* (shape id -> bump scale of its mesh)."""
    lut: dict[str, int] = {}
    maps: list[tuple[MapKind, Any, float]] = []
    for shape in loaded.shapes():
        if shape.id() in scales:
            kind, texture = _map_texture(mi, shape.bsdf())
            lut[shape.id()] = len(maps)
            maps.append((kind, texture, scales[shape.id()]))
    return lut, maps


def perturbed_normal(mi: Any, dr: Any, kind: MapKind, texture: Any, scale: float, si: Any) -> Any:
    """World shading normal of the hits *si* under a *kind* map of *texture* (module
    docstring; Dr.Jit, traced in the kernel)."""
    frame = si.sh_frame
    if kind == "normal":
        return dr.normalize(frame.to_world(dr.fma(texture.eval_3(si), 2.0, -1.0)))
    grad = texture.eval_1_grad(si) * scale
    n = frame.n
    dp_du = dr.fma(n, grad.x - dr.dot(n, si.dp_du), si.dp_du)
    dp_dv = dr.fma(n, grad.y - dr.dot(n, si.dp_dv), si.dp_dv)
    out = dr.normalize(dr.cross(dp_du, dp_dv))
    return dr.select(dr.dot(si.n, out) < 0.0, -out, out)
