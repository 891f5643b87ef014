"""Camera sampling with coverage and visibility checks, and placement without interpenetration.

A camera is accepted when it is in free space (inside no closed mesh, by the generalised winding
number) and at least a minimum fraction of a grid of its rays first hits an *object* (a mesh
that is not a wall, floor or ground). Placement rejects footprints whose axis-aligned
rectangles overlap, so objects standing on one support never interpenetrate.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import SceneError
from ..geometry import camera_rays, is_closed, winding_numbers
from ..model import Camera, Mesh

__all__ = ["Footprints", "first_hits", "ray_triangle_hits", "coverage", "is_free", "sample_camera"]

#: Rays per side of the coverage grid.
COVERAGE_GRID = 12


@dataclass
class Footprints:
    """Occupied axis-aligned rectangles ``(x0, y0, x1, y1)`` on one support surface (metres)."""

    rects: list[tuple[float, float, float, float]]

    def try_add(self, centre: Any, half: Any, gap: float = 0.01) -> bool:
        """Occupy the rectangle around *centre* with half-sizes *half*, if it overlaps none."""
        x0, y0 = centre[0] - half[0] - gap, centre[1] - half[1] - gap
        x1, y1 = centre[0] + half[0] + gap, centre[1] + half[1] + gap
        if any(x0 < b[2] and b[0] < x1 and y0 < b[3] and b[1] < y1 for b in self.rects):
            return False
        self.rects.append((x0, y0, x1, y1))
        return True


def ray_triangle_hits(
    tri: np.ndarray, origins: np.ndarray, dirs: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Index into *tri* ``(F, 3, 3)`` of the first triangle each ray hits (-1: none) and its
    distance along the ray (inf: none), by Möller-Trumbore; cost ``O(R x F)`` in chunks."""
    best = np.full(len(origins), np.inf)
    hit = np.full(len(origins), -1)
    for s in range(0, len(tri), 4096):
        t0, e1, e2 = (
            tri[s : s + 4096, 0],
            tri[s : s + 4096, 1] - tri[s : s + 4096, 0],
            tri[s : s + 4096, 2] - tri[s : s + 4096, 0],
        )
        p = np.cross(dirs[:, None], e2[None])
        det = np.einsum("rfk,fk->rf", p, e1)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        tv = origins[:, None] - t0[None]
        u = np.einsum("rfk,rfk->rf", tv, p) * inv
        q = np.cross(tv, e1[None])
        v = np.einsum("rk,rfk->rf", dirs, q) * inv
        t = np.einsum("fk,rfk->rf", e2, q) * inv
        valid = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6)
        t = np.where(valid, t, np.inf)
        k = t.argmin(axis=1)
        tk = t[np.arange(len(t)), k]
        closer = tk < best
        best[closer], hit[closer] = tk[closer], s + k[closer]
    return hit, best


def first_hits(meshes: Sequence[Mesh], origins: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """Index into *meshes* of the first surface each ray hits (-1: none), by Möller-Trumbore.

    *origins*, *dirs*: ``(R, 3)``; cost ``O(R x F)`` in chunks of triangles.
    """
    tri = np.concatenate([m.vertices[m.faces] for m in meshes])
    owner = np.concatenate([np.full(len(m.faces), i) for i, m in enumerate(meshes)])
    hit, _ = ray_triangle_hits(tri, origins, dirs)
    return np.where(hit >= 0, owner[np.maximum(hit, 0)], -1)


def coverage(meshes: Sequence[Mesh], camera: Camera, is_object: Callable[[Mesh], bool]) -> float:
    """Fraction of a ``COVERAGE_GRID²`` ray grid of *camera* whose first hit is an object."""
    o, d = camera_rays(
        camera.origin,
        camera.target,
        camera.up,
        camera.fov_deg,
        camera.width,
        camera.height,
        n=COVERAGE_GRID,
    )
    hit = first_hits(meshes, o, d)
    flags = np.array([is_object(m) for m in meshes] + [False])
    return float(flags[hit].mean())


def is_free(meshes: Sequence[Mesh], point: Sequence[float] | np.ndarray) -> bool:
    """True when *point* is inside no closed mesh (generalised winding number < 0.5)."""
    p = np.asarray(point, float).reshape(1, 3)
    for m in meshes:
        lo, hi = m.vertices.min(axis=0), m.vertices.max(axis=0)
        if np.all(p >= lo) and np.all(p <= hi) and is_closed(m.faces):
            if abs(float(winding_numbers(p, m.vertices, m.faces)[0])) >= 0.5:
                return False
    return True


def sample_camera(
    rng: np.random.Generator,
    meshes: Sequence[Mesh],
    propose: Callable[[np.random.Generator], tuple[np.ndarray, np.ndarray, float]],
    *,
    width: int,
    height: int,
    is_object: Callable[[Mesh], bool],
    min_coverage: float,
    name: str = "view0",
    tries: int = 40,
    accept: Callable[[Camera], bool] | None = None,
) -> tuple[Camera, float]:
    """Draw cameras from ``propose(rng) -> (origin, target, fov_deg)`` until one is in free
    space, sees at least *min_coverage* of objects and passes *accept* (e.g. the view rule,
    :mod:`spectrinsic.scenes.generators.view_rule`); return it and its coverage.

    Raises
    ------
    SceneError
        When no proposal passes in *tries* draws.
    """
    best = 0.0
    for _ in range(tries):
        origin, target, fov = propose(rng)
        if (
            not math.isfinite(fov)
            or np.linalg.norm(target - origin) < 1e-3
            or not is_free(meshes, origin)
        ):
            continue
        cam = Camera(
            origin=tuple(float(x) for x in origin),  # type: ignore[arg-type]
            target=tuple(float(x) for x in target),  # type: ignore[arg-type]
            fov_deg=float(fov),
            width=width,
            height=height,
            name=name,
        )
        cov = coverage(meshes, cam, is_object)
        best = max(best, cov)
        if cov >= min_coverage and (accept is None or accept(cam)):
            return cam, cov
    raise SceneError(
        f"no camera of {tries} draws saw >= {min_coverage:.1%} objects (best {best:.1%})"
        + ("" if accept is None else " and passed the view rule")
    )
