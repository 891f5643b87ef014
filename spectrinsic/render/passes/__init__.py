"""Mitsuba passes: K-channel diagonal renders, the spectral reference, and AOVs.

Every pass of one image uses the same sampler seed, sample count and path depth with Russian
roulette off, so passes trace identical paths (common random numbers): the differences between
3-, 6- and K-channel renders are spectral error, not Monte Carlo noise. A scene is loaded once
per variant and light subset; between passes only BSDF and emitter values change, through
``mi.traverse``/``params.update()``, so Dr.Jit reuses its compiled kernels.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import RenderError, SceneError
from ...interrupts import raise_if_requested
from ...scenes.model import Scene
from ...spectra import COLORIMETRIC_WAVELENGTHS, SensorSet, get_spectrum
from ..algebra.modes import ChannelValues, light_spectra, pad_to_passes
from ..base import translate as tr
from ..base.plugins import hdr_film, path_integrator, regular_spectrum, rgb_spectrum, spectral_film
from ..base.textures import refuse_textures
from ..base.variants import choose_variant, variant_scope

__all__ = [
    "DIRECT_DEPTH",
    "PassProgress",
    "PassOutput",
    "render_diagonal",
    "render_spectral",
    "AOV_NAMES",
]

logger = logging.getLogger(__name__)

#: Path depth of a direct-light-only render (camera -> surface -> light).
DIRECT_DEPTH = 2
#: Called with 1 after each Mitsuba pass (e.g. ``tqdm.update``).
PassProgress = Callable[[int], Any]
#: Keys of the dict :func:`~spectrinsic.render.passes.aovs.render_aovs` returns.
AOV_NAMES = ("coverage", "material_id", "object_id", "depth", "normals", "mask")


@dataclass(frozen=True, eq=False)
class PassOutput:
    """Raw images of one set of channel values.

    Attributes
    ----------
    image
        ``(H, W, K)`` float32 full render (all bounces up to ``max_depth``).
    direct
        ``(H, W, K)`` float32 direct-light-only render, or ``None`` when not asked for.
    seconds
        Wall-clock seconds of each Mitsuba pass, in order (full passes, then direct ones).
    variant
        The Mitsuba variant used.
    """

    image: np.ndarray
    direct: np.ndarray | None
    seconds: tuple[float, ...]
    variant: str


def _check_render_args(scene: Scene, spp: int, max_depth: int) -> None:
    if int(spp) < 1:
        raise SceneError(f"spp {spp}: expected at least 1 sample per pixel")
    if int(max_depth) < 1:
        raise SceneError(f"max_depth {max_depth}: expected >= 1")
    if not scene.lights:
        raise SceneError(f"scene {scene.name!r} has no lights: nothing to render")


def _active(scene: Scene, active_lights: Sequence[int] | None) -> set[int]:
    active = (
        set(range(len(scene.lights))) if active_lights is None else {int(i) for i in active_lights}
    )
    bad = sorted(i for i in active if not 0 <= i < len(scene.lights))
    if bad or not active:
        raise SceneError(
            f"scene {scene.name!r}: active lights {sorted(active)} must be a non-empty subset of "
            f"0..{len(scene.lights) - 1}"
        )
    return active


def timed_render(
    mi: Any, loaded: Any, *, spp: int, seed: int, integrator: Any = None
) -> tuple[np.ndarray, float]:
    """One ``mi.render`` as float32 and its seconds; a Ctrl-C stops the build within it."""
    raise_if_requested()
    start = time.perf_counter()
    try:
        image = np.array(
            mi.render(loaded, spp=int(spp), seed=int(seed), integrator=integrator), dtype=np.float32
        )
    except RuntimeError as exc:
        raise_if_requested()  # Dr.Jit re-raises a Ctrl-C inside the render as RuntimeError
        raise RenderError(f"Mitsuba render failed: {exc}") from exc
    raise_if_requested()  # Mitsuba's own SIGINT handler may have cut the pass short
    return image, time.perf_counter() - start


def placeholder_light(index: int) -> dict[str, Any]:
    """Distinct emission per light at load time (identical dicts could be merged into one
    shared object); every pass sets the real values before rendering."""
    return rgb_spectrum([1.0 + index, 1.0, 1.0])


def scene_parameters(mi: Any, loaded: Any, keys: Sequence[str]) -> Any:
    """``mi.traverse`` of a loaded scene, checked to expose every parameter a pass updates."""
    params = mi.traverse(loaded)
    missing = [k for k in keys if k not in params]
    if missing:
        raise RenderError(f"Mitsuba scene lacks the parameters {missing[:3]} the passes update")
    return params


def set_rgb(mi: Any, params: Any, key: str, values: np.ndarray) -> None:
    params[key] = mi.Color3f(*(float(v) for v in values))


def render_diagonal(
    scene: Scene,
    value_sets: Sequence[ChannelValues],
    *,
    spp: int,
    seed: int,
    max_depth: int = 8,
    direct: Sequence[bool] | bool = False,
    active_lights: Sequence[int] | None = None,
    variant: str | None = None,
    progress: PassProgress | None = None,
    geometry: Sequence[tr.SurfaceGeometry] | None = None,
) -> list[PassOutput]:
    """Diagonal renders of *scene*, one per entry of *value_sets*, all on one loaded scene.

    Each K-channel value set is rendered as ⌈K/3⌉ RGB passes (the last zero-padded) that share
    seed, sample count and paths with every other pass (Eq. 5.2 per channel).

    Parameters
    ----------
    value_sets
        Channel values (:func:`spectrinsic.render.algebra.modes.channel_values`) of each render.
    direct
        Per value set (or for all): also render direct light only (``max_depth`` 2), for the
        energy ratio r of Eq. 5.8.
    active_lights
        Indices of the lights to render (default all); others are left out (per-light renders).
    variant
        Backend or variant name (:func:`spectrinsic.render.base.variants.choose_variant`).
    geometry
        :func:`spectrinsic.render.base.translate.prepare_geometry` of *scene*, if already computed.

    Returns
    -------
    One :class:`PassOutput` per value set, ``(H, W, K)`` float32 raw channels.
    """
    _check_render_args(scene, spp, max_depth)
    refuse_textures(scene, "the diagonal passes")
    active = _active(scene, active_lights)
    flags = (
        [bool(direct)] * len(value_sets) if isinstance(direct, bool) else [bool(d) for d in direct]
    )
    if len(flags) != len(value_sets):
        raise SceneError(f"direct flags {flags}: expected one per value set ({len(value_sets)})")
    if not value_sets:
        return []
    surfaces = [s for s in tr.surfaces(scene) if s.material >= 0]
    chosen = choose_variant("rgb", variant)
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
            integrator=path_integrator(max_depth),
            sample_count=spp,
            geometry=geometry,
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
            passes = _DiagonalPasses(mi, loaded, params, direct_integrator, spp, seed, progress)
            outputs.append(
                passes.render(scene, surfaces, sorted(active), values, want_direct, chosen)
            )
    return outputs


@dataclass(frozen=True)
class _DiagonalPasses:
    """One loaded RGB scene and what every diagonal pass on it shares (seed, spp, integrators)."""

    mi: Any
    loaded: Any
    params: Any
    direct_integrator: Any
    spp: int
    seed: int
    progress: PassProgress | None

    def _render(self, integrator: Any = None) -> tuple[np.ndarray, float]:
        image, dt = timed_render(
            self.mi, self.loaded, spp=self.spp, seed=self.seed, integrator=integrator
        )
        if self.progress is not None:
            self.progress(1)
        return image, dt

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
            image, dt = self._render()
            full.append(image)
            seconds.append(dt)
            if want_direct:
                image, dt = self._render(self.direct_integrator)
                direct_parts.append(image)
                seconds.append(dt)
        return PassOutput(
            image=np.concatenate(full, axis=-1)[..., :k],
            direct=np.concatenate(direct_parts, axis=-1)[..., :k] if want_direct else None,
            seconds=tuple(seconds),
            variant=variant,
        )


def render_spectral(
    scene: Scene,
    sensors: SensorSet,
    *,
    spp: int,
    seed: int,
    max_depth: int = 8,
    direct: bool = False,
    active_lights: Sequence[int] | None = None,
    variant: str | None = None,
    data_dir: str | None = None,
    progress: PassProgress | None = None,
    geometry: Sequence[tr.SurfaceGeometry] | None = None,
) -> PassOutput:
    """Spectral reference: Mitsuba's spectral variant with a ``specfilm`` of *sensors*' curves.

    Materials and lights are their registry spectra on the 1 nm CIE grid (360–830 nm), lights
    scaled by their power; channel k is ``∫ L(λ) S_k(λ) dλ`` (nm), the exact counterpart of a
    diagonal render's channel k. Works with any sensor set (CIE 1931, a camera's curves);
    negative lobes (``"srgb"``) are not supported by ``specfilm`` and are clipped.
    """
    _check_render_args(scene, spp, max_depth)
    active = _active(scene, active_lights)
    wl = COLORIMETRIC_WAVELENGTHS
    if np.any(sensors.curves < 0):
        raise SceneError(
            f"sensor set {sensors.name!r} has negative lobes; render 'cie1931' and convert instead"
        )
    chosen = choose_variant("spectral", variant)
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
            integrator=path_integrator(max_depth),
            sample_count=spp,
            geometry=geometry,
        )
        loaded = mi.load_dict(mitsuba_dict)
        image, dt = timed_render(mi, loaded, spp=spp, seed=seed)
        seconds = [dt]
        if progress is not None:
            progress(1)
        direct_image = None
        if direct:
            integrator = mi.load_dict(path_integrator(DIRECT_DEPTH))
            direct_image, dt = timed_render(mi, loaded, spp=spp, seed=seed, integrator=integrator)
            seconds.append(dt)
            if progress is not None:
                progress(1)
    k = sensors.n
    if image.shape[-1] < k:
        raise RenderError(f"specfilm returned {image.shape[-1]} channels for {k} sensors")
    return PassOutput(
        image=image[..., :k],
        direct=None if direct_image is None else direct_image[..., :k],
        seconds=tuple(seconds),
        variant=chosen,
    )
