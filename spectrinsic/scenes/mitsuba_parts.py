"""Mitsuba 3's built-in shapes as triangles, for :mod:`spectrinsic.scenes.mitsuba_xml`.

Conventions follow Mitsuba 3's documentation: ``rectangle`` spans [-1, 1]² at z = 0 with
normal +z, ``cube`` [-1, 1]³, ``disk`` the unit disk at z = 0, ``sphere`` a ``center`` and
``radius``, ``cylinder`` an open tube of ``radius`` from ``p0`` to ``p1``. Round shapes are
tessellated (:data:`SEGMENTS`): the scene's ground truth is that of the triangles rendered, so it
stays exact; only the silhouette differs from Mitsuba's analytic shape (said on stderr).
"""

from __future__ import annotations

import numpy as np

__all__ = ["SEGMENTS", "apply", "rectangle", "cube", "disk", "sphere", "cylinder", "faces_of"]

#: Segments of a tessellated disk and sphere (longitude; a sphere has half as many rings).
SEGMENTS = 32


def apply(m: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """*vertices* ``(V, 3)`` mapped by the 4 × 4 matrix *m*."""
    return vertices @ m[:3, :3].T + m[:3, 3]


def rectangle() -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of Mitsuba's ``rectangle``."""
    v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def cube() -> tuple[np.ndarray, np.ndarray]:
    """Vertices and outward faces of Mitsuba's ``cube``, [-1, 1]³."""
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    faces = [f for a, b, c, d in quads for f in ((a, b, c), (a, c, d))]
    return v, np.array(faces)


def disk() -> tuple[np.ndarray, np.ndarray]:
    """The unit disk at z = 0 (normal +z) as a fan of :data:`SEGMENTS` triangles."""
    t = np.linspace(0, 2 * np.pi, SEGMENTS, endpoint=False)
    v = np.vstack([[0, 0, 0], np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], 1)])
    i = np.arange(SEGMENTS)
    return v, np.stack([np.zeros_like(i), 1 + i, 1 + (i + 1) % SEGMENTS], 1)


def sphere(center: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """A UV sphere of :data:`SEGMENTS` longitudes, outward faces."""
    rings, seg = SEGMENTS // 2, SEGMENTS
    theta = np.linspace(0, np.pi, rings + 1)[1:-1]
    phi = np.linspace(0, 2 * np.pi, seg, endpoint=False)
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    ring = np.stack([st * np.cos(phi), st * np.sin(phi), np.broadcast_to(ct, (rings - 1, seg))], -1)
    v = np.vstack([[0, 0, 1], ring.reshape(-1, 3), [0, 0, -1]])
    faces = []
    south = len(v) - 1
    for j in range(seg):
        k = (j + 1) % seg
        faces.append((0, 1 + j, 1 + k))
        for r in range(rings - 2):
            a, b = 1 + r * seg + j, 1 + r * seg + k
            faces += [(a, a + seg, b + seg), (a, b + seg, b)]
        last = 1 + (rings - 2) * seg
        faces.append((last + j, south, last + k))
    return center + radius * v, np.array(faces)


def cylinder(p0: np.ndarray, p1: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """An open tube of :data:`SEGMENTS` quads from *p0* to *p1*, outward faces."""
    axis = np.asarray(p1, float) - np.asarray(p0, float)
    length = float(np.linalg.norm(axis))
    w = axis / length
    u = np.cross(w, [1.0, 0.0, 0.0] if abs(w[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    t = np.linspace(0, 2 * np.pi, SEGMENTS, endpoint=False)
    ring = radius * (np.cos(t)[:, None] * u + np.sin(t)[:, None] * v)
    verts = np.vstack([p0 + ring, p1 + ring])
    i = np.arange(SEGMENTS)
    j = (i + 1) % SEGMENTS
    n = SEGMENTS
    faces = np.concatenate([np.stack([i, j, j + n], 1), np.stack([i, j + n, i + n], 1)])
    return verts, faces


def faces_of(plugin: str) -> int:
    """Triangles :func:`rectangle`, :func:`cube`, :func:`disk`, :func:`sphere` or
    :func:`cylinder` makes (the scene budget counts them before building any)."""
    rings = SEGMENTS // 2
    return {
        "rectangle": 2,
        "cube": 12,
        "disk": SEGMENTS,
        "sphere": 2 * SEGMENTS + 2 * SEGMENTS * (rings - 2),
        "cylinder": 2 * SEGMENTS,
    }[plugin]
