"""The spectral reference pass: Mitsuba's spectral variant with a ``specfilm`` of a sensor
set's curves (the exact counterpart of a diagonal render's channels, Eq. 5.2)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import RenderError, SceneError
from ..scenes.envmaps import envmap_groups, verified_map
from ..scenes.model import GLASS_TINTS, Scene
from ..spectra import COLORIMETRIC_WAVELENGTHS, SensorSet, get_spectrum
from .algebra.modes import light_spectra
from .base import translate as tr
from .base.one_pass import (
    DIRECT_DEPTH,
    PassOutput,
    active_light_set,
    timed_render,
)
from .base.plugins import path_integrator, regular_spectrum, spectral_film
from .base.summed_envmap import MapLight, summed_envmap
from .base.variants import choose_variant, variant_scope
from .settings import PassRequest

__all__ = ["render_spectral"]

#: Key of the environment maps' one emitter in the pass's Mitsuba scene dictionary.
_SUMMED_ENVMAP_KEY = "environment_maps"


def _render_pass(
    mi: Any, loaded: Any, request: PassRequest, direct: bool
) -> tuple[np.ndarray, np.ndarray | None, list[float]]:
    """One loaded scene rendered (and direct light only with *direct*): images and seconds."""
    image, dt = timed_render(mi, loaded, request)
    seconds = [dt]
    direct_image = None
    if direct:
        integrator = mi.load_dict(path_integrator(DIRECT_DEPTH))
        direct_image, dt = timed_render(mi, loaded, request, integrator)
        seconds.append(dt)
    return image, direct_image, seconds


def _map_lights(
    mi: Any, scene: Scene, active: set[int], emission: np.ndarray, curves: np.ndarray
) -> list[MapLight]:
    """The environment maps with an active channel light, as the summed emitter takes them:
    each active channel's emitted spectrum, sampled by its weight ``∫ E_j Σ_k S_k dλ`` (only
    the variance depends on it; equal weights if every one is 0)."""
    out = []
    for group in envmap_groups(scene):
        lit = [j if j in active else None for j in group.lights]
        if all(j is None for j in lit):
            continue
        w = np.array([0.0 if j is None else float(emission[j] @ curves.sum(0)) for j in lit])
        w = w if np.all(np.isfinite(w)) and w.sum() > 0 else np.ones(3)
        light = scene.lights[group.lights[0]]
        data = np.asarray(mi.Bitmap(verified_map(light)), np.float32)
        spectra = tuple(None if j is None else emission[j] for j in lit)
        weights = tuple(float(x) for x in w)
        out.append(MapLight(data, tr.envmap_to_world(light), spectra, weights))  # type: ignore[arg-type]
    return out


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
    negative lobes (``"srgb"``) are not supported by ``specfilm`` and are clipped. An
    environment map's channel lights are one emitter of the same pass (:func:`_map_lights`,
    :mod:`~spectrinsic.render.base.summed_envmap`).
    """
    active = active_light_set(scene, active_lights)
    wl = COLORIMETRIC_WAVELENGTHS
    if np.any(sensors.curves < 0):
        raise SceneError(
            f"sensor set {sensors.name!r} has negative lobes; render 'cie1931' and convert instead"
        )
    chosen = choose_variant("spectral", request.variant)
    emission = light_spectra(scene, wl, data_dir=data_dir)
    curves = sensors.on(wl)
    with variant_scope(chosen) as mi:
        materials = [
            regular_spectrum(get_spectrum(m.spectrum, data_dir=data_dir).on(wl), wl)
            for m in scene.materials
        ]
        tints = [  # tinted glass: Mitsuba's specular_transmittance/_reflectance, the same spectra
            {
                param: regular_spectrum(get_spectrum(m.tint(key), data_dir=data_dir).on(wl), wl)
                for key, param in GLASS_TINTS.items()
                if m.transmissive or getattr(m, key)  # a conductor has only a reflection tint
            }
            if m.tinted or m.specular_reflectance
            else None
            for m in scene.materials
        ]
        maps = _map_lights(mi, scene, active, emission, curves)
        env = {j for group in envmap_groups(scene) for j in group.lights}
        mitsuba_dict = tr.scene_to_mitsuba(
            scene,
            materials=materials,
            lights=[
                regular_spectrum(emission[j], wl) if j in active - env else None
                for j in range(len(scene.lights))
            ],
            film=spectral_film(scene.camera.width, scene.camera.height, curves, wl),
            integrator=path_integrator(request.max_depth),
            sample_count=request.batch_spp,
            geometry=request.geometry,
            transmittances=tints,
        )
        emitter = summed_envmap(mi, maps, wl) if maps else None
        if emitter is not None:
            mitsuba_dict[_SUMMED_ENVMAP_KEY] = emitter
        loaded = mi.load_dict(mitsuba_dict)
        if emitter is not None:
            emitter.attach(loaded)  # Mitsuba calls set_scene on built-in emitters only
        image, direct_image, seconds = _render_pass(mi, loaded, request, direct)
    k = sensors.n
    if image.shape[-1] < k:
        raise RenderError(f"specfilm returned {image.shape[-1]} channels for {k} sensors")
    return PassOutput(
        image=image[..., :k],
        direct=None if direct_image is None else direct_image[..., :k],
        seconds=tuple(seconds),
        variant=chosen,
    )
