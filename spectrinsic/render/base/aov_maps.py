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
    n_mat = len(scene.materials)
    material_cov = np.zeros((h, w, n_mat))
    object_ids = sorted({m.object_id for m in scene.meshes})
    object_cov = np.zeros((h, w, len(object_ids)))
    for i, s in enumerate(surfaces):
        if s.material >= 0:
            if scene.meshes[s.mesh].texture is None:
                material_cov[..., s.material] += cover[..., i]
            object_cov[..., object_ids.index(scene.meshes[s.mesh].object_id)] += cover[..., i]
    for g, m in enumerate(columns):
        material_cov[..., int(m)] += cover[..., len(surfaces) + g]
    hit = cover[..., : len(surfaces)].sum(axis=-1)
    material_id = _majority(material_cov)
    winner = _majority(object_cov)
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
        "coverage": np.clip(material_cov, 0.0, 1.0).astype(np.float32),
        "material_id": material_id,
        "object_id": object_id,
        "depth": depth.astype(np.float32),
        "normals": normals.astype(np.float32),
        "mask": material_id >= 0,
    }
