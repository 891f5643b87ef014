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
from .base.variants import choose_variant, variant_scope
from .settings import PassRequest

__all__ = ["render_spectral"]


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


def _mitsuba_d65(mi: Any, wl: np.ndarray) -> np.ndarray:
    """Mitsuba's own D65 (the ``d65`` texture a spectral ``envmap`` multiplies by) at *wl*."""
    import drjit as dr

    si = dr.zeros(mi.SurfaceInteraction3f)
    si.wavelengths = mi.Spectrum(*[mi.Float(np.asarray(wl, float))] * 4)
    return np.asarray(mi.load_dict({"type": "d65"}).eval(si)[0], float)


def _light_passes(
    mi: Any, scene: Scene, active: set[int], emission: np.ndarray, wl: np.ndarray
) -> list[tuple[set[int], Any, np.ndarray]]:
    """The passes of one spectral render, each ``(lights on, grey bitmap or None, film factor
    (W,))``: one pass of every active light but an environment map's, then one per active
    channel light of the map.

    A spectral ``envmap`` evaluates its RGB data through a non-linear spectral upsampling,
    but a grey map of value v exactly as ``v · D65_mi(λ)`` (``docs/envmap_design.md`` fact 3).
    Channel light j (channel c) radiates ``m_c(ω) · E_j(λ)``; its pass loads the grey map of
    channel c and a film of curves ``S_k(λ) · E_j(λ) / D65_mi(λ)``, so its channel k is
    exactly ``∫ m_c E_j S_k dλ``. The passes sum (the render is linear in the lights)."""
    maps = envmap_groups(scene)
    env = {j for m in maps for j in m.lights}
    ones = np.ones(len(wl))
    others = active - env
    out: list[tuple[set[int], Any, np.ndarray]] = (
        [(others, None, ones)] if others or not (active & env) else []
    )
    if not active & env:
        return out
    d65 = _mitsuba_d65(mi, wl)
    for group in maps:
        data = np.asarray(mi.Bitmap(verified_map(scene.lights[group.lights[0]])), np.float32)
        for c, j in enumerate(group.lights):
            if j in active:
                grey = np.repeat(data[..., c : c + 1], 3, axis=-1)
                out.append(({j}, mi.Bitmap(np.ascontiguousarray(grey)), emission[j] / d65))
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
    environment map takes one more pass per channel (:func:`_light_passes`).
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
        passes = []
        for on, bitmap, factor in _light_passes(mi, scene, active, emission, wl):
            mitsuba_dict = tr.scene_to_mitsuba(
                scene,
                materials=materials,
                lights=[
                    None
                    if j not in on
                    else regular_spectrum(emission[j], wl)
                    if bitmap is None
                    else {"bitmap": bitmap}
                    for j in range(len(scene.lights))
                ],
                film=spectral_film(scene.camera.width, scene.camera.height, curves * factor, wl),
                integrator=path_integrator(request.max_depth),
                sample_count=request.batch_spp,
                geometry=request.geometry,
                transmittances=tints,
            )
            passes.append(_render_pass(mi, mi.load_dict(mitsuba_dict), request, direct))
    image = np.sum([p[0] for p in passes], axis=0)
    direct_image = np.sum([p[1] for p in passes if p[1] is not None], axis=0) if direct else None
    seconds = [sum(p[2][i] for p in passes) for i in range(len(passes[0][2]))]
    k = sensors.n
    if image.shape[-1] < k:
        raise RenderError(f"specfilm returned {image.shape[-1]} channels for {k} sensors")
    return PassOutput(
        image=image[..., :k],
        direct=None if direct_image is None else direct_image[..., :k],
        seconds=tuple(seconds),
        variant=chosen,
    )
