"""Opacity masks and bump or normal maps of a mesh: geometry detail, not colour.

A :class:`MeshMaps` record rides on a :class:`~spectrinsic.scenes.model.Mesh` and is read by
its texture coordinates ``uv`` (``(F, 3, 2)`` per face corner, v = 0 at the image's bottom
row as for colour textures). Its images are :class:`~spectrinsic.scenes.image_textures.ImageTexture`
file records (confined to the scene's folder, bounded in texels, SHA-256 and the file's bytes
kept), decoded *raw*: they are data, so no sRGB transfer function is applied.

* **Opacity** α ∈ [0, 1]: a constant (:attr:`MeshMaps.opacity`) times, where given, an image
  (:attr:`MeshMaps.opacity_image`, its luminance, as Mitsuba's ``eval_1`` reads an RGB
  bitmap). Rendered as Mitsuba's ``mask`` BSDF: at a hit the surface reflects with
  probability α and lets the ray pass unchanged (a *null* event) with probability 1 − α.
* **Normal map** (:attr:`MeshMaps.normal_image`): a tangent-space normal per texel, encoded
  ``(n + 1) / 2``; the shading normal is ``normalize(s n_x + t n_y + n n_z)`` in the mesh's
  shading frame (``s`` along ∂p/∂u). Mitsuba's ``normalmap``.
* **Bump map** (:attr:`MeshMaps.bump_image`, :attr:`MeshMaps.bump_scale`): a height field h
  (the image's luminance); the shading normal is ``normalize(∂p'/∂u × ∂p'/∂v)`` with
  ``∂p'/∂u = ∂p/∂u + n (scale ∂h/∂u − n·∂p/∂u)`` (likewise v). Mitsuba's ``bumpmap``.

The ground truth through masks and under bump maps is in ``scenes/FORMAT.md`` (section "Ground
truth on masks and bump maps").
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from PIL import Image

from .image_textures import (
    Filter,
    ImageTexture,
    Wrap,
    image_from_record,
    image_texture_from_bytes,
    opened_image,
)

__all__ = [
    "MeshMaps",
    "maps_problem",
    "maps_from_record",
    "luminance",
    "alpha_values",
    "opacity_image",
]

_OPTIONAL = {"omit_default": True}
#: Rec. 709 luminance weights, the ones Mitsuba's ``eval_1`` of an RGB bitmap uses.
_LUMINANCE = np.array([0.212671, 0.715160, 0.072169])


def luminance(texels: np.ndarray) -> np.ndarray:
    """``(h, w)`` luminance of ``(h, w, 3)`` linear *texels* (a grey image's value itself)."""
    return np.asarray(texels, np.float64) @ _LUMINANCE


@dataclass(frozen=True, eq=False)
class MeshMaps:
    """A mesh's opacity and bump or normal map (module docstring).

    Attributes
    ----------
    uv
        ``(F, 3, 2)`` texture coordinates of each face corner.
    opacity
        Constant opacity in [0, 1] (1: opaque).
    opacity_image
        Raw image whose luminance multiplies :attr:`opacity`, or ``None``.
    normal_image
        Raw tangent-space normal map, or ``None``.
    bump_image
        Raw height map, or ``None`` (not together with a normal map).
    bump_scale
        Height per unit of the bump image's value, in scene units per unit of texture
        coordinate gradient (Mitsuba's ``scale``).
    normal_scale
        Scale on a normal map's tangent components (glTF ``normalTexture.scale``): the normal
        is ``normalize((2 t − 1) ⊙ (s, s, 1))``.
    """

    uv: np.ndarray
    opacity: float = field(default=1.0, metadata=_OPTIONAL)
    opacity_image: ImageTexture | None = field(default=None, metadata=_OPTIONAL)
    normal_image: ImageTexture | None = field(default=None, metadata=_OPTIONAL)
    bump_image: ImageTexture | None = field(default=None, metadata=_OPTIONAL)
    bump_scale: float = field(default=1.0, metadata=_OPTIONAL)
    normal_scale: float = field(default=1.0, metadata=_OPTIONAL)

    @property
    def masked(self) -> bool:
        """Whether the mesh lets light through anywhere."""
        return self.opacity < 1.0 or self.opacity_image is not None

    @property
    def perturbed(self) -> bool:
        """Whether a bump or normal map perturbs the shading normal."""
        return self.normal_image is not None or self.bump_image is not None

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, MeshMaps):
            return NotImplemented
        return (
            np.array_equal(self.uv, other.uv)
            and (self.opacity, self.bump_scale, self.normal_scale)
            == (other.opacity, other.bump_scale, other.normal_scale)
            and self.opacity_image == other.opacity_image
            and self.normal_image == other.normal_image
            and self.bump_image == other.bump_image
        )

    __hash__ = None  # type: ignore[assignment]


def maps_problem(maps: MeshMaps, n_faces: int) -> str | None:
    """What is wrong with *maps* on a mesh of *n_faces* faces, or ``None``."""
    uv = np.asarray(maps.uv)
    if uv.shape != (n_faces, 3, 2) or not np.all(np.isfinite(uv)):
        return f"uv of shape {uv.shape}; expected ({n_faces}, 3, 2) finite texture coordinates"
    if not (0.0 <= maps.opacity <= 1.0):
        return f"opacity {maps.opacity}; expected a number in [0, 1]"
    if maps.normal_image is not None and maps.bump_image is not None:
        return "both a normal map and a bump map; expected at most one"
    if not (math.isfinite(maps.bump_scale) and math.isfinite(maps.normal_scale)):
        return f"bump scale {maps.bump_scale}, normal scale {maps.normal_scale}; expected finite numbers"
    if not (maps.masked or maps.perturbed):
        return "neither an opacity below 1 nor a bump or normal map; leave the maps out"
    return None


def maps_from_record(record: Mapping[str, Any]) -> MeshMaps:
    """The :class:`MeshMaps` of its ``scene_to_dict`` record (images decoded again from their
    bytes, checked against their SHA-256)."""

    def image(key: str) -> ImageTexture | None:
        value = record.get(key)
        return image_from_record(value) if value else None

    return MeshMaps(
        uv=np.asarray(record["uv"], np.float64).reshape(-1, 3, 2),
        opacity=float(record.get("opacity", 1.0)),
        opacity_image=image("opacity_image"),
        normal_image=image("normal_image"),
        bump_image=image("bump_image"),
        bump_scale=float(record.get("bump_scale", 1.0)),
        normal_scale=float(record.get("normal_scale", 1.0)),
    )


def alpha_values(data: bytes, what: str, *, luminance_without_alpha: bool) -> np.ndarray:
    """``(h, w)`` 8-bit alpha of the image file *data* (row 0 the image's top); an image
    without alpha gives 255 everywhere, or with *luminance_without_alpha* its 8-bit grey
    (PIL's ``L``). One line names *what* for an unreadable or too large image."""
    with opened_image(data, what) as img:
        if img.mode in ("LA", "RGBA") or (img.mode == "P" and "transparency" in img.info):
            return np.asarray(img.convert("RGBA").getchannel("A"), np.uint8)
        if luminance_without_alpha:
            return np.asarray(img.convert("L"), np.uint8)
        return np.full(img.size[::-1], 255, np.uint8)


def opacity_image(values: np.ndarray, source: str, wrap: Wrap, filter: Filter) -> ImageTexture:  # noqa: A002
    """The raw opacity image of ``(h, w)`` 8-bit *values* (row 0 the top), kept as the bytes
    of a one-channel PNG written here, named *source*."""
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(values, np.uint8), "L").save(buffer, format="PNG")
    return image_texture_from_bytes(
        buffer.getvalue(), source=source, srgb=False, wrap=wrap, filter=filter
    )
