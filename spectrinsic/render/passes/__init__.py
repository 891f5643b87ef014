"""Mitsuba passes: K-channel diagonal renders as ⌈K/3⌉ RGB passes (the first-hit maps are in
:mod:`.aovs`, the spectral reference in :mod:`spectrinsic.render.spectral`).

Every pass of one image uses the same sampler seed, sample count and path depth with Russian
roulette off, so passes trace identical paths (common random numbers): the differences between
3-, 6- and K-channel renders are spectral error, not Monte Carlo noise. A scene is loaded once
per variant and light subset; between passes only BSDF and emitter values change, through
``mi.traverse``/``params.update()``, so Dr.Jit reuses its compiled kernels.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ...errors import SceneError
from ...scenes.model import Scene
from ..algebra.modes import ChannelValues, pad_to_passes
from ..base import translate as tr
from ..base.one_pass import (
    DIRECT_DEPTH,
    PassOutput,
    active_light_set,
    load_rgb_scene,
    refuse_surface_detail,
    set_rgb,
    timed_render,
)
from ..base.plugins import path_integrator
from ..base.variants import choose_variant, variant_scope
from ..settings import PassRequest

__all__ = ["render_diagonal"]


def render_diagonal(
    scene: Scene,
    value_sets: Sequence[ChannelValues],
    request: PassRequest,
    *,
    direct: Sequence[bool] | bool = False,
    active_lights: Sequence[int] | None = None,
) -> list[PassOutput]:
    """Diagonal renders of *scene*, one per entry of *value_sets*
    (:func:`~spectrinsic.render.algebra.modes.channel_values`), all on one loaded scene: each
    K-channel value set is ⌈K/3⌉ RGB passes (the last zero-padded), stacked to ``(H, W, K)``
    float32 raw channels (Eq. 5.2 per channel).

    Parameters
    ----------
    direct
        Per value set (or for all): also render direct light only (``max_depth`` 2), for the
        energy ratio r of Eq. 5.8.
    active_lights
        Indices of the lights to render (default all); others are left out (per-light renders).
    """
    if any(light.kind == "envmap" for light in scene.lights):
        raise SceneError(
            f"scene {scene.name!r} has an environment map: the passes cannot split its RGB "
            "channels into lights; render it with the single traversal (--integrator single, "
            "an llvm or cuda variant)"
        )
    refuse_surface_detail(scene, "the diagonal passes")
    active = sorted(active_light_set(scene, active_lights))
    flags = (
        [bool(direct)] * len(value_sets) if isinstance(direct, bool) else [bool(d) for d in direct]
    )
    if len(flags) != len(value_sets):
        raise SceneError(f"direct flags {flags}: expected one per value set ({len(value_sets)})")
    if not value_sets:
        return []
    surfaces = [s for s in tr.surfaces(scene) if s.material >= 0]
    keys = [tr.reflectance_key(s, spectral=False) for s in surfaces] + [
        tr.emission_key(scene, j, spectral=False) for j in active
    ]
    chosen = choose_variant("rgb", request.variant)
    outputs = []
    with variant_scope(chosen) as mi:
        integrator = path_integrator(request.max_depth)
        loaded, params = load_rgb_scene(mi, scene, request, integrator, active, keys)
        direct_integrator = mi.load_dict(path_integrator(DIRECT_DEPTH)) if any(flags) else None
        for values, want_direct in zip(value_sets, flags, strict=True):
            runs: list[tuple[Any, list[np.ndarray]]] = [(None, [])] + (
                [(direct_integrator, [])] if want_direct else []
            )
            seconds = []
            for mats, lights in zip(
                pad_to_passes(values.materials), pad_to_passes(values.lights), strict=True
            ):
                rgbs = [mats[s.material] for s in surfaces] + [lights[j] for j in active]
                for key, rgb in zip(keys, rgbs, strict=True):
                    set_rgb(mi, params, key, rgb)
                params.update()
                for integrator, parts in runs:  # the full pass, then its direct twin
                    image, dt = timed_render(mi, loaded, request, integrator)
                    parts.append(image)
                    seconds.append(dt)
            k = values.materials.shape[1]
            full, *twin = (np.concatenate(parts, axis=-1)[..., :k] for _, parts in runs)
            outputs.append(PassOutput(full, twin[0] if twin else None, tuple(seconds), chosen))
    return outputs
