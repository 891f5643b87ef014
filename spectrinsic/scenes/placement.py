"""Where the camera and the lights sit: no point light or camera inside a closed mesh, and a
camera that sees something.

Inside is decided by the generalised winding number (Jacobson et al. 2013), exact for closed
meshes (every edge shared by exactly two faces) and robust to overlapping parts; an open surface
has no inside. The camera must see a mesh along at least one ray through a coarse grid of pixel
centres (trimesh ray tests: Embree through ``embreex`` when installed, else trimesh's own
triangle tests, which need ``rtree``).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

import numpy as np

from .geometry import VISIBILITY_GRID, camera_rays, is_closed, winding_numbers
from .model import LIGHT_FIELDS, Mesh, Scene
from .problems import field_error

__all__ = ["check_placement"]

log = logging.getLogger(__name__)


#: A point is inside a closed mesh when its winding number exceeds this (exactly 1 inside,
#: 0 outside for a closed outward-oriented surface; overlapping parts add up).
_INSIDE_WINDING = 0.5


def check_placement(scene: Scene, source: str) -> None:
    """Refuse a light or the camera inside a closed mesh, and a camera that sees no mesh."""
    points = {
        f"lights[{i}].position ({light.kind} light)": light.position
        for i, light in enumerate(scene.lights)
        if "position" in LIGHT_FIELDS[light.kind]
    }
    points["camera.origin"] = scene.camera.origin
    labels, xyz = list(points), np.asarray(list(points.values()), dtype=np.float64)
    for m in scene.meshes:
        lo, hi = m.vertices.min(axis=0), m.vertices.max(axis=0)
        candidates = np.flatnonzero(np.all((xyz >= lo) & (xyz <= hi), axis=1))
        if len(candidates) == 0:  # tested first: cheaper than is_closed on big scenes
            continue
        if not is_closed(m.faces):
            log.debug("mesh %r is not closed; it has no inside to test", m.name)
            continue
        w = winding_numbers(xyz[candidates], m.vertices, m.faces)
        for k, wk in zip(candidates, w, strict=True):
            if wk > _INSIDE_WINDING:
                raise field_error(
                    source,
                    labels[k],
                    f"{list(map(float, xyz[k]))} is inside the closed mesh {m.name!r}; move it into free space",
                )
    cam = scene.camera
    origins, dirs = camera_rays(cam.origin, cam.target, cam.up, cam.fov_deg, cam.width, cam.height)
    if not _sees_a_mesh(scene.meshes, origins, dirs):
        raise field_error(
            source,
            "camera",
            f"looks at nothing: none of {VISIBILITY_GRID}x{VISIBILITY_GRID} rays from origin "
            f"{list(cam.origin)} towards target {list(cam.target)} hits a mesh",
        )


def _box_hits(origins: np.ndarray, dirs: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Which rays meet the box [lo, hi] ahead of their origin (the slab test)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / dirs
        t0, t1 = (lo - origins) * inv, (hi - origins) * inv
    near = np.nanmax(np.minimum(t0, t1), axis=1)
    far = np.nanmin(np.maximum(t0, t1), axis=1)
    return (far >= np.maximum(near, 0.0)) & np.isfinite(far)


def _sees_a_mesh(meshes: Sequence[Mesh], origins: np.ndarray, dirs: np.ndarray) -> bool:
    """Whether a ray hits a mesh: each mesh tested with the rays that meet its bounding box,
    the meshes whose boxes most rays meet first (a scene in view is found by the first one;
    one mesh at a time keeps a big scene's ray test small)."""
    import trimesh

    hits = [
        _box_hits(origins, dirs, m.vertices.min(axis=0), m.vertices.max(axis=0)) for m in meshes
    ]
    for k in sorted(range(len(meshes)), key=lambda k: -int(hits[k].sum())):
        if not hits[k].any():
            break
        m = meshes[k]
        shape = trimesh.Trimesh(m.vertices, m.faces, process=False)
        if shape.ray.intersects_any(origins[hits[k]], dirs[hits[k]]).any():
            return True
    return False
