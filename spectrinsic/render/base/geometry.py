"""A scene's triangles ready for Mitsuba (pure numpy): every mesh split by material into
surfaces with unshared corners, smoothed corner normals and texture coordinates.

Vertex normals are smoothed across edges whose faces meet at less than
:data:`CREASE_ANGLE_DEG`, and kept sharp elsewhere (box corners stay crisp, spheres look round).
Computed once per scene (:func:`prepare_geometry`) and carried by the
:class:`~spectrinsic.render.settings.PassRequest` to every translation
(:func:`spectrinsic.render.base.translate.scene_to_mitsuba`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...scenes.model import Scene
from ...scenes.textures import box_uv

__all__ = ["CREASE_ANGLE_DEG", "smooth_corner_normals", "SurfaceGeometry", "prepare_geometry"]


#: Faces meeting at a smaller angle than this share smoothed vertex normals (degrees).
CREASE_ANGLE_DEG = 30.0


def smooth_corner_normals(
    vertices: np.ndarray, faces: np.ndarray, crease_deg: float = CREASE_ANGLE_DEG
) -> np.ndarray:
    """``(F, 3, 3)`` unit normals at each face corner, smoothed below a crease angle.

    A corner's normal is the area-weighted mean of the normals of the faces around its vertex
    that meet the corner's face at less than *crease_deg* degrees; degenerate faces fall back
    to ``+z``.
    """
    v = np.asarray(vertices, float)
    f = np.asarray(faces, np.int64)
    tri = v[f]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])  # length = 2 × area
    length = np.linalg.norm(cross, axis=1)
    unit = np.divide(cross, length[:, None], out=np.zeros_like(cross), where=length[:, None] > 0)
    corner_vertex = f.ravel()  # corner i is corner i % 3 of face i // 3
    order = np.argsort(corner_vertex, kind="stable")
    sorted_v = corner_vertex[order]
    sorted_face = order // 3
    starts = np.flatnonzero(np.r_[True, sorted_v[1:] != sorted_v[:-1]])
    counts = np.diff(np.r_[starts, sorted_v.size])
    # every ordered pair (a, b) of sorted corners at one vertex: a runs over the sorted corners,
    # each repeated once per corner of its vertex, and b over that vertex's corners. Built with
    # np.repeat rather than fancy indexing, which is the costly part on large meshes.
    per = np.repeat(counts, counts)  # pairs each sorted corner takes part in
    b = np.repeat(starts, counts * counts) + (
        np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per)
    )
    fb = sorted_face[b]
    unit_a = np.repeat(unit[sorted_face], per, axis=0)
    keep = np.einsum("ij,ij->i", unit_a, unit[fb]) >= np.cos(np.radians(crease_deg))
    target, weights = np.repeat(order, per)[keep], cross[fb[keep]]
    acc = np.stack(
        [
            np.bincount(target, weights=weights[:, c], minlength=corner_vertex.size)
            for c in range(3)
        ],
        axis=1,
    ).astype(np.float64)  # no pairs: bincount gives int
    norm = np.linalg.norm(acc, axis=1)
    out = np.divide(acc, norm[:, None], out=np.zeros_like(acc), where=norm[:, None] > 0)
    out[norm == 0] = (0.0, 0.0, 1.0)
    return out.reshape(len(f), 3, 3)


@dataclass(frozen=True, eq=False)
class SurfaceGeometry:
    """Triangles of one surface, ready for Mitsuba: ``corners`` and ``normals`` ``(F, 3, 3)``,
    and on a textured mesh (its ``mesh`` index) the corners' ``uv`` ``(F, 3, 2)`` (the
    texture's own, else :func:`~spectrinsic.scenes.textures.box_uv`)."""

    key: str
    material: int
    corners: np.ndarray
    normals: np.ndarray
    mesh: int = -1
    uv: np.ndarray | None = None


def prepare_geometry(scene: Scene) -> tuple[SurfaceGeometry, ...]:
    """Split every mesh by material and compute its smoothed corner normals (module docstring);
    :func:`scene_to_mitsuba` does this itself when not given the result."""
    out = []
    for index, mesh in enumerate(scene.meshes):
        faces = np.asarray(mesh.faces, np.int64)
        corners = np.asarray(mesh.vertices, float)[faces]
        normals = smooth_corner_normals(mesh.vertices, faces)
        face_materials = np.asarray(mesh.face_materials, np.int64)
        texture = mesh.texture
        uv = (
            None
            if texture is None
            else box_uv(mesh.vertices, faces)
            if texture.uv is None
            else np.asarray(texture.uv, float)  # the asset's own coordinates
        )
        if uv is None and mesh.maps is not None:
            uv = np.asarray(mesh.maps.uv, float)
        for m in np.unique(face_materials):
            sel = face_materials == m
            out.append(
                SurfaceGeometry(
                    f"surf_{index}_{int(m)}",
                    int(m),
                    corners[sel],
                    normals[sel],
                    index,
                    None if uv is None else uv[sel],
                )
            )
    return tuple(out)
