"""Mitsuba passes: K-channel diagonal renders as ⌈K/3⌉ RGB passes (the first-hit maps are in
:mod:`.aovs`, the spectral reference in :mod:`spectrinsic.render.spectral`).

Every pass of one image uses the same sampler seed, sample count and path depth with Russian
roulette off, so passes trace identical paths (common random numbers): the differences between
3-, 6- and K-channel renders are spectral error, not Monte Carlo noise. A scene is loaded once
per variant and light subset; between passes only BSDF and emitter values change, through
``mi.traverse``/``params.update()``, so Dr.Jit reuses its compiled kernels.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
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
    check_scene_lights,
    placeholder_light,
    scene_parameters,
    set_rgb,
    timed_render,
)
from ..base.plugins import hdr_film, path_integrator, rgb_spectrum
from ..base.surface_maps import refuse_maps
from ..base.textures import refuse_textures
from ..base.variants import choose_variant, variant_scope
from ..settings import PassRequest

__all__ = ["render_diagonal"]

logger = logging.getLogger(__name__)


def render_diagonal(
    scene: Scene,
    value_sets: Sequence[ChannelValues],
    request: PassRequest,
    *,
    direct: Sequence[bool] | bool = False,
    active_lights: Sequence[int] | None = None,
) -> list[PassOutput]:
    """Diagonal renders of *scene*, one per entry of *value_sets*, all on one loaded scene.

    Each K-channel value set is rendered as ⌈K/3⌉ RGB passes (the last zero-padded) that share
    seed, sample count and paths with every other pass (Eq. 5.2 per channel).

    Parameters
    ----------
    value_sets
        Channel values (:func:`spectrinsic.render.algebra.modes.channel_values`) of each render.
    request
        The batch's :class:`~spectrinsic.render.settings.PassRequest`.
    direct
        Per value set (or for all): also render direct light only (``max_depth`` 2), for the
        energy ratio r of Eq. 5.8.
    active_lights
        Indices of the lights to render (default all); others are left out (per-light renders).

    Returns
    -------
    One :class:`PassOutput` per value set, ``(H, W, K)`` float32 raw channels.
    """
    check_scene_lights(scene)
    if any(light.kind == "envmap" for light in scene.lights):
        raise SceneError(
            f"scene {scene.name!r} has an environment map: the passes cannot split its RGB "
            "channels into lights; render it with the single traversal (--integrator single, "
            "an llvm or cuda variant)"
        )
    refuse_textures(scene, "the diagonal passes")
    refuse_maps(scene, "the diagonal passes")
    active = active_light_set(scene, active_lights)
    flags = (
        [bool(direct)] * len(value_sets) if isinstance(direct, bool) else [bool(d) for d in direct]
    )
    if len(flags) != len(value_sets):
        raise SceneError(f"direct flags {flags}: expected one per value set ({len(value_sets)})")
    if not value_sets:
        return []
    surfaces = [s for s in tr.surfaces(scene) if s.material >= 0]
    chosen = choose_variant("rgb", request.variant)
    outputs = []
    with variant_scope(chosen) as mi:
        mitsuba_dict = tr.scene_to_mitsuba(
            scene,
            # placeholders: every pass sets its own values before rendering
            materials=[rgb_spectrum([0.0, 0.0, 0.0])] * len(scene.materials),
            lights=[
                placeholder_light(j) if j in active else None for j in range(len(scene.lights))
            ],
            film=hdr_film(scene.camera.width, scene.camera.height),
            integrator=path_integrator(request.max_depth),
            sample_count=request.batch_spp,
            geometry=request.geometry,
        )
        loaded = mi.load_dict(mitsuba_dict)
        params = scene_parameters(
            mi,
            loaded,
            [tr.reflectance_key(s, spectral=False) for s in surfaces]
            + [tr.emission_key(scene, j, spectral=False) for j in sorted(active)],
        )
        direct_integrator = mi.load_dict(path_integrator(DIRECT_DEPTH)) if any(flags) else None
        for values, want_direct in zip(value_sets, flags, strict=True):
            passes = _DiagonalPasses(mi, loaded, params, direct_integrator, request)
            outputs.append(
                passes.render(scene, surfaces, sorted(active), values, want_direct, chosen)
            )
    return outputs


@dataclass(frozen=True)
class _DiagonalPasses:
    """One loaded RGB scene and what every diagonal pass on it shares (the request, integrators)."""

    mi: Any
    loaded: Any
    params: Any
    direct_integrator: Any
    request: PassRequest

    def render(
        self,
        scene: Scene,
        surfaces: Sequence[tr.Surface],
        active: Sequence[int],
        values: ChannelValues,
        want_direct: bool,
        variant: str,
    ) -> PassOutput:
        """The ⌈K/3⌉ RGB passes of one value set (and their direct-only twins), stacked to K."""
        k = values.materials.shape[1]
        full, direct_parts, seconds = [], [], []
        for mats, lights in zip(
            pad_to_passes(values.materials), pad_to_passes(values.lights), strict=True
        ):
            for s in surfaces:
                set_rgb(
                    self.mi, self.params, tr.reflectance_key(s, spectral=False), mats[s.material]
                )
            for j in active:
                set_rgb(self.mi, self.params, tr.emission_key(scene, j, spectral=False), lights[j])
            self.params.update()
            image, dt = timed_render(self.mi, self.loaded, self.request)
            full.append(image)
            seconds.append(dt)
            if want_direct:
                image, dt = timed_render(self.mi, self.loaded, self.request, self.direct_integrator)
                direct_parts.append(image)
                seconds.append(dt)
        return PassOutput(
            image=np.concatenate(full, axis=-1)[..., :k],
            direct=np.concatenate(direct_parts, axis=-1)[..., :k] if want_direct else None,
            seconds=tuple(seconds),
            variant=variant,
        )
