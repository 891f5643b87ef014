"""Per-light band transport, and renders under any light spectra composed from it.

A diagonal pass (:func:`~spectrinsic.render.passes.render_diagonal`) multiplies channel by
channel along each path, and each path's contribution ends at one light. So channel k of a
K-channel render is linear in every light's channel value (thesis Eq. 5.2 per channel):

    raw_k(x) = Σ_l T_lk(x) · ē_lk,      ē_lk = power_l ∫ L_l(λ) S_k(λ) dλ / ∫ S_k(λ) dλ     (1)

with ``T_lk`` the *transport* of light ``l``: the raw channel k (``∫ radiance · S_k dλ``,
render units) that light alone gives when it emits the flat unit spectrum ``L(λ) = 1`` at
power 1, and ``ē_lk`` the light's ``S_k``-weighted mean spectral value (for 10 nm box bands,
the mean of ``power · L`` over the band). Everything a sample derives from its raw channels
(XYZ images, the white-surface radiance and the shading, residual, illuminant, light shares
and camera layers built from it) then follows for any other light spectra and powers, by
the same functions.

Where the single traversal runs (``RenderSettings.integrator="single"``, the default on the
JIT variants), the transport is the traversal's own per-light split
(``RenderResult.transport``, per unit channel emission) times the flat unit spectrum's channel
values: one traversal per batch for every mode and light, and a relit sample equals a direct
``"single"`` render with the new spectra (same seed, spp and depth) to float32 rounding, since
the traversal's paths do not depend on the light spectra. With ``integrator="passes"`` (and on
a scalar variant) each light is rendered alone (one scene load per light, as Mitsuba cannot
switch an emitter off), with the seed, sample count and path depth of the sample, so every
light's paths are those of a direct per-light render with the passes. Either way, composing
Eq. 1 with the very spectra of a render equals that render to float32 rounding (the
multiplication by ``ē`` happens after the path sum instead of inside it). The spectral Monte
Carlo mode samples wavelengths and is not a band render; it cannot be relit.

:func:`render_transport_batches` is the one function that produces a sample's transport.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np

from ..errors import SceneError
from ..scenes.model import Scene
from ..spectra import COLORIMETRIC_WAVELENGTHS, get_sensors, responses
from .algebra.light_transport import LightTransport, diagonal_mode_names, relit_result
from .algebra.modes import ChannelValues, channel_values, get_mode
from .band_path.traversal import resolve_integrator
from .base.geometry import prepare_geometry
from .base.one_pass import PassProgress, timing
from .base.variants import choose_variant, variant_scope
from .batches import run_batches
from .passes import render_diagonal
from .passes.aovs import render_aovs
from .result import RenderResult
from .scene_render import render_scene
from .settings import PassRequest, RenderSettings

__all__ = ["render_transport", "render_transport_batches"]

logger = logging.getLogger(__name__)


def _unit_values(scene: Scene, sensors: str, data_dir: str | None) -> ChannelValues:
    """Material values of the scene and, for every light, the flat unit spectrum at power 1
    (``∫S_k dλ``, what :func:`channel_values` gives a light of spectrum 1)."""
    wl, sensor_set = COLORIMETRIC_WAVELENGTHS, get_sensors(sensors, data_dir=data_dir)
    flat = responses(np.ones(wl.size), sensor_set.on(wl), wl)
    materials = channel_values(scene, sensor_set, data_dir=data_dir).materials
    return ChannelValues(materials=materials, lights=np.tile(flat, (len(scene.lights), 1)))


def render_transport(
    scene: Scene,
    settings: RenderSettings,
    *,
    seed: int,
    progress: PassProgress | None = None,
    data_dir: str | None = None,
) -> tuple[dict[str, np.ndarray], dict[str, tuple[float, ...]]]:
    """One batch of transport by the passes, each light alone with the flat unit spectrum at
    power 1 (module docstring), for the diagonal ones of ``settings.modes``: mode ->
    ``(L, H, W, K)`` float32 ``T_lk``, and the pass seconds."""
    modes = settings.modes
    names = diagonal_mode_names(modes)
    if not names:
        raise SceneError(
            f"modes {list(modes)}: the transport needs a diagonal mode (rgb3, rgb6, bands31)"
        )
    if not scene.lights:
        raise SceneError(f"scene {scene.name!r} has no lights: no transport to render")
    sensors = [get_mode(m).sensors for m in names]
    values = [_unit_values(scene, s, data_dir) for s in sensors]
    chosen = choose_variant("rgb", settings.variant)
    request = replace(
        PassRequest.of(settings, seed, progress, prepare_geometry(scene)), variant=chosen
    )
    per_light: list[list[np.ndarray]] = [[] for _ in names]
    seconds: dict[str, list[float]] = {m: [] for m in names}
    with variant_scope(chosen):  # one scope: switching variants reloads Mitsuba's modules
        for j in range(len(scene.lights)):
            outputs = render_diagonal(scene, values, request, active_lights=[j])
            for i, out in enumerate(outputs):
                per_light[i].append(out.image)
                seconds[names[i]].extend(out.seconds)
    return (
        {m: np.stack(p).astype(np.float32) for m, p in zip(names, per_light, strict=True)},
        {m: tuple(s) for m, s in seconds.items()},
    )


def _one_batch(
    names: Sequence[str],
    settings: RenderSettings,
    seed: int,
    t: dict[str, np.ndarray],
    parts: Mapping[str, dict[str, np.ndarray]] | None = None,
) -> LightTransport:
    """One batch's transport (and its glossy parts, where rendered) as a :class:`LightTransport`."""
    return LightTransport(
        modes=tuple(names),
        sensors={m: get_mode(m).sensors for m in names},
        batches=(t,),
        seeds=(int(seed),),
        batch_spp=int(settings.batch_spp),
        max_depth=int(settings.max_depth),
        parts={p: (held,) for p, held in (parts or {}).items() if held},
    )


def _join(
    diagonal: RenderResult,
    other: RenderResult | None,
    aovs: Mapping[str, np.ndarray],
    order: Sequence[str],
) -> RenderResult:
    """One batch: the composed diagonal modes with the directly rendered others and the AOVs,
    modes in the requested *order*."""
    if other is None:
        return replace(diagonal, aovs=dict(aovs))
    meta = dict(other.meta)
    for key in ("sensors", "to_xyz", "timings", "variants"):
        meta[key] = {**other.meta.get(key, {}), **diagonal.meta.get(key, {})}
    meta.update(modes=list(order), per_light=True, per_light_modes=diagonal.meta["per_light_modes"])
    images, raw = {**other.images, **diagonal.images}, {**other.raw, **diagonal.raw}
    return RenderResult(
        images={m: images[m] for m in order},
        raw={m: raw[m] for m in order if m in raw},
        per_light=diagonal.per_light,
        direct=dict(other.direct),
        aovs=dict(aovs),
        meta=meta,
        parts=dict(diagonal.parts),
    )


def _flat_unit(
    scene: Scene, render: RenderResult, names: Sequence[str], data_dir: str | None
) -> tuple[dict[str, np.ndarray], dict[str, dict[str, np.ndarray]]]:
    """A traversal's transport and parts, per unit channel emission ``E_lk``, per flat unit
    spectrum instead (times ``∫S_k dλ``): Eq. 1's ``T_lk``."""
    flat = {
        m: _unit_values(scene, get_mode(m).sensors, data_dir).lights[:, None, None, :]
        for m in names
    }

    def unit(part: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {m: (part[m].astype(np.float64) * flat[m]).astype(np.float32) for m in part}

    return unit(render.transport), {p: unit(held) for p, held in render.part_transport.items()}


def _batch(
    scene: Scene,
    settings: RenderSettings,
    seed: int,
    *,
    progress: PassProgress | None,
    data_dir: str | None,
) -> tuple[LightTransport, RenderResult]:
    """Transport of one batch and the sample's render of that batch (the diagonal modes
    composed from it, the other modes rendered directly with every light on, the AOVs from the
    same pixel samples): where *settings*' integrator (resolved by
    :func:`render_transport_batches`) is ``"single"``, from one traversal, whose per-light split
    ``T'_lk`` (per unit channel emission) times ``∫S_k dλ`` is Eq. 1's ``T_lk``; else from one
    set of passes per light (:func:`render_transport`)."""
    order = list(dict.fromkeys(settings.modes))
    names = diagonal_mode_names(order)
    others = [m for m in order if m not in names]
    direct = (
        tuple(others)
        if settings.direct is True
        else tuple(m for m in settings.direct or () if m not in names)
    )

    def rendered(modes: Sequence[str]) -> RenderResult:
        return render_scene(
            scene,
            settings.with_options(
                modes=tuple(modes), per_light=False, share_mode=None, direct=direct, aovs=True
            ),
            seed=seed,
            progress=progress,
            data_dir=data_dir,
        )

    if settings.integrator == "single":
        render = rendered(settings.modes)
        t, parts = _flat_unit(scene, render, names, data_dir)
        batch = _one_batch(names, settings, seed, t, parts)
        timings = {m: render.meta["timings"][m] for m in names}
        variants = {m: render.meta["variants"][m] for m in names}
        aovs = render.aovs
        other = (
            replace(
                render,
                images={m: render.images[m] for m in others},
                raw={m: render.raw[m] for m in others},
                transport={},
                part_transport={},
            )
            if others
            else None
        )
    else:
        t, seconds = render_transport(
            scene, settings, seed=seed, progress=progress, data_dir=data_dir
        )
        batch = _one_batch(names, settings, seed, t)
        timings = {m: timing(s) for m, s in seconds.items()}
        variants = dict.fromkeys(names, choose_variant("rgb", settings.variant))
        other = rendered(others) if others else None
        if other is None:
            aovs, aov_seconds = render_aovs(scene, PassRequest.of(settings, seed, progress))
            timings["aovs"] = timing(aov_seconds)
        else:
            aovs = other.aovs
    meta = {"max_depth": int(settings.max_depth), "variants": variants, "timings": timings}
    return batch, _join(
        relit_result(batch, scene, meta=meta, data_dir=data_dir), other, aovs, order
    )


def render_transport_batches(
    scene: Scene,
    settings: RenderSettings,
    *,
    seed: int,
    progress: PassProgress | None = None,
    data_dir: str | None = None,
) -> tuple[LightTransport, RenderResult]:
    """The sample's transport and its render, as :func:`~spectrinsic.render.render_batches`.

    Each batch is :func:`_batch`'s, its diagonal modes composed with the scene's own spectra
    (:func:`~spectrinsic.render.algebra.light_transport.relit_result`), so relighting the
    sample with those spectra gives it back exactly. Batches, seeds and adaptive sampling
    follow :func:`~spectrinsic.render.render_batches`; ``per_light`` and ``share_mode`` do not
    apply (the transport is per light already).
    """
    modes = settings.modes
    if settings.direct and not [m for m in modes if m not in diagonal_mode_names(modes)]:
        raise SceneError(
            "direct-only renders with the transport need the 'spectral' mode "
            "(the diagonal modes are composed, not rendered with every light)"
        )

    # the integrator resolved once for every batch ("passes" where the traversal cannot run)
    resolved = settings.with_options(
        integrator=resolve_integrator(settings.integrator, settings.variant)
    )

    def one(s: int) -> tuple[LightTransport, RenderResult]:
        return _batch(scene, resolved, s, progress=progress, data_dir=data_dir)

    done, merged, seeds = run_batches(settings, seed, one, lambda d: d[1])
    names = diagonal_mode_names(modes)
    seconds = {
        m: tuple(x for r in done for x in r[1].meta["timings"][m]["per_pass"])
        for m in (*names, "single")
        if m in done[0][1].meta["timings"]
    }
    first = done[0][0]  # every batch's record holds the same modes, samples and depth
    transport = replace(
        first,
        batches=tuple(t.batches[0] for t, _ in done),
        seeds=tuple(int(s) for s in seeds),
        seconds=seconds,
        parts={p: tuple(t.parts[p][0] for t, _ in done) for p in first.parts},
    )
    merged.meta["transport"] = {"modes": list(names), "batches": len(done)}
    logger.debug(
        "transport of %s: %d light(s), %d batch(es)", scene.name, transport.n_lights, len(done)
    )
    return transport, merged
