"""Mesh and camera geometry: winding numbers, closed meshes and a grid of camera rays.

:func:`winding_numbers` decides whether points lie inside a triangle mesh (the generalised
winding number, Jacobson et al. 2013), :func:`is_closed` whether a mesh has an inside at all,
and :func:`camera_rays` casts rays through a grid of image positions. Scene validation and the
camera placement of generators share them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["VISIBILITY_GRID", "camera_rays", "is_closed", "winding_numbers"]

#: Rays per image side of the "camera looking at nothing" test.
VISIBILITY_GRID = 16


def winding_numbers(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Generalised winding numbers of *points* with respect to a triangle mesh.

    ``w(p) = Σ_f Ω_f(p) / 4π`` with the solid angle of triangle ``(a, b, c)`` seen from p
    (Van Oosterom & Strackee 1983): ``tan(Ω/2) = a·(b×c) / (|a||b||c| + (a·b)|c| + (b·c)|a| +
    (c·a)|b|)`` for ``a, b, c`` relative to p.

    Parameters
    ----------
    points
        ``(P, 3)`` query points.
    vertices, faces
        ``(V, 3)`` float and ``(F, 3)`` int triangle mesh, counter-clockwise seen from outside.

    Returns
    -------
    numpy.ndarray
        ``(P,)`` float64: 1 inside and 0 outside a closed outward mesh.

    >>> import trimesh
    >>> m = trimesh.creation.box()
    >>> w = winding_numbers(np.array([[0, 0, 0], [2, 0, 0]]), m.vertices, m.faces)
    >>> bool(np.allclose(w, [1.0, 0.0]))
    True
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    out = np.zeros(len(pts))
    for k, p in enumerate(pts):
        a, b, c = (tri[:, i] - p for i in range(3))
        la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
        det = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = la * lb * lc + np.einsum("ij,ij->i", a, b) * lc
        den += np.einsum("ij,ij->i", b, c) * la + np.einsum("ij,ij->i", c, a) * lb
        out[k] = np.sum(2.0 * np.arctan2(det, den)) / (4.0 * np.pi)
    return out


def is_closed(faces: np.ndarray) -> bool:
    """True if every edge is shared by exactly two faces with opposite orientations."""
    f = np.asarray(faces)
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    if len(np.unique(directed, axis=0)) != len(directed):
        return False
    _, counts = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    return bool(np.all(counts == 2))


def camera_rays(
    origin: Sequence[float],
    target: Sequence[float],
    up: Sequence[float],
    fov_deg: float,
    width: int,
    height: int,
    n: int = VISIBILITY_GRID,
) -> tuple[np.ndarray, np.ndarray]:
    """Ray origins and unit directions through an ``n x n`` grid of image positions.

    The grid's cell centres span the image; *fov_deg* is horizontal, the vertical extent
    follows the aspect ratio ``height / width``.

    Returns
    -------
    tuple
        ``(n*n, 3)`` origins and ``(n*n, 3)`` unit directions.
    """
    o = np.asarray(origin, dtype=np.float64)
    forward = np.asarray(target, dtype=np.float64) - o
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(up, dtype=np.float64))
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    half = math.tan(math.radians(fov_deg) / 2)
    s = (np.arange(n) + 0.5) / n * 2 - 1
    x, y = np.meshgrid(s * half, s * half * height / width)
    d = forward + x.reshape(-1, 1) * right + y.reshape(-1, 1) * true_up
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.broadcast_to(o, d.shape).copy(), d
