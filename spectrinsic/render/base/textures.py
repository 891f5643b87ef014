"""Spectral textures in the renderer: the texel tables the band path gathers from, and the
Mitsuba BSDF of a textured surface for the passes that evaluate spectra per wavelength.

A textured mesh (:class:`~spectrinsic.scenes.textures.Texture`) has per-texel convex weights
``w_ij,b`` over basis materials b. A band albedo is linear in the reflectance, so texel
``(i, j)``'s band albedo is exactly ``Σ_b w_ij,b ρ_{b,k}`` (the basis materials' rows of the
band table): the band path multiplies by it at every vertex on the surface, the nearest texel
of the hit's ``(u, v)`` (:func:`~spectrinsic.scenes.textures.texel_index`). Its first-hit maps
split the coverage of a textured hit over the basis materials by the same weights, so
``Σ_m coverage_m ρ_m`` (the reflectance layer, the white-surface radiance) is the
box-filtered texel spectrum of every pixel.

For Mitsuba's own BSDFs (the spectral reference), :func:`textured_bsdf` nests ``blendbsdf``
with nearest-filtered raw ``bitmap`` weights: ``(1 − t_b) f_b + t_b f_{>b}`` with
``t_b = Σ_{c>b} w_c / Σ_{c≥b} w_c`` reproduces ``Σ_b w_b f_b`` at each texel.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...scenes.model import Scene
from ...scenes.textures import Texture
from .plugins import raw_bitmap

__all__ = [
    "TextureTables",
    "texture_tables",
    "shape_slots",
    "textured_bsdf",
    "texel_of",
    "shape_id_table",
    "texture_lookups",
]


@dataclass(frozen=True, eq=False)
class TextureTables:
    """Every textured mesh's texels, concatenated (slot s covers rows ``offsets[s]`` on).

    Attributes
    ----------
    albedo
        ``(N, K)`` band albedo of each texel.
    columns
        ``(G,)`` material index of each coverage column (every basis material once).
    weights
        ``(N, G)`` each texel's weight on each coverage column.
    offsets, heights, widths
        ``(T,)`` first row, texture height and width of each textured mesh (slot).
    mesh_slots
        ``{mesh index: slot}``.
    """

    albedo: np.ndarray
    columns: np.ndarray
    weights: np.ndarray
    offsets: np.ndarray
    heights: np.ndarray
    widths: np.ndarray
    mesh_slots: dict[int, int]


def texture_tables(scene: Scene, band_albedo: np.ndarray) -> TextureTables | None:
    """The texel tables of *scene* for ``(M, K)`` *band_albedo* per material; ``None`` when no
    mesh is textured."""
    textured = [(i, m.texture) for i, m in enumerate(scene.meshes) if m.texture is not None]
    if not textured:
        return None
    columns = np.array(sorted({b for _, t in textured for b in t.basis}), np.int64)
    col_of = {int(m): g for g, m in enumerate(columns)}
    rho = np.asarray(band_albedo, float)
    albedo, weights, sizes = [], [], []
    for _, tex in textured:
        w = tex.weights.reshape(-1, len(tex.basis))
        albedo.append(w @ rho[list(tex.basis)])
        cols = np.zeros((len(w), len(columns)))
        cols[:, [col_of[b] for b in tex.basis]] = w
        weights.append(cols)
        sizes.append(tex.weights.shape[:2])
    counts = [h * w for h, w in sizes]
    return TextureTables(
        albedo=np.concatenate(albedo),
        columns=columns,
        weights=np.concatenate(weights),
        offsets=np.cumsum([0] + counts[:-1]).astype(np.int64),
        heights=np.array([h for h, _ in sizes], np.int64),
        widths=np.array([w for _, w in sizes], np.int64),
        mesh_slots={i: s for s, (i, _) in enumerate(textured)},
    )


def shape_slots(tables: TextureTables | None, surfaces: Sequence[Any]) -> dict[str, int]:
    """``{shape key: texture slot}`` of the textured ones among *surfaces*
    (:class:`~spectrinsic.render.base.translate.Surface` records: ``key``, ``mesh``)."""
    if tables is None:
        return {}
    return {s.key: tables.mesh_slots[s.mesh] for s in surfaces if s.mesh in tables.mesh_slots}


def textured_bsdf(mi: Any, texture: Texture, reflectances: Sequence[Mapping]) -> dict[str, Any]:
    """Two-sided nested ``blendbsdf`` of Lambertian basis BSDFs with *reflectances* (one
    Mitsuba spectrum dict per basis material), weighted per texel (module docstring)."""
    w = np.asarray(texture.weights, float)
    tail = np.cumsum(w[..., ::-1], axis=-1)[..., ::-1]  # Σ_{c≥b} w_c
    bsdf: dict[str, Any] = {"type": "diffuse", "reflectance": dict(reflectances[-1])}
    for b in range(len(reflectances) - 2, -1, -1):
        t = np.divide(
            tail[..., b + 1], tail[..., b], out=np.zeros(w.shape[:2]), where=tail[..., b] > 0
        )
        bsdf = {
            "type": "blendbsdf",
            "weight": raw_bitmap(mi, t[..., None], "nearest", "clamp"),
            "bsdf_0": {"type": "diffuse", "reflectance": dict(reflectances[b])},
            "bsdf_1": bsdf,
        }
    return {"type": "twosided", "bsdf": bsdf}


def texel_of(mi: Any, dr: Any, it: Any, si: Any) -> tuple[Any, Any]:
    """Global texel row of each lane's hit and whether the hit is textured (Dr.Jit): the slot of
    the hit shape, then the nearest texel of ``si.uv`` clamped to the texture."""
    valid = si.is_valid()
    slot = dr.gather(mi.UInt32, it.slot_lut, dr.reinterpret_array(mi.UInt32, si.shape), valid)
    width = dr.gather(mi.Int32, it.tex_widths, slot, valid)
    height = dr.gather(mi.Int32, it.tex_heights, slot, valid)
    textured = valid & (width > 0)
    col = dr.clip(mi.Int32(dr.floor(si.uv.x * mi.Float(width))), 0, width - 1)
    row = dr.clip(mi.Int32(dr.floor(si.uv.y * mi.Float(height))), 0, height - 1)
    offset = dr.gather(mi.Int32, it.tex_offsets, slot, valid)
    return mi.UInt32(dr.select(textured, offset + row * width + col, 0)), textured


def shape_id_table(
    mi: Any, dr: Any, scene: Any, values: Mapping[str, int], default: int
) -> np.ndarray:
    """``uint32`` table indexed by the Mitsuba registry id of each shape of the loaded *scene*
    (``dr.reinterpret_array`` of ``si.shape``): ``values[shape.id()]``, *default* elsewhere."""
    shapes = list(scene.shapes())
    ids = (
        np.array(dr.reinterpret_array(mi.UInt32, mi.ShapePtr(shapes)), np.int64)
        if shapes
        else np.zeros(0, np.int64)
    )
    table = np.full(int(ids.max(initial=0)) + 1, default, np.uint32)
    for sid, shape in zip(ids, shapes, strict=True):
        table[sid] = values.get(shape.id(), default)
    return table


def texture_lookups(
    mi: Any, dr: Any, scene: Any, tables: TextureTables | None, shape_slots: Mapping[str, int]
) -> tuple[Any, ...]:
    """Dr.Jit arrays for :func:`texel_of` and the first-hit weights: shape id -> slot, each
    slot's width, height and first row (a last slot of width 0 for untextured shapes), the
    ``(N·K)`` texel albedos and ``(N·G)`` coverage weights."""
    n_slots = 0 if tables is None else len(tables.widths)
    slots = shape_id_table(mi, dr, scene, shape_slots, n_slots)
    if tables is None:
        zero = np.zeros(1, np.int32)
        return (
            mi.UInt32(slots),
            mi.Int32(zero),
            mi.Int32(zero),
            mi.Int32(zero),
            mi.Float(0.0),
            mi.Float(0.0),
        )

    def padded(a: np.ndarray) -> Any:
        return mi.Int32(np.append(np.asarray(a, np.int32), 0))

    return (
        mi.UInt32(slots),
        padded(tables.widths),
        padded(tables.heights),
        padded(tables.offsets),
        mi.Float(np.asarray(tables.albedo, np.float32).ravel()),
        mi.Float(np.asarray(tables.weights, np.float32).ravel()),
    )
