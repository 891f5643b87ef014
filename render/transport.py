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
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from spectrinsic.errors import RenderError, SceneError
from spectrinsic.render.modes import (
    ChannelValues,
    channel_values,
    get_mode,
    light_spectra,
    raw_to_xyz,
    to_xyz_matrix,
)
from spectrinsic.render.passes import PassProgress, render_aovs, render_diagonal
from spectrinsic.render.result import RenderResult
from spectrinsic.render.scene_render import batch_seeds, image_noise, merge_batches, render_scene
from spectrinsic.render.settings import RenderSettings
from spectrinsic.render.single import resolve_integrator
from spectrinsic.render.translate import prepare_geometry
from spectrinsic.render.variants import choose_variant, variant_scope
from spectrinsic.scenes.model import Scene
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS, diagonal_values, get_sensors, responses

__all__ = [
    "LightTransport",
    "diagonal_mode_names",
    "light_band_means",
    "render_transport",
    "transport_result",
    "render_transport_batches",
]

logger = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False)
class LightTransport:
    """The per-light transport of one scene view, batch by batch (Eq. 1 of the module).

    Attributes
    ----------
    modes
        Diagonal render modes held (``"rgb3"``, ``"rgb6"``, ``"bands31"``).
    sensors
        mode -> registry name of its sensor set (channel k of the arrays is sensor k).
    batches
        One dict per independent batch: mode -> ``(L, H, W, K)`` float32 ``T_lk``, the raw
        channels light l gives alone with the flat unit spectrum at power 1 (render units).
    seeds
        Sampler seed of each batch.
    spp
        Samples per pixel of each batch.
    max_depth
        Longest path of the passes.
    seconds
        Seconds of each Mitsuba pass, per mode, and under ``"single"`` those of the traversals
        carrying every mode at once (empty when read from a file).
    """

    modes: tuple[str, ...]
    sensors: dict[str, str]
    batches: tuple[dict[str, np.ndarray], ...] = field(repr=False)
    seeds: tuple[int, ...]
    spp: int
    max_depth: int
    seconds: dict[str, tuple[float, ...]] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if not self.batches or len(self.batches) != len(self.seeds):
            raise RenderError(f"transport: {len(self.batches)} batches for {len(self.seeds)} seeds")
        shapes = {a.shape[:3] for b in self.batches for a in b.values()}
        if len(shapes) != 1 or any(set(b) != set(self.modes) for b in self.batches):
            raise RenderError(
                f"transport: every batch must hold modes {list(self.modes)} with "
                f"one (lights, height, width); got shapes {sorted(shapes)}"
            )

    @property
    def n_lights(self) -> int:
        """Number of lights L."""
        return int(next(iter(self.batches[0].values())).shape[0])

    @property
    def shape(self) -> tuple[int, int]:
        """``(H, W)`` of the images."""
        first = next(iter(self.batches[0].values()))
        return int(first.shape[1]), int(first.shape[2])


def diagonal_mode_names(modes: Iterable[str]) -> tuple[str, ...]:
    """The diagonal (relightable) modes among *modes*, in order, validated."""
    return tuple(m for m in dict.fromkeys(modes) if get_mode(m).kind == "diagonal")


def light_band_means(scene: Scene, sensors: str, *, data_dir: str | None = None) -> np.ndarray:
    """``(L, K)`` float64 ``ē_lk = power_l ∫L_l S_k dλ / ∫S_k dλ`` of the scene's lights
    (Eq. 1), on the 1 nm CIE grid; the flat unit spectrum gives 1 in every channel.

    >>> from spectrinsic.scenes.model import Camera, Light, Scene
    >>> lamp = Light("point", "flat:1", 2.0)
    >>> s = Scene("s", (), (), (lamp,), Camera((0, 0, 1), (0, 0, 0)))
    >>> float(light_band_means(s, "bands:31@400-700").round(12).max())
    2.0
    """
    wl = COLORIMETRIC_WAVELENGTHS
    return diagonal_values(
        light_spectra(scene, wl, data_dir=data_dir),
        get_sensors(sensors, data_dir=data_dir).on(wl),
        wl,
    )


def _unit_values(scene: Scene, sensors: str, data_dir: str | None) -> ChannelValues:
    """Material values of the scene and, for every light, the flat unit spectrum at power 1
    (``∫S_k dλ``, what :func:`channel_values` gives a light of spectrum 1)."""
    wl = COLORIMETRIC_WAVELENGTHS
    curves = get_sensors(sensors, data_dir=data_dir).on(wl)
    flat = responses(np.ones(wl.size), curves, wl)
    materials = channel_values(
        scene, get_sensors(sensors, data_dir=data_dir), data_dir=data_dir
    ).materials
    return ChannelValues(materials=materials, lights=np.tile(flat, (len(scene.lights), 1)))


def render_transport(
    scene: Scene,
    settings: RenderSettings,
    *,
    seed: int,
    progress: PassProgress | None = None,
    data_dir: str | None = None,
) -> tuple[dict[str, np.ndarray], dict[str, tuple[float, ...]]]:
    """One batch of transport: mode -> ``(L, H, W, K)`` float32 ``T_lk`` and the pass seconds.

    Each light is rendered alone (its own scene load) with the flat unit spectrum at power 1
    and the scene's material values, seed *seed*, ``settings.batch_spp`` samples, depth
    ``settings.max_depth`` and Russian roulette off, so its paths are those of a per-light
    render with the same settings; only the diagonal ones of ``settings.modes`` are rendered.
    """
    modes, spp, max_depth, variant = (
        settings.modes,
        settings.batch_spp,
        settings.max_depth,
        settings.variant,
    )
    names = diagonal_mode_names(modes)
    if not names:
        raise SceneError(
            f"modes {list(modes)}: the transport needs a diagonal mode (rgb3, rgb6, bands31)"
        )
    if not scene.lights:
        raise SceneError(f"scene {scene.name!r} has no lights: no transport to render")
    sensors = [get_mode(m).sensors for m in names]
    values = [_unit_values(scene, s, data_dir) for s in sensors]
    geometry = prepare_geometry(scene)
    chosen = choose_variant("rgb", variant)
    per_light: list[list[np.ndarray]] = [[] for _ in names]
    seconds: dict[str, list[float]] = {m: [] for m in names}
    with variant_scope(chosen):  # one scope: switching variants reloads Mitsuba's modules
        for j in range(len(scene.lights)):
            outputs = render_diagonal(
                scene,
                values,
                spp=spp,
                seed=seed,
                max_depth=max_depth,
                active_lights=[j],
                variant=chosen,
                progress=progress,
                geometry=geometry,
            )
            for i, out in enumerate(outputs):
                per_light[i].append(out.image)
                seconds[names[i]].extend(out.seconds)
    return (
        {m: np.stack(p).astype(np.float32) for m, p in zip(names, per_light, strict=True)},
        {m: tuple(s) for m, s in seconds.items()},
    )


def transport_result(
    batch: Mapping[str, np.ndarray],
    scene: Scene,
    *,
    seed: int,
    spp: int,
    meta: Mapping[str, Any] | None = None,
    data_dir: str | None = None,
) -> RenderResult:
    """The render of one batch under the scene's light spectra and powers, from its transport.

    Per mode: each light's raw channels ``T_l ∘ ē_l`` (float32, as Mitsuba returns a pass),
    their float64 sum as ``raw`` (as :func:`~spectrinsic.render.render_scene` sums per-light
    renders), and the XYZ of both through the mode's matrix for this scene's lights. *meta*
    (a render's metadata) is kept, with the modes, sensors, XYZ matrices, seed and spp set.
    """
    raw: dict[str, np.ndarray] = {}
    images: dict[str, np.ndarray] = {}
    per_light: list[dict[str, np.ndarray]] = [{} for _ in scene.lights]
    matrices: dict[str, np.ndarray] = {}
    for mode, t in batch.items():
        if t.shape[0] != len(scene.lights):
            raise RenderError(
                f"transport of {mode!r} has {t.shape[0]} lights; the scene has {len(scene.lights)}"
            )
        means = light_band_means(scene, get_mode(mode).sensors, data_dir=data_dir)
        parts = [
            (np.asarray(t[j], np.float64) * means[j]).astype(np.float32) for j in range(t.shape[0])
        ]
        raw[mode] = np.sum(parts, axis=0, dtype=np.float64).astype(np.float32)
        matrices[mode] = to_xyz_matrix(get_mode(mode), scene, data_dir=data_dir)
        images[mode] = raw_to_xyz(raw[mode], matrices[mode])
        for j, part in enumerate(parts):
            per_light[j][mode] = raw_to_xyz(part, matrices[mode])
    out_meta: dict[str, Any] = dict(meta or {})
    out_meta.update(
        seed=int(seed),
        spp=int(spp),
        modes=list(batch),
        per_light=True,
        per_light_modes=list(batch),
        sensors={m: get_mode(m).sensors for m in batch},
        to_xyz={m: np.asarray(v).tolist() for m, v in matrices.items()},
    )
    out_meta.setdefault("timings", {})
    return RenderResult(images=images, raw=raw, per_light=tuple(per_light), meta=out_meta)


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
    for key in ("sensors", "to_xyz"):
        meta[key] = {**other.meta.get(key, {}), **diagonal.meta[key]}
    meta["timings"] = {**other.meta.get("timings", {}), **diagonal.meta["timings"]}
    meta.update(
        modes=list(order),
        per_light=True,
        per_light_modes=diagonal.meta["per_light_modes"],
        variants={**other.meta.get("variants", {}), **diagonal.meta.get("variants", {})},
    )
    return RenderResult(
        images={m: {**other.images, **diagonal.images}[m] for m in order},
        raw={
            m: {**other.raw, **diagonal.raw}[m] for m in order if m in {**other.raw, **diagonal.raw}
        },
        per_light=diagonal.per_light,
        direct=dict(other.direct),
        aovs=dict(aovs),
        meta=meta,
    )


def _traversal_batch(
    scene: Scene,
    settings: RenderSettings,
    seed: int,
    *,
    progress: PassProgress | None,
    data_dir: str | None,
) -> tuple[dict[str, np.ndarray], RenderResult]:
    """:func:`_batch` from one single traversal (:mod:`spectrinsic.render.single`), which
    already splits every band by light: its transport ``T'_lk`` (per unit channel emission
    ``E_lk``) times the flat unit spectrum's channel values ``∫S_k dλ`` is Eq. 1's ``T_lk``,
    so no per-light pass is rendered. The same call renders the other modes and the AOVs from
    the same pixel samples, as a direct render with ``integrator="single"`` does, so a relit
    sample equals that render to float rounding."""
    names = diagonal_mode_names(settings.modes)
    direct = (
        tuple(m for m in settings.modes if m not in names)
        if settings.direct is True
        else tuple(m for m in settings.direct or () if m not in names)
    )
    render = render_scene(
        scene,
        settings.with_options(per_light=False, share_mode=None, direct=direct, aovs=True),
        seed=seed,
        progress=progress,
        data_dir=data_dir,
    )
    flat = {m: _unit_values(scene, get_mode(m).sensors, data_dir).lights for m in names}
    t = {
        m: (render.transport[m].astype(np.float64) * flat[m][:, None, None, :]).astype(np.float32)
        for m in names
    }
    base = {
        "max_depth": int(settings.max_depth),
        "variants": {m: render.meta["variants"][m] for m in names},
        "timings": {m: render.meta["timings"][m] for m in names},
    }
    diagonal = transport_result(
        t, scene, seed=seed, spp=settings.batch_spp, meta=base, data_dir=data_dir
    )
    others = [m for m in dict.fromkeys(settings.modes) if m not in names]
    other = (
        replace(
            render,
            images={m: render.images[m] for m in others},
            raw={m: render.raw[m] for m in others},
            transport={},
        )
        if others
        else None
    )
    return t, _join(diagonal, other, render.aovs, list(dict.fromkeys(settings.modes)))


def _batch(
    scene: Scene,
    settings: RenderSettings,
    seed: int,
    *,
    progress: PassProgress | None,
    data_dir: str | None,
) -> tuple[dict[str, np.ndarray], RenderResult]:
    """Transport of one batch and the sample's render of that batch (other modes rendered
    directly with every light on, the AOVs from the same pixel samples): from the single
    traversal where it runs (:func:`_traversal_batch`), else one set of passes per light."""
    if resolve_integrator(settings.integrator, settings.variant) == "single":
        return _traversal_batch(scene, settings, seed, progress=progress, data_dir=data_dir)
    modes, spp, variant = settings.modes, settings.batch_spp, settings.variant
    names = diagonal_mode_names(modes)
    others = tuple(m for m in dict.fromkeys(modes) if m not in names)
    t, seconds = render_transport(scene, settings, seed=seed, progress=progress, data_dir=data_dir)
    rgb = choose_variant("rgb", variant)
    timing = {
        m: {"passes": len(s), "seconds": float(sum(s)), "per_pass": list(s)}
        for m, s in seconds.items()
    }
    base = {
        "max_depth": int(settings.max_depth),
        "timings": timing,
        "variants": dict.fromkeys(names, rgb),
    }
    diagonal = transport_result(t, scene, seed=seed, spp=spp, meta=base, data_dir=data_dir)
    other = None
    if others:
        direct = (
            settings.direct
            if isinstance(settings.direct, bool)
            else tuple(m for m in settings.direct if m in others)
        )
        other = render_scene(
            scene,
            settings.with_options(
                modes=others, per_light=False, share_mode=None, direct=direct, aovs=True
            ),
            seed=seed,
            progress=progress,
            data_dir=data_dir,
        )
        aovs = other.aovs
    else:
        aovs, aov_seconds = render_aovs(
            scene, spp=spp, seed=seed, variant=variant, progress=progress
        )
        timing["aovs"] = {
            "passes": len(aov_seconds),
            "seconds": float(sum(aov_seconds)),
            "per_pass": list(aov_seconds),
        }
    return t, _join(diagonal, other, aovs, list(dict.fromkeys(modes)))


def render_transport_batches(
    scene: Scene,
    settings: RenderSettings,
    *,
    seed: int,
    progress: PassProgress | None = None,
    data_dir: str | None = None,
) -> tuple[LightTransport, RenderResult]:
    """The sample's transport and its render, as :func:`~spectrinsic.render.render_batches`.

    The diagonal modes of every batch are composed from the transport with the scene's own
    spectra (:func:`transport_result`), so relighting the sample with those spectra gives it
    back exactly; the other modes (the spectral reference) are rendered directly with every
    light on, with a direct-only render when ``settings.direct``. Batches, seeds and adaptive
    sampling (``settings.noise_target``, ``settings.max_batches``) follow
    :func:`~spectrinsic.render.render_batches`; ``per_light`` and ``share_mode`` do not apply
    (the transport is per light already).
    """
    modes, batches, noise_target = settings.modes, settings.batches, settings.noise_target
    if settings.direct and not [m for m in modes if m not in diagonal_mode_names(modes)]:
        raise SceneError(
            "direct-only renders with the transport need the 'spectral' mode "
            "(the diagonal modes are composed, not rendered with every light)"
        )
    cap = max(batches, settings.max_batches if settings.max_batches is not None else 4 * batches)
    seeds = batch_seeds(seed, cap if noise_target is not None else batches)
    done = [
        _batch(scene, settings, s, progress=progress, data_dir=data_dir) for s in seeds[:batches]
    ]
    reached = image_noise([r for _, r in done]) if noise_target is not None else None
    while (
        reached is not None
        and noise_target is not None
        and reached > noise_target
        and len(done) < cap
    ):
        done.append(_batch(scene, settings, seeds[len(done)], progress=progress, data_dir=data_dir))
        reached = image_noise([r for _, r in done])
    merged = merge_batches([r for _, r in done])
    if noise_target is not None:
        merged.meta["noise_target"] = {
            "target": float(noise_target),
            "reached": reached,
            "max_batches": cap,
        }
    names = diagonal_mode_names(modes)
    seconds = {
        m: tuple(x for r in done for x in r[1].meta["timings"][m]["per_pass"])
        for m in (*names, "single")
        if m in done[0][1].meta["timings"]
    }
    transport = LightTransport(
        modes=names,
        sensors={m: get_mode(m).sensors for m in names},
        batches=tuple(t for t, _ in done),
        seeds=tuple(int(s) for s in seeds[: len(done)]),
        spp=int(settings.batch_spp),
        max_depth=int(settings.max_depth),
        seconds=seconds,
    )
    merged.meta["transport"] = {"modes": list(names), "batches": len(done)}
    logger.debug(
        "transport of %s: %d light(s), %d batch(es)", scene.name, transport.n_lights, len(done)
    )
    return transport, merged
