"""The spectral reference pass: Mitsuba's spectral variant with a ``specfilm`` of a sensor
set's curves (the exact counterpart of a diagonal render's channels, Eq. 5.2)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import RenderError, SceneError
from ..scenes.model import Scene
from ..spectra import COLORIMETRIC_WAVELENGTHS, SensorSet, get_spectrum
from .algebra.modes import light_spectra
from .base import translate as tr
from .base.one_pass import (
    DIRECT_DEPTH,
    PassOutput,
    active_light_set,
    check_scene_lights,
    timed_render,
)
from .base.plugins import path_integrator, regular_spectrum, spectral_film
from .base.variants import choose_variant, variant_scope
from .settings import PassRequest

__all__ = ["render_spectral"]


def render_spectral(
    scene: Scene,
    sensors: SensorSet,
    request: PassRequest,
    *,
    direct: bool = False,
    active_lights: Sequence[int] | None = None,
    data_dir: str | None = None,
) -> PassOutput:
    """Spectral reference: Mitsuba's spectral variant with a ``specfilm`` of *sensors*' curves.

    Materials and lights are their registry spectra on the 1 nm CIE grid (360–830 nm), lights
    scaled by their power; channel k is ``∫ L(λ) S_k(λ) dλ`` (nm), the exact counterpart of a
    diagonal render's channel k. Works with any sensor set (CIE 1931, a camera's curves);
    negative lobes (``"srgb"``) are not supported by ``specfilm`` and are clipped. *request*
    (:class:`~spectrinsic.render.settings.PassRequest`) gives samples, seed, depth, variant,
    progress and prepared geometry.
    """
    check_scene_lights(scene)
    active = active_light_set(scene, active_lights)
    wl = COLORIMETRIC_WAVELENGTHS
    if np.any(sensors.curves < 0):
        raise SceneError(
            f"sensor set {sensors.name!r} has negative lobes; render 'cie1931' and convert instead"
        )
    chosen = choose_variant("spectral", request.variant)
    emission = light_spectra(scene, wl, data_dir=data_dir)
    with variant_scope(chosen) as mi:
        mitsuba_dict = tr.scene_to_mitsuba(
            scene,
            materials=[
                regular_spectrum(get_spectrum(m.spectrum, data_dir=data_dir).on(wl), wl)
                for m in scene.materials
            ],
            lights=[
                regular_spectrum(emission[j], wl) if j in active else None
                for j in range(len(scene.lights))
            ],
            film=spectral_film(scene.camera.width, scene.camera.height, sensors.on(wl), wl),
            integrator=path_integrator(request.max_depth),
            sample_count=request.batch_spp,
            geometry=request.geometry,
        )
        loaded = mi.load_dict(mitsuba_dict)
        spp, seed = request.batch_spp, request.seed
        image, dt = timed_render(mi, loaded, spp=spp, seed=seed)
        seconds = [dt]
        request.tick()
        direct_image = None
        if direct:
            integrator = mi.load_dict(path_integrator(DIRECT_DEPTH))
            direct_image, dt = timed_render(mi, loaded, spp=spp, seed=seed, integrator=integrator)
            seconds.append(dt)
            request.tick()
    k = sensors.n
    if image.shape[-1] < k:
        raise RenderError(f"specfilm returned {image.shape[-1]} channels for {k} sensors")
    return PassOutput(
        image=image[..., :k],
        direct=None if direct_image is None else direct_image[..., :k],
        seconds=tuple(seconds),
        variant=chosen,
    )
