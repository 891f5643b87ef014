"""The generators' ray cast (:func:`ray_triangle_hits`): analytic hits, and the same answers as
the ``np.cross``/``np.einsum`` form of Möller-Trumbore it replaced (issue 45: same cameras)."""

from __future__ import annotations

import numpy as np

from spectrinsic.scenes.generators.camera import MeshBoxes, ray_triangle_hits


def _reference(
    tri: np.ndarray, origins: np.ndarray, dirs: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Möller-Trumbore on (R, F, 3) stacks, one chunk: the former implementation."""
    t0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    p = np.cross(dirs[:, None], e2[None])
    det = np.einsum("rfk,fk->rf", p, e1)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    tv = origins[:, None] - t0[None]
    u = np.einsum("rfk,rfk->rf", tv, p) * inv
    q = np.cross(tv, e1[None])
    v = np.einsum("rk,rfk->rf", dirs, q) * inv
    t = np.einsum("fk,rfk->rf", e2, q) * inv
    t = np.where(ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6), t, np.inf)
    k = t.argmin(axis=1)
    best = t[np.arange(len(t)), k]
    return np.where(np.isfinite(best), k, -1), best


def test_analytic_hit_and_miss() -> None:
    # the unit right triangle in the plane z = 2, seen from the origin along +z
    tri = np.array([[[0.0, 0.0, 2.0], [1.0, 0.0, 2.0], [0.0, 1.0, 2.0]]])
    origins = np.zeros((3, 3))
    dirs = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.6, 0.6, 2.0]])
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    hit, dist = ray_triangle_hits(tri, origins + [0.2, 0.2, 0.0], dirs)
    assert hit.tolist() == [0, -1, -1]  # the third ray passes beyond the hypotenuse
    assert dist[0] == 2.0 and np.isinf(dist[1:]).all()


def test_same_hits_as_the_stacked_form() -> None:
    rng = np.random.default_rng(7)
    tri = rng.normal(size=(3000, 3, 3)) * 0.3 + rng.normal(size=(3000, 1, 3)) * 2.0
    origins = rng.normal(size=(144, 3)) * 0.1
    dirs = rng.normal(size=(144, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    hit, dist = ray_triangle_hits(tri, origins, dirs)
    ref_hit, ref_dist = _reference(tri, origins, dirs)
    assert (hit >= 0).sum() > 50  # the scene is hit often enough to test something
    np.testing.assert_array_equal(hit, ref_hit)
    np.testing.assert_allclose(dist, ref_dist, rtol=1e-12)


def test_culled_cast_equals_the_full_cast() -> None:
    # 12 clusters of 200 triangles ("meshes"), rays from inside the scene in all directions
    rng = np.random.default_rng(3)
    centres = rng.normal(size=(12, 1, 1, 3)) * 2.0
    tri = (rng.normal(size=(12, 200, 3, 3)) * 0.3 + centres).reshape(-1, 3, 3)
    per = tri.reshape(12, -1, 3)
    boxes = MeshBoxes(
        tri=tri,
        starts=np.arange(13) * 200,
        lo=per.min(axis=1) - 1e-6,
        hi=per.max(axis=1) + 1e-6,
    )
    origins = rng.normal(size=(256, 3)) * 0.2
    dirs = rng.normal(size=(256, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    hit, dist = boxes.hits(origins, dirs)
    full_hit, full_dist = ray_triangle_hits(tri, origins, dirs)
    assert (hit >= 0).sum() > 30
    np.testing.assert_array_equal(hit, full_hit)
    np.testing.assert_array_equal(dist, full_dist)
    assert boxes.mesh_of(hit).tolist() == np.where(hit >= 0, hit // 200, -1).tolist()
