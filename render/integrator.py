"""One path traversal for every band of every diagonal mode, split by light (issue 20).

Today's diagonal modes render ⌈K/3⌉ RGB passes that trace identical paths (common random
numbers) and differ only in the channel values of materials and lights (Eq. 5.2). A Lambertian
vertex multiplies the throughput by its material's band albedo ρ_k and a light adds its band
value E_k; neither changes the path. So one traversal can carry all K bands at once:
:class:`BandPath` (built by :func:`band_path_class`) is Mitsuba's ``path`` integrator
(``src/integrators/path.cpp``: emitter hits and next-event estimation with the same power-
heuristic MIS, the same sampler calls in the same order) written in Python on Dr.Jit, whose
throughput is a list of K band products gathered from a per-material table, and whose
contributions go to one accumulator per (light, band).

The scene is loaded with white Lambertian surfaces (area-light shapes black) and unit white
emitters, so Mitsuba's own BSDF and emitter sampling give the band-independent factors
(cosine, pdfs, visibility, spot falloff); the integrator multiplies each by
``ρ[material(shape), k]`` along the path. Its output is the **light transport** of each light
for unit emission, ``T_{l,k}`` per pixel, ``(H, W, L·K)``; the K-channel image is
``Σ_l E_{l,k} T_{l,k}``, equal to the diagonal passes' image to float rounding (same seed, spp
and paths), and each light's share is exact: the per-light images sum to the total.

Material and emitter indices come from Mitsuba's registry ids of ``si.shape`` and
``ds.emitter`` (``dr.reinterpret_array``), mapped through lookup tables built after loading.
Tables are Dr.Jit arrays, not literals, so the compiled kernel is reused for every scene with
the same number of bands and lights.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from spectrinsic.errors import RenderError
from spectrinsic.render.textures import (
    TextureTables,
    shape_id_table,
    texel_of,
    texture_lookups,
)
from spectrinsic.render.variants import import_mitsuba

__all__ = [
    "INTEGRATOR_NAME",
    "BandTables",
    "band_path_class",
    "band_path",
    "transport_channels",
    "first_hit_channels",
]

#: Name the integrator is registered under (``mi.load_dict({"type": INTEGRATOR_NAME})``).
INTEGRATOR_NAME = "spectrinsic_bandpath"


@dataclass(frozen=True, eq=False)
class BandTables:
    """What the integrator gathers from, built for one loaded scene.

    Attributes
    ----------
    albedo
        ``(R, K)`` float band albedos per table row; the last row is black (area-light shapes
        and anything unknown).
    shape_rows
        ``{Mitsuba shape id (str): row}`` for every BSDF-carrying shape.
    emitter_lights
        ``{Mitsuba emitter registry id (int): light index}``.
    n_lights
        L, the number of accumulator groups.
    shape_surfaces
        ``{Mitsuba shape id: surface index}`` for the first-hit maps (coverage one-hot per
        surface, ray distance, shading normal), empty when not wanted.
    textures
        The texel tables of textured meshes (:mod:`~spectrinsic.render.textures`), or ``None``.
    shape_textures
        ``{Mitsuba shape id: texture slot}`` of textured shapes.
    """

    albedo: np.ndarray
    shape_rows: dict[str, int]
    emitter_lights: dict[int, int]
    n_lights: int
    shape_surfaces: dict[str, int] = field(default_factory=dict)
    textures: TextureTables | None = None
    shape_textures: dict[str, int] = field(default_factory=dict)


def transport_channels(n_lights: int, n_bands: int) -> list[str]:
    """AOV names of the transport channels, light-major: ``t<l>_<k>``."""
    return [f"t{j:02d}_{k:02d}" for j in range(n_lights) for k in range(n_bands)]


def first_hit_channels(n_surfaces: int, n_texcols: int = 0) -> list[str]:
    """AOV names of the first-hit maps after the transport: the coverage of each surface, the
    texel weights of each textured coverage column (:class:`TextureTables`), the ray distance
    and the shading normal (as Mitsuba's ``aov`` integrator's ``depth`` and ``sh_normal``);
    none without surfaces."""
    if n_surfaces == 0:
        return []
    cover = [f"cov{i:03d}" for i in range(n_surfaces)] + [f"tex{g:03d}" for g in range(n_texcols)]
    return [*cover, "depth", "normal.x", "normal.y", "normal.z"]


def _mis_weight(dr: Any, mi: Any, pdf_a: Any, pdf_b: Any) -> Any:
    """Power heuristic exactly as ``path.cpp``'s ``mis_weight``."""
    a, b = pdf_a * pdf_a, pdf_b * pdf_b
    w = a / (a + b)
    return dr.detach(dr.select(dr.isfinite(w), w, mi.Float(0.0)))


def _band_max(dr: Any, bands: Sequence) -> Any:
    """Largest band value per lane (a balanced tree of ``dr.maximum``)."""
    values = list(bands)
    while len(values) > 1:
        values = [
            dr.maximum(values[i], values[i + 1]) if i + 1 < len(values) else values[i]
            for i in range(0, len(values), 2)
        ]
    return values[0]


def _lookups(mi: Any, dr: Any, scene: Any, tables: BandTables) -> tuple[Any, Any, Any, Any]:
    """Dr.Jit arrays of the band albedos, shape id -> table row, emitter id -> light and shape
    id -> surface (``len(shape_surfaces)`` where none)."""
    albedo = np.asarray(tables.albedo, np.float32)
    black, none = albedo.shape[0] - 1, len(tables.shape_surfaces)
    rows = shape_id_table(mi, dr, scene, tables.shape_rows, black)
    surfaces = shape_id_table(mi, dr, scene, tables.shape_surfaces, none)
    lights = np.zeros(max(tables.emitter_lights, default=0) + 1, np.uint32)
    for eid, light in tables.emitter_lights.items():
        lights[eid] = light
    return mi.Float(albedo.ravel()), mi.UInt32(rows), mi.UInt32(lights), mi.UInt32(surfaces)


class _Kernel:
    """The loop of ``path.cpp`` on band throughputs; *it* is the integrator (depths, sizes,
    lookups). Each method is one step of the loop body, in ``path.cpp``'s order, so the
    sampler is called exactly as there and the paths are the same."""

    def __init__(self, mi: Any, dr: Any, it: Any, scene: Any) -> None:
        self.mi, self.dr, self.it, self.scene = mi, dr, it, scene

    def light_of(self, emitter: Any, mask: Any) -> Any:
        return self.dr.gather(
            self.mi.UInt32,
            self.it.emitter_lut,
            self.dr.reinterpret_array(self.mi.UInt32, emitter),
            mask,
        )

    def deposit(self, acc: list, light: Any, weight: Any, bands: Sequence, mask: Any) -> list:
        """``acc[l·K + k] += bands[k]·weight`` on the lanes whose light is l."""
        k, out = self.it.n_bands, list(acc)
        for j in range(self.it.n_lights):
            w = self.dr.select(mask & (light == j), weight, 0.0)
            for b in range(k):
                out[j * k + b] = self.dr.fma(bands[b], w, out[j * k + b])
        return out

    def emitter_hit(
        self, si: Any, prev_si: Any, prev_pdf: Any, prev_delta: Any
    ) -> tuple[Any, Any, Any]:
        """Light, weight (radiance x BSDF-sampling MIS weight) and mask of an emitter hit."""
        mi, dr = self.mi, self.dr
        emitter = si.emitter(self.scene)
        hit = emitter != None  # noqa: E711 (a Dr.Jit pointer array, compared lane by lane)
        ds = mi.DirectionSample3f(self.scene, si=si, ref=prev_si)
        em_pdf = dr.select(
            prev_delta, 0.0, self.scene.pdf_emitter_direction(prev_si, ds, ~prev_delta)
        )
        radiance = emitter.eval(si, (prev_pdf > 0.0) & hit)[0]
        return self.light_of(emitter, hit), radiance * _mis_weight(dr, mi, prev_pdf, em_pdf), hit

    def vertex(self, sampler: Any, si: Any, bsdf: Any, active_next: Any) -> tuple:
        """Emitter sample, then BSDF evaluation and sample (``eval_pdf_sample``)."""
        mi, dr = self.mi, self.dr
        active_em = active_next & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth)
        ds, em_weight = self.scene.sample_emitter_direction(si, sampler.next_2d(), True, active_em)
        active_em &= ds.pdf != 0.0
        sample_1, sample_2 = sampler.next_1d(), sampler.next_2d()
        bsdf_val, bsdf_pdf, bsdf_sample, bsdf_weight = bsdf.eval_pdf_sample(
            mi.BSDFContext(), si, si.to_local(ds.d), sample_1, sample_2
        )
        mis_em = dr.select(ds.delta, 1.0, _mis_weight(dr, mi, ds.pdf, bsdf_pdf))
        nee = bsdf_val[0] * em_weight[0] * mis_em
        return self.light_of(ds.emitter, active_em), nee, active_em, bsdf_sample, bsdf_weight[0]

    def albedo(self, si: Any) -> list:
        """ρ_k of the material of the shape hit (the black row elsewhere), or of the nearest
        texel on a textured shape."""
        mi, dr, k = self.mi, self.dr, self.it.n_bands
        valid = si.is_valid()
        row = dr.gather(
            mi.UInt32, self.it.shape_lut, dr.reinterpret_array(mi.UInt32, si.shape), valid
        )
        rho = [dr.gather(mi.Float, self.it.albedo, row * k + b, valid) for b in range(k)]
        if not self.it.n_texcols:
            return rho
        texel, textured = texel_of(mi, dr, self.it, si)
        return [
            dr.select(
                textured, dr.gather(mi.Float, self.it.texel_albedo, texel * k + b, textured), r
            )
            for b, r in enumerate(rho)
        ]

    def first_hit(self, si: Any, depth: Any, first: tuple) -> tuple:
        """Surface index, ray distance and shading normal of the camera ray's hit."""
        mi, dr = self.mi, self.dr
        if not self.it.n_surfaces:
            return first
        now, valid = depth == 0, si.is_valid()
        surface = dr.gather(
            mi.UInt32, self.it.surface_lut, dr.reinterpret_array(mi.UInt32, si.shape), valid
        )
        surface = dr.select(valid, surface, self.it.n_surfaces)
        distance = dr.select(valid, si.t, 0.0)
        normal = dr.select(valid, si.sh_frame.n, mi.Vector3f(0.0))
        hit = (surface, distance, normal) + (
            texel_of(mi, dr, self.it, si) if self.it.n_texcols else ()
        )
        return tuple(dr.select(now, h, f) for h, f in zip(hit, first, strict=True))

    def first_state(self) -> tuple:
        """The first-hit state before any hit: no surface, no distance, no normal (no texel)."""
        mi = self.mi
        first = (mi.UInt32(self.it.n_surfaces), mi.Float(0.0), mi.Vector3f(0.0))
        return first + ((mi.UInt32(0), mi.Bool(False)) if self.it.n_texcols else ())

    def first_maps(self, first: tuple) -> list:
        """The first-hit channels (:func:`first_hit_channels`) of the final first-hit state."""
        mi, dr, n = self.mi, self.dr, self.it.n_surfaces
        if not n:
            return []
        surface, distance, normal = first[:3]
        out = [dr.select(surface == i, 1.0, 0.0) for i in range(n)]
        if self.it.n_texcols:
            texel, textured = first[3:]
            g = self.it.n_texcols
            out += [
                dr.select(
                    textured,
                    dr.gather(mi.Float, self.it.texel_weights, texel * g + c, textured),
                    0.0,
                )
                for c in range(g)
            ]
        return out + [distance, normal.x, normal.y, normal.z]

    def path_state(self, sampler: Any, ray: Any) -> tuple:
        """The start of a loop's state: sampler, ray, depth 0, throughput 1 and K band
        throughputs 1, K·L accumulators 0, and the previous vertex (none, pdf 1, delta)."""
        mi, dr, k = self.mi, self.dr, self.it.n_bands
        return (
            sampler,
            mi.Ray3f(ray),
            mi.UInt32(0),
            mi.Float(1.0),
            [mi.Float(1.0) for _ in range(k)],
            [mi.Float(0.0) for _ in range(k * self.it.n_lights)],
            dr.zeros(mi.Interaction3f),
            mi.Float(1.0),
            mi.Bool(True),
        )

    def next_state(
        self,
        sampler: Any,
        si: Any,
        bsdf_sample: Any,
        bsdf_weight: Any,
        depth: Any,
        beta: Any,
        bands: list,
        acc: list,
    ) -> tuple[tuple, Any]:
        """Step to the next vertex (bands already scaled here): the state every loop carries
        (:meth:`path_state`'s fields: ray, depth, throughput, previous vertex, its pdf and delta
        flag) and the go-on flag. Russian roulette on the largest band (``path.cpp``: largest
        channel); off when ``rr_depth`` > ``max_depth``, but its sample is drawn either way."""
        mi, dr = self.mi, self.dr
        ray = si.spawn_ray(si.to_world(bsdf_sample.wo))
        depth = dr.select(si.is_valid(), depth + 1, depth)
        beta = beta * bsdf_weight
        throughput_max = beta * _band_max(dr, bands)
        rr_prob = dr.minimum(throughput_max, 0.95)
        rr_active = depth >= self.it.rr_depth
        rr_continue = sampler.next_1d() < rr_prob
        beta = dr.select(rr_active, beta * dr.rcp(dr.detach(rr_prob)), beta)
        go_on = (~rr_active | rr_continue) & (throughput_max != 0.0)
        delta = mi.has_flag(bsdf_sample.sampled_type, mi.BSDFFlags.Delta)
        state = (sampler, ray, depth, beta, bands, acc, mi.Interaction3f(si), bsdf_sample.pdf)
        return (*state, delta), go_on

    def body(
        self,
        sampler: Any,
        ray: Any,
        depth: Any,
        beta: Any,
        bands: list,
        acc: list,
        prev_si: Any,
        prev_pdf: Any,
        prev_delta: Any,
        first: tuple,
        alive: Any,
    ) -> tuple:
        mi = self.mi
        si = self.scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=depth == 0)
        first = self.first_hit(si, depth, first)
        light, weight, hit = self.emitter_hit(si, prev_si, prev_pdf, prev_delta)
        acc = self.deposit(acc, light, beta * weight, bands, hit)
        active_next = (depth + 1 < self.it.max_depth) & si.is_valid()
        light, nee, active_em, bsdf_sample, bsdf_weight = self.vertex(
            sampler, si, si.bsdf(ray), active_next
        )
        bands = [b * rho for b, rho in zip(bands, self.albedo(si), strict=True)]
        acc = self.deposit(acc, light, beta * nee, bands, active_em)
        state, go_on = self.next_state(
            sampler, si, bsdf_sample, bsdf_weight, depth, beta, bands, acc
        )
        return (*state, first, active_next & go_on)

    def run(self, sampler: Any, ray: Any, active: Any) -> list:
        """The K·L accumulators of one wavefront of camera rays, then the first-hit maps
        (:func:`first_hit_channels`)."""
        state = (*self.path_state(sampler, ray), self.first_state(), self.mi.Bool(active))
        state = self.dr.while_loop(
            state, lambda *s: s[-1], self.body, label="spectrinsic band path"
        )
        return list(state[5]) + self.first_maps(state[9])


def _check_fit(it: Any, tables: BandTables) -> None:
    """Raise if *tables* do not fit integrator *it* (bands, lights, surfaces, texture columns)."""
    shape = np.shape(tables.albedo)
    n_texcols = 0 if tables.textures is None else len(tables.textures.columns)
    if (
        len(shape) != 2
        or shape[1] != it.n_bands
        or tables.n_lights != it.n_lights
        or len(tables.shape_surfaces) != it.n_surfaces
        or n_texcols != it.n_texcols
    ):
        raise RenderError(
            f"band tables {shape} for {tables.n_lights} lights and {n_texcols} texture columns "
            f"do not fit an integrator of {it.n_bands} bands, {it.n_lights} lights and "
            f"{it.n_texcols} texture columns"
        )


@functools.cache
def band_path_class(variant: str) -> type:
    """The :class:`BandPath` integrator class for the active *variant* (defined per variant,
    since ``mi.SamplingIntegrator`` is the variant's), registered as :data:`INTEGRATOR_NAME`.

    Properties: ``max_depth``, ``rr_depth`` (as ``path``), ``n_bands`` (K), ``n_lights`` (L).
    Its AOVs are the L·K transports (:func:`transport_channels`); its RGB output is zero.
    """
    mi = import_mitsuba()
    if mi.variant() != variant:
        raise RenderError(f"band_path_class({variant!r}) called while {mi.variant()!r} is active")
    import drjit as dr

    class BandPath(mi.SamplingIntegrator):  # type: ignore[misc, name-defined]
        """``path`` with K band throughputs and L·K per-light accumulators (module docstring)."""

        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.max_depth = int(props.get("max_depth", 8))
            self.rr_depth = int(props.get("rr_depth", self.max_depth + 1))
            self.n_bands = int(props.get("n_bands", 3))
            self.n_lights = int(props.get("n_lights", 1))
            self.n_surfaces = int(props.get("n_surfaces", 0))
            self.n_texcols = int(props.get("n_texcols", 0))
            self.surface_lut = mi.UInt32(np.zeros(1, np.uint32))
            self.albedo = mi.Float(np.zeros(self.n_bands, np.float32))
            self.shape_lut = mi.UInt32(np.zeros(1, np.uint32))
            self.emitter_lut = mi.UInt32(np.zeros(1, np.uint32))

        def set_tables(self, scene: Any, tables: BandTables) -> None:
            """Point the lookups at *tables* for the loaded *scene* (no recompilation)."""
            _check_fit(self, tables)
            self.albedo, self.shape_lut, self.emitter_lut, self.surface_lut = _lookups(
                mi, dr, scene, tables
            )
            lookups = texture_lookups(mi, dr, scene, tables.textures, tables.shape_textures)
            self.slot_lut, self.tex_widths, self.tex_heights, self.tex_offsets = lookups[:4]
            self.texel_albedo, self.texel_weights = lookups[4:]

        def aov_names(self) -> list[str]:
            return transport_channels(self.n_lights, self.n_bands) + first_hit_channels(
                self.n_surfaces, self.n_texcols
            )

        def sample(
            self, scene: Any, sampler: Any, ray: Any, medium: Any = None, active: Any = True
        ) -> tuple:
            return (
                mi.Spectrum(0.0),
                mi.Bool(True),
                _Kernel(mi, dr, self, scene).run(sampler, ray, active),
            )

        def to_string(self) -> str:
            return f"BandPath[max_depth={self.max_depth}, n_bands={self.n_bands}, n_lights={self.n_lights}]"

    mi.register_integrator(INTEGRATOR_NAME, lambda props: BandPath(props))
    return BandPath


def band_path(
    mi: Any, *, max_depth: int, n_bands: int, n_lights: int, n_surfaces: int = 0, n_texcols: int = 0
) -> Any:
    """A :class:`BandPath` instance for the active variant (rr off: ``rr_depth`` > ``max_depth``),
    with first-hit maps of *n_surfaces* surfaces if not 0 and textures of *n_texcols* coverage
    columns (:class:`TextureTables`) if not 0."""
    band_path_class(mi.variant())
    return mi.load_dict(
        {
            "type": INTEGRATOR_NAME,
            "max_depth": int(max_depth),
            "rr_depth": int(max_depth) + 1,
            "n_bands": int(n_bands),
            "n_lights": int(n_lights),
            "n_surfaces": int(n_surfaces),
            "n_texcols": int(n_texcols),
        }
    )
