"""The first-hit maps of a scene (coverage per material, object and material ids, depth,
normals, mask) assembled from the box-filtered first-hit channels of a render, whichever wing
made them: Mitsuba's ``aov`` integrator (:func:`spectrinsic.render.passes.aovs.render_aovs`) or
the single traversal (:mod:`spectrinsic.render.band_path.traversal`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...scenes.model import Scene
from . import translate as tr

__all__ = ["assemble_aovs"]


def _majority(coverage: np.ndarray) -> np.ndarray:
    """Index of the largest coverage per pixel, -1 where the uncovered rest is larger."""
    if coverage.shape[-1] == 0:
        return np.full(coverage.shape[:2], -1, np.int32)
    rest = 1.0 - coverage.sum(axis=-1, keepdims=True)
    winner = np.argmax(np.concatenate([coverage, rest], axis=-1), axis=-1)
    return np.where(winner == coverage.shape[-1], -1, winner).astype(np.int32)


#: float64 coverage held at once per row block: the per-object maps of a scene with hundreds of
#: objects are otherwise gigabytes (docs/artist-interior-speed.md); every map is per pixel, so
#: a block's bits are those of the whole image's.
_BLOCK_BYTES = 32 * 2**20


def _row_blocks(h: int, w: int, channels: int) -> list[slice]:
    """Row slices of about :data:`_BLOCK_BYTES` of float64 for *channels* maps of width *w*."""
    step = max(1, _BLOCK_BYTES // max(1, 8 * w * channels))
    return [slice(r, min(h, r + step)) for r in range(0, h, step)]


def _block_coverage(
    scene: Scene,
    surfaces: Sequence[tr.Surface],
    cover: np.ndarray,
    columns: np.ndarray,
    object_ids: list[int],
) -> tuple[np.ndarray, np.ndarray]:
    """float64 coverage per material and per object (*object_ids* order) of rows of *cover*."""
    h, w = cover.shape[:2]
    material_cov = np.zeros((h, w, len(scene.materials)))
    object_cov = np.zeros((h, w, len(object_ids)))
    slot = {o: k for k, o in enumerate(object_ids)}
    for i, s in enumerate(surfaces):
        if s.material >= 0:
            if scene.meshes[s.mesh].texture is None:
                material_cov[..., s.material] += cover[..., i]
            object_cov[..., slot[scene.meshes[s.mesh].object_id]] += cover[..., i]
    for g, m in enumerate(columns):
        material_cov[..., int(m)] += cover[..., len(surfaces) + g]
    return material_cov, object_cov


def assemble_aovs(
    scene: Scene,
    surfaces: Sequence[tr.Surface],
    cover: np.ndarray,
    depth_sum: np.ndarray | None,
    normal_sum: np.ndarray | None,
    texture_columns: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """The maps :func:`~spectrinsic.render.passes.aovs.render_aovs` returns, from the box-filtered per-surface coverage
    ``(H, W, S)``, ray distance ``(H, W)`` and shading normal ``(H, W, 3)`` of the camera rays'
    first hits (0 where they miss).

    With *texture_columns* ``(G,)`` (material indices), *cover* has ``S + G`` channels: the last
    G hold the box-filtered texel weights of textured hits on those basis materials
    (:mod:`~spectrinsic.render.base.textures`), which take the place of the textured surfaces'
    own coverage in the material coverage."""
    columns = np.zeros(0, np.int64) if texture_columns is None else np.asarray(texture_columns)
    h, w = cover.shape[:2]
    object_ids = sorted({m.object_id for m in scene.meshes})
    coverage = np.empty((h, w, len(scene.materials)), np.float32)
    material_id = np.empty((h, w), np.int32)
    winner = np.empty((h, w), np.int32)
    for rows in _row_blocks(h, w, len(scene.materials) + len(object_ids) + 1):
        material_cov, object_cov = _block_coverage(
            scene, surfaces, cover[rows], columns, object_ids
        )
        material_id[rows] = _majority(material_cov)
        winner[rows] = _majority(object_cov)
        coverage[rows] = np.clip(material_cov, 0.0, 1.0)
    hit = cover[..., : len(surfaces)].sum(axis=-1)
    object_id = np.where(winner >= 0, np.asarray(object_ids + [-1], np.int64)[winner], -1).astype(
        np.int32
    )
    depth = (
        np.zeros((h, w))
        if depth_sum is None
        else np.divide(depth_sum, hit, out=np.zeros((h, w)), where=hit > 1e-6)
    )
    normals = np.zeros((h, w, 3)) if normal_sum is None else normal_sum
    length = np.linalg.norm(normals, axis=-1, keepdims=True)
    normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 1e-6)
    return {
        "coverage": coverage,
        "material_id": material_id,
        "object_id": object_id,
        "depth": depth.astype(np.float32),
        "normals": normals.astype(np.float32),
        "mask": material_id >= 0,
    }
