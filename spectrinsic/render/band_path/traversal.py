"""Every diagonal mode of one scene in a single path traversal, split by light.

The counterpart of :func:`spectrinsic.render.passes.render_diagonal` (⌈K/3⌉ RGB passes per
mode, one scene per light subset) built on the band-path integrator of
:mod:`spectrinsic.render.band_path.integrator`: the bands of every value set are stacked into one table
(K = 3 + 6 + 31 = 40 for the default modes) and traced once, with every light on. Because the
passes trace identical paths (same seed and spp, Russian roulette off), the images are those of
the passes to float rounding; each light's image is its exact share of that render (the
per-light images sum to the total), not a separate render with the other lights removed.
The coverage, ids, depth and normals of :func:`~spectrinsic.render.passes.aovs.render_aovs` come
from the same traversal's camera rays (their first hits), so no coverage passes are needed.

Cost, measured on ``room-living__v1__two-colour-a`` at the default preset (256², 2 batches of
8 spp, 2 lights, 25 surfaces): see ``make bench`` (``bench_traversal.json``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ...errors import RenderError, SceneError, validate_choice
from ...scenes.envmaps import envmap_groups
from ...scenes.model import Scene
from ...spectra import get_sensors
from ..algebra.modes import ChannelValues, RenderMode, channel_values, get_mode
from ..algebra.shares import TransportOutput
from ..base import translate as tr
from ..base.aov_maps import assemble_aovs
from ..base.one_pass import DIRECT_DEPTH, PassOutput, check_scene_lights, timed_render
from ..base.plugins import hdr_film, path_integrator, rgb_spectrum
from ..base.surface_maps import map_scales
from ..base.textures import shape_slots, texture_tables
from ..base.variants import choose_variant, variant_scope
from ..result import METAL_WHITE, SPECULAR
from ..settings import DEFAULT_INTEGRATOR, INTEGRATORS, PassRequest
from .integrator import BandTables, band_path, first_hit_channels
from .kernel import GLASS_ROW, MIRROR_ROW

__all__ = [
    "SingleTraversal",
    "render_traversal",
    "render_jobs",
    "light_of_emitters",
    "resolve_integrator",
]


def resolve_integrator(name: str | None, variant: str | None = None) -> str:
    """*name* checked against :data:`~spectrinsic.render.settings.INTEGRATORS` (``None``:
    :data:`~spectrinsic.render.settings.DEFAULT_INTEGRATOR`); ``"passes"`` where the traversal
    does not run: on a scalar RGB variant of *variant* a Python integrator would run once per
    sample (a JIT one, LLVM or CUDA, traces it into one kernel)."""
    chosen = (
        DEFAULT_INTEGRATOR
        if name is None
        else validate_choice(name, INTEGRATORS, "integrator", error=RenderError)
    )
    if chosen == "passes" or not choose_variant("rgb", variant).startswith("scalar"):
        return chosen
    return "passes"


def light_of_emitters(mi: Any, loaded: Any) -> dict[int, int]:
    """``{emitter registry id: scene light index}`` of a scene translated by
    :func:`~spectrinsic.render.base.translate.scene_to_mitsuba` (ids ``light_<i>``; an area
    emitter is named by its rectangle)."""
    import drjit as dr

    emitters = list(loaded.emitters())
    if not emitters:
        return {}
    ids = np.array(dr.reinterpret_array(mi.UInt32, mi.EmitterPtr(emitters)), np.int64)
    out = {}
    for eid, emitter in zip(ids, emitters, strict=True):
        shape = emitter.get_shape()
        key = shape.id() if shape is not None else emitter.id()
        prefix = tr.light_key(0)[:-1]
        if not key.startswith(prefix) or not key[len(prefix) :].isdigit():
            raise RenderError(f"emitter {key!r} is not one of the scene's lights ({prefix}<i>)")
        out[int(eid)] = int(key[len(prefix) :])
    return out


def _tables(
    scene: Scene, value_sets: Sequence[ChannelValues], emitters: dict[int, int], aovs: bool
) -> BandTables:
    bands = np.concatenate([np.asarray(v.materials, float) for v in value_sets], axis=1)
    albedo = np.vstack([bands, np.zeros((1, bands.shape[1]))])  # last row: black
    surfaces = tr.surfaces(scene)
    rows = {s.key: s.material for s in surfaces if s.material >= 0}
    textures = texture_tables(scene, albedo[:-1])
    return BandTables(
        albedo=albedo,
        shape_rows=rows,
        emitter_lights=emitters,
        n_lights=len(scene.lights),
        shape_surfaces={s.key: i for i, s in enumerate(surfaces)} if aovs else {},
        textures=textures,
        shape_textures=shape_slots(textures, surfaces),
        light_channels=light_channels(scene, emitters),
        map_scales=map_scales(scene, surfaces),
        masks=any(m.maps is not None and m.maps.masked for m in scene.meshes),
        transmittance=_tint_table(scene, value_sets, "transmittance"),
        specular_reflectance=_tint_table(scene, value_sets, "specular_reflectance"),
    )


def _tint_table(scene: Scene, sets: Sequence[ChannelValues], key: str) -> np.ndarray | None:
    """``(M + 1, K)`` band values of every material's glass tint *key* (the value *sets*' side
    by side over bands; the last row, black, ones), or ``None`` without tinted glass."""
    if not any(m.tinted for m in scene.materials):
        return None
    tables = [getattr(v, key) for v in sets if getattr(v, key) is not None]
    if len(tables) != len(sets):
        raise RenderError(
            f"scene {scene.name!r} has tinted glass but its channel values carry no {key}"
        )
    table = np.concatenate(tables, axis=1)
    return np.vstack([table, np.ones((1, table.shape[1]))])


def light_channels(scene: Scene, emitters: dict[int, int]) -> tuple[tuple[int, int, int], ...]:
    """Per light, ``(light loaded as its emitter, RGB component, source)``: ``(j, 0, 0)``, or
    for a channel light of the scene's environment map i the one loaded ``envmap`` (the light
    *emitters* names), its channel and source 0 for the loaded map (i = 0), ``i`` for extra
    map ``i - 1`` (:func:`extra_maps`)."""
    loaded = set(emitters.values())
    maps = envmap_groups(scene)
    owner = next((j for j in maps[0].lights if j in loaded), 0) if maps else 0
    out = []
    for j, light in enumerate(scene.lights):
        source = next((i for i, g in enumerate(maps) if j in g.lights), None)
        if source is None:
            out.append((j, 0, 0))
        else:
            out.append((owner, int(light.channel), source))
    return tuple(out)


def extra_maps(mi: Any, scene: Scene) -> tuple[object, ...]:
    """Standalone Mitsuba ``envmap`` emitters of the scene's environment maps after the first
    (Mitsuba loads one per scene; the band path evaluates these itself)."""
    return tuple(
        mi.load_dict(tr.envmap_entry(mi, scene.lights[g.lights[0]]))
        for g in envmap_groups(scene)[1:]
    )


def _specular_table(scene: Scene, value_sets: Sequence[ChannelValues]) -> np.ndarray:
    """``(M + 1, N, K)`` band factors of the non-diffuse lobes of every material (the value
    sets' tables side by side over bands; the last row, black, all ones)."""
    tables = [np.asarray(v.specular, float) for v in value_sets if v.specular is not None]
    if len(tables) != len(value_sets):
        raise RenderError(
            f"scene {scene.name!r} has glossy materials but its channel values carry no specular tables"
        )
    table = np.concatenate(tables, axis=2)
    return np.concatenate([table, np.ones((1, *table.shape[1:]))], axis=0)


@dataclass(frozen=True)
class _Dims:
    """Image height and width, bands K, lights L, and whether the scene has glossy materials
    and metals."""

    h: int
    w: int
    #: Bands of each value set, traced side by side.
    widths: tuple[int, ...]
    n_lights: int
    glossy: bool
    #: Per albedo-table row (materials, then the black row): 0 with a diffuse lobe, else
    #: MIRROR_ROW or GLASS_ROW (the white-at-metal loop's rows; ``set_non_diffuse``).
    non_diffuse_rows: tuple[int, ...] = ()

    @property
    def metals(self) -> bool:
        return any(self.non_diffuse_rows)

    @property
    def n_bands(self) -> int:
        return sum(self.widths)

    def per_set(self, channels: np.ndarray) -> tuple[np.ndarray, ...]:
        """Light-major film *channels* ``(H, W, L·K)`` cut into each value set's contiguous
        ``(L, H, W, K_m)``: copies, so the film can be dropped at once."""
        per_light = channels.reshape(self.h, self.w, self.n_lights, self.n_bands)
        edges = np.cumsum([0, *self.widths])
        return tuple(
            np.ascontiguousarray(per_light[..., a:b].transpose(2, 0, 1, 3))
            for a, b in zip(edges[:-1], edges[1:], strict=True)
        )


@dataclass(frozen=True, eq=False)
class _Traced:
    """One traversal: each value set's transport ``(L, H, W, K_m)``, the parts of
    :data:`~spectrinsic.render.result.PARTS` it rendered (the same per value set; the first
    traversal only), the first-hit channels (first traversal with surfaces) and its seconds."""

    transport: tuple[np.ndarray, ...]
    parts: dict[str, tuple[np.ndarray, ...]]
    first: np.ndarray | None
    seconds: float


def _trace(
    mi: Any,
    loaded: Any,
    tables: BandTables,
    dims: _Dims,
    spec_table: np.ndarray | None,
    request: PassRequest,
    *,
    depth: int,
    first: bool,
) -> _Traced:
    """One traversal at path *depth*; the *first* one also takes the first-hit maps and, in
    scenes with metals, the white-at-metal radiance."""
    n_surfaces = len(tables.shape_surfaces) if first else 0
    metals = dims.metals and first
    n_texcols = 0 if tables.textures is None else len(tables.textures.columns)
    integrator = band_path(
        mi,
        max_depth=depth,
        n_bands=dims.n_bands,
        n_lights=dims.n_lights,
        n_surfaces=n_surfaces,
        n_texcols=n_texcols,
        gloss=dims.glossy,
        metals=metals,
        masks=tables.masks,
        tinted=tables.transmittance is not None,
    )
    integrator.set_tables(loaded, tables if n_surfaces else replace(tables, shape_surfaces={}))
    if spec_table is not None:
        integrator.set_specular(spec_table)
    if dims.glossy:  # every traversal: a glass row's null event is no mask cut-out
        integrator.set_non_diffuse(np.array(dims.non_diffuse_rows, np.uint32))
    n_t = dims.n_bands * dims.n_lights
    n_spec = n_t if dims.glossy else 0
    n_white = n_t if metals else 0
    n = n_t + n_spec + n_white + len(first_hit_channels(n_surfaces, n_texcols))
    film, dt = timed_render(mi, loaded, request, integrator)
    if film.shape[-1] < n:
        raise RenderError(f"band-path render returned {film.shape[-1]} channels; expected {n}+")
    image = film[..., film.shape[-1] - n :]  # the AOVs: after Mitsuba's own R, G, B

    end = n_t + n_spec + n_white
    parts = {}
    if dims.glossy and first:
        parts[SPECULAR] = dims.per_set(image[..., n_t : n_t + n_spec])
    if metals:
        parts[METAL_WHITE] = dims.per_set(image[..., n_t + n_spec : end])
    return _Traced(
        transport=dims.per_set(image[..., :n_t]),
        parts=parts,
        first=np.ascontiguousarray(image[..., end:]) if n_surfaces else None,
        seconds=dt,
    )


def _outputs(
    value_sets: Sequence[ChannelValues], traced: Sequence[_Traced], direct: bool
) -> list[TransportOutput]:
    """One :class:`TransportOutput` per value set from the traversals' cuts."""
    return [
        TransportOutput(
            transport=traced[0].transport[i],
            direct=traced[1].transport[i] if direct else None,
            emission=np.asarray(v.lights, float),
            parts={n: p[i] for n, p in traced[0].parts.items()},
        )
        for i, v in enumerate(value_sets)
    ]


def render_traversal(
    scene: Scene,
    value_sets: Sequence[ChannelValues],
    request: PassRequest,
    *,
    direct: bool = False,
    aovs: bool = False,
    crop: tuple[int, int, int, int] | None = None,
) -> tuple[list[TransportOutput], dict[str, np.ndarray], tuple[float, ...], str]:
    """Per-light band transport of every value set, in one traversal (two with *direct*).

    Parameters
    ----------
    value_sets
        Channel values (:func:`spectrinsic.render.algebra.modes.channel_values`) of each diagonal mode;
        their bands are traced together.
    request
        The batch's :class:`~spectrinsic.render.settings.PassRequest`.
    direct
        Also trace direct light only (path depth 2), for the energy ratio r of Eq. 5.8.
    aovs
        Also take coverage, ids, depth and normals from the camera rays' first hits, as
        :func:`~spectrinsic.render.passes.aovs.render_aovs` computes them from the same samples.
    crop
        ``(x, y, width, height)``: render only that window of the image
        (:func:`~spectrinsic.render.base.plugins.hdr_film`); every map is the window's.

    Returns
    -------
    outputs
        One :class:`TransportOutput` per value set.
    aov_maps
        The maps of :func:`~spectrinsic.render.passes.aovs.render_aovs` (empty without *aovs*).
    seconds
        Wall-clock seconds of each traversal.
    variant
        The Mitsuba variant used.
    """
    check_scene_lights(scene)
    if not value_sets:
        raise SceneError("render_traversal: expected at least one set of channel values")
    widths = [np.asarray(v.materials).shape[1] for v in value_sets]
    n_lights = len(scene.lights)
    chosen = choose_variant("rgb", request.variant)
    h, w = (
        (scene.camera.height, scene.camera.width) if crop is None else (int(crop[3]), int(crop[2]))
    )
    white = rgb_spectrum([1.0, 1.0, 1.0])
    glossy = any(m.glossy for m in scene.materials)
    with variant_scope(chosen) as mi:
        loaded = mi.load_dict(
            tr.scene_to_mitsuba(
                scene,
                materials=[white] * len(scene.materials),
                lights=[white] * n_lights,
                film=hdr_film(scene.camera.width, scene.camera.height, crop),
                integrator=path_integrator(request.max_depth),
                sample_count=request.batch_spp,
                geometry=request.geometry,
                white_metal=True,
            )
        )
        tables = _tables(scene, value_sets, light_of_emitters(mi, loaded), aovs)
        tables = replace(tables, extra_maps=extra_maps(mi, scene))
        non_diffuse_rows = tuple(
            GLASS_ROW if m.transmissive else MIRROR_ROW if m.non_diffuse else 0
            for m in scene.materials
        ) + (0,)
        dims = _Dims(h, w, tuple(widths), n_lights, glossy, non_diffuse_rows)
        spec_table = _specular_table(scene, value_sets) if glossy else None
        traced: list[_Traced] = []
        for depth in [request.max_depth] + ([DIRECT_DEPTH] if direct else []):
            first = not traced
            traced.append(
                _trace(mi, loaded, tables, dims, spec_table, request, depth=depth, first=first)
            )
    outputs = _outputs(value_sets, traced, direct)
    hits, aov_maps = traced[0].first, {}
    if aovs and hits is not None:  # coverage (and texture columns), ray distance, normal
        columns = None if tables.textures is None else tables.textures.columns
        cover, distance, normal = hits[..., :-4], hits[..., -4], hits[..., -3:]
        aov_maps = assemble_aovs(scene, tr.surfaces(scene), cover, distance, normal, columns)
    seconds = [t.seconds for t in traced]
    return outputs, aov_maps, tuple(seconds), chosen


@dataclass(frozen=True, eq=False)
class SingleTraversal:
    """The transport of every diagonal mode from :func:`render_jobs`, and its seconds."""

    transport: dict[str, TransportOutput]
    seconds: tuple[float, ...]
    #: First-hit maps (:func:`~spectrinsic.render.passes.aovs.render_aovs`'s), when asked for.
    aovs: dict[str, np.ndarray] = field(default_factory=dict)

    def per_light(self, part: str) -> dict[str, np.ndarray]:
        """Mode -> ``(L, H, W, K)`` per-light *part* (``"transport"`` or one of
        :data:`~spectrinsic.render.result.PARTS`); modes without it left out."""
        arrays = {
            n: t.transport if part == "transport" else t.parts.get(part)
            for n, t in self.transport.items()
        }
        return {n: a for n, a in arrays.items() if a is not None}


def render_jobs(
    scene: Scene,
    jobs: Sequence[tuple[Sequence[RenderMode], Sequence[int] | None, bool]],
    request: PassRequest,
    *,
    wanted: set[str],
    data_dir: str | None,
    aovs: bool = False,
) -> tuple[list[dict[str, PassOutput]], SingleTraversal]:
    """The diagonal images of every job ``(modes, lights or None for all, with_direct)`` from
    one traversal: each job's image of a mode is the sum of its lights' shares.

    Drop-in for rendering each job's diagonal modes with
    :func:`~spectrinsic.render.passes.render_diagonal`; a direct-only image is made for the
    modes in *wanted* of the jobs that ask for one. With *aovs*, the first-hit maps come from
    the same traversal (drop-in for :func:`~spectrinsic.render.passes.aovs.render_aovs`). The jobs
    must hold at least one diagonal mode, or none with *aovs*: one traversal then gives the
    first-hit maps alone (a textured scene's coverage, which the coverage passes cannot give).
    """
    diagonal = list(
        {m.name: m for modes, _, _ in jobs for m in modes if m.kind == "diagonal"}.values()
    )
    maps_only = not diagonal and aovs
    if maps_only:  # any mode's traversal gives the first-hit maps
        diagonal = [get_mode("rgb3")]
    want_direct = any(
        flag and m.name in wanted for modes, _, flag in jobs for m in modes if m.kind == "diagonal"
    )
    values = [
        channel_values(scene, get_sensors(m.sensors, data_dir=data_dir), data_dir=data_dir)
        for m in diagonal
    ]
    outs, aov_maps, seconds, chosen = render_traversal(
        scene, values, request, direct=want_direct, aovs=aovs
    )
    transport = {} if maps_only else {m.name: o for m, o in zip(diagonal, outs, strict=True)}
    parts = []
    for modes, group, flag in jobs:
        part = {}
        for m in (m for m in modes if m.kind == "diagonal"):
            t = transport[m.name]
            part[m.name] = PassOutput(
                image=t.image(group),
                direct=t.image(group, direct=True) if flag and m.name in wanted else None,
                seconds=(),
                variant=chosen,
            )
        parts.append(part)
    return parts, SingleTraversal(transport, seconds, aov_maps)
