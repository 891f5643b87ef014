"""The first-hit maps of a scene with the passes integrator: coverage per surface, ids, depth
and normals, from Mitsuba's ``aov`` integrator (the single traversal makes them itself)."""

from __future__ import annotations

import numpy as np

from ...errors import RenderError
from ...scenes.model import Scene
from ..base import translate as tr
from ..base.aov_maps import assemble_aovs
from ..base.one_pass import (
    load_rgb_scene,
    refuse_surface_detail,
    set_rgb,
    timed_render,
)
from ..base.plugins import aov_integrator
from ..base.variants import choose_variant, variant_scope
from ..settings import PassRequest

__all__ = ["render_aovs"]


def render_aovs(
    scene: Scene, request: PassRequest
) -> tuple[dict[str, np.ndarray], tuple[float, ...]]:
    """Coverage, id, depth and normal maps, box-filtered over the same pixel samples as a render.

    Each BSDF-carrying surface gets a one-hot diffuse reflectance in turn (three per pass) and
    the ``albedo`` AOV, averaged by a box filter, is the fraction of the pixel's samples hitting
    it; with the seed and sample count of the colour passes these are the very samples those
    passes averaged, so ``Σ_m coverage_m ρ_m`` is the ground-truth reflectance of each pixel.
    Mitsuba's own albedo of the real materials is not used (it assumes RGB wavelengths). The
    path depth of *request* does not apply: the ``aov`` integrator reads the first hit.

    Returns
    -------
    aovs
        ``coverage`` ``(H, W, M)`` float32 per material; ``material_id`` and ``object_id``
        ``(H, W)`` int32, the material (object) covering most of the pixel, -1 where background
        or light geometry covers most; ``depth`` ``(H, W)`` float32 mean ray distance from the
        camera centre over the pixel's hits (scene units, 0 where nothing is hit);
        ``normals`` ``(H, W, 3)`` float32 unit mean shading normal in world space as wound by
        the mesh (zero where nothing is hit); ``mask`` ``(H, W)`` bool, ``material_id >= 0``.
    seconds
        Seconds per pass.
    """
    refuse_surface_detail(scene, "the coverage passes")
    surfaces = tr.surfaces(scene)
    n_pass = max(1, -(-len(surfaces) // 3))
    chosen = choose_variant("rgb", request.variant)
    h, w = scene.camera.height, scene.camera.width
    cover = np.zeros((h, w, len(surfaces)), np.float64)
    seconds = []
    with variant_scope(chosen) as mi:
        keys = [tr.reflectance_key(s, spectral=False) for s in surfaces]
        every = range(len(scene.lights))
        loaded, params = load_rgb_scene(mi, scene, request, aov_integrator(), every, keys)
        depth_sum = normal_sum = None
        for p in range(n_pass):
            for i, key in enumerate(keys):  # one-hot: surface i is channel i % 3 of pass i // 3
                set_rgb(mi, params, key, np.eye(3)[i % 3] * (i // 3 == p))
            params.update()
            image, dt = timed_render(mi, loaded, request)
            seconds.append(dt)
            if image.shape[-1] != 7:
                raise RenderError(
                    f"AOV pass returned {image.shape[-1]} channels; expected 7 (depth, normal, albedo)"
                )
            if p == 0:
                depth_sum, normal_sum = image[..., 0].astype(float), image[..., 1:4].astype(float)
            block = surfaces[3 * p : 3 * p + 3]
            cover[..., 3 * p : 3 * p + len(block)] = image[..., 4 : 4 + len(block)]
    return assemble_aovs(scene, surfaces, cover, depth_sum, normal_sum), tuple(seconds)
