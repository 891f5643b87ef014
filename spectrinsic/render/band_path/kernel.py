"""The one band-path loop: Mitsuba's ``path`` on K band throughputs, its features chosen when traced.

:class:`BandKernel` is the loop of Mitsuba's ``path`` integrator (``src/integrators/path.cpp``:
emitter hits and next-event estimation with the power-heuristic :func:`mis_weight`, the same
sampler calls in the same order) whose throughput is a list of K band products and whose
contributions go to one accumulator per (light, band). The scene is loaded white, so Mitsuba's
own BSDF and emitter sampling give the band-independent factors (cosine, pdfs, visibility, spot
falloff); the kernel multiplies each by a band factor ``c_k`` of the vertex
(:mod:`spectrinsic.render.band_path.integrator` builds the integrator).
One body, three loops, told apart by Python flags read while Dr.Jit traces the kernel (as
Mitsuba's ``prb.py`` switches its features), so each traced kernel holds only its own steps:

* **matte** (no flag): ``c_k = ρ_k``, the band albedo of the material hit (or of the nearest
  texel of a textured shape).
* **gloss**: a glossy material is loaded as Mitsuba's ``plastic`` / ``roughplastic`` with a white
  base, or as a perfect-mirror ``conductor`` / ``roughconductor``. Its white BSDF is
  ``f = f_d + f_s`` (diffuse and non-diffuse lobes, told apart by evaluating with a
  ``BSDFContext`` whose ``type_mask`` is ``BSDFFlags.Diffuse``), and its band BSDF is
  ``ρ_k f_d + s_k f_s``: the plastic's diffuse lobe is linear in the base reflectance and its coat
  band-independent (``s_k = 1``); a metal has ``f_d = 0`` and ``s_k = F_k(μ)``, the band Fresnel
  of its η/k at ``μ = |wi · h|``, read from a per-row table
  (:func:`spectrinsic.spectra.conductors.fresnel_table`). With ``a = f_d / f`` at the direction
  used (0 for a delta-sampled lobe) the band factor is exactly::

      c_k = ρ_k a + s_k (1 − a)                                                    (G1)

  in both the emitter and the BSDF sample (``a = 1`` at a Lambertian vertex). The loop also
  carries the **specular transport** ``S``: the part whose first camera-ray vertex went through
  the non-diffuse lobe; its band throughput starts as ``s_k (1 − a)`` there and is multiplied by
  (G1) afterwards. Emitters the camera sees directly are in neither S nor the diffuse part.
* **white at metals** (with gloss): a metal has no diffuse lobe, so its shading ``W = P_diff / ρ``
  is 0/0; it is defined as the radiance a white Lambertian surface would reflect there,
  ``W_k = E_k / π``. A second loop over the same camera rays (after the first, whose paths are so
  unchanged) makes a metal first hit a white ``diffuse`` vertex (ρ_k = 1) and goes on through the
  true scene with (G1); elsewhere the lane stops at once. Its accumulators ``M`` average over all
  of a pixel's samples, so ``M = c_metal · W`` with ``c_metal`` the pixel's metal coverage.
  Mirrors and glass have no diffuse lobe either and are swapped alike (``non_diffuse_rows``).
* **glass** (with gloss): Mitsuba's ``(rough)dielectric`` / ``thindielectric`` of one index in
  every band, so its BSDF weight holds the Fresnel choice of reflection or transmission and
  ``s_k = 1`` on both lobes (a row of ones; μ, meaningless when refracted, is unused). ``a = 0``:
  all the camera sees in and through glass is ``S``. Mitsuba's BSDF handles both sides
  (``si.wi`` inside) and ``spawn_ray`` offsets the refracted ray, as in ``path.cpp``.
* **tinted glass** (``it.tinted``, with gloss): a transmission through glass of
  transmittance T(λ) multiplies band k by ``T_k`` (a per-row table, 1 on every other row),
  a reflection by its reflection tint ``R_k`` (likewise), as Mitsuba's
  ``specular_transmittance`` weights only the refracted lobe and ``specular_reflectance``
  only the reflected one (``dielectric``, ``roughdielectric``, ``thindielectric``; the lobe
  choice is Fresnel's alone). So ``s_k`` becomes ``T_k s_k`` on a transmission, ``R_k s_k``
  on a reflection: a BSDF sample whose sampled type
  is ``BSDFFlags.Transmission`` (a ``thindielectric``'s is ``Null``, which that flag holds), an
  emitter sample (rough glass only) where ``cos θ_i cos θ_o`` is not positive, the test of
  ``roughdielectric``'s ``eval``. A mask on tinted glass is refused (its hole's null event
  would be tinted; :mod:`~spectrinsic.scenes.validate`).
* **first-hit maps** (``n_surfaces`` > 0, not in the white loop): the camera ray's surface, ray
  distance, shading normal (and texel) are kept in the loop state. Under a bump or normal map
  the normal is the perturbed one Mitsuba's wrapper shades with
  (:func:`~spectrinsic.render.base.surface_maps.perturbed_normal`).
* **masks** (``it.masks``): an opacity mask (Mitsuba's ``mask`` BSDF) lets a ray pass with a
  *null* event (``sampled_type`` ``BSDFFlags.Null``, weight 1, direction unchanged). A cut-out
  is geometry, not material: a null event's band factor is 1 on every band (not ρ_k nor
  (G1), whose ``a`` is 0 there, as for any delta lobe), and the camera ray's *first vertex*
  (first-hit maps, the start of the specular throughput) is its first vertex that is not a
  null event (``PathState.seen``). Depths count null events as ``path.cpp`` does, so the
  image stays Mitsuba's. A partly opaque hit is first with probability α, so the first-hit
  maps mix the surface and what lies behind it by coverage, over the pixel's samples. The
  white-at-metal loop's first vertex is the same (a metal behind a hole gets its ``W``); a
  *masked metal* is swapped whole for the white BSDF, so its ``W`` there is over-estimated by
  1/α (a known limit: masks are for leaves and cut-outs, not metals).

Where to add a glossy part (a new per-light accumulator): a flag and its step here, its
channel names and AOV order in :mod:`~spectrinsic.render.band_path.integrator`, and its cut into the
per-light record in :mod:`~spectrinsic.render.band_path.traversal`.
"""

# long module: one loop (path.cpp on band throughputs), its features switched by trace-time
# flags in one body, so each step sits beside the others it must stay in step with

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from types import ModuleType
from typing import TYPE_CHECKING, Any, cast

from ..base.surface_maps import perturbed_normal
from ..base.textures import texel_of

if TYPE_CHECKING:  # the variant is chosen at run time: the caller imports Mitsuba
    import mitsuba as mi

    # the array types Mitsuba's stubs take and give (the variant's own arrays at run time)
    from drjit.auto.ad import Bool, Float, UInt

#: Values of the ``non_diffuse_rows`` table (``BandPath.set_non_diffuse``) other than 0 (a
#: diffuse lobe): no diffuse lobe (metal, mirror), and glass. Non-zero rows are the first hits
#: the white-at-metal loop makes white Lambertian; a glass row's null event (a
#: ``thindielectric``'s straight transmission) is no mask cut-out.
MIRROR_ROW, GLASS_ROW = 1, 2

__all__ = ["PathState", "BandKernel", "mis_weight", "band_max", "MIRROR_ROW", "GLASS_ROW"]


def mis_weight(dr: ModuleType, mi: ModuleType, pdf_a: Float, pdf_b: Float) -> Float:
    """Power heuristic exactly as ``path.cpp``'s ``mis_weight`` (pdfs in the same measure)."""
    a, b = pdf_a * pdf_a, pdf_b * pdf_b
    w = a / (a + b)
    return dr.detach(dr.select(dr.isfinite(w), w, mi.Float(0.0)))


def band_max(dr: ModuleType, bands: Sequence[Float]) -> Float:
    """Largest band value per lane (a balanced tree of ``dr.maximum``)."""
    values = list(bands)
    while len(values) > 1:
        values = [
            dr.maximum(values[i], values[i + 1]) if i + 1 < len(values) else values[i]
            for i in range(0, len(values), 2)
        ]
    return values[0]


@dataclass
class PathState:
    """The loop state Dr.Jit carries (a dataclass: ``dr.while_loop`` traverses its fields in
    this order). Band lists hold K entries, accumulators K·L (light-major).

    The fields are typed ``Any`` (their Mitsuba types in comments): Dr.Jit resolves a loop
    state's annotations when it traverses it (``typing.get_type_hints``), at run time, where
    Mitsuba is not imported at module level (the variant is chosen at run time)."""

    sampler: Any  # mi.Sampler
    ray: Any  # mi.Ray3f
    depth: Any  # UInt
    #: Band-independent throughput (Mitsuba's BSDF weights and the roulette's scale).
    beta: Any  # Float
    bands: list  # list[Float]
    acc: list  # list[Float]
    prev_si: Any  # mi.Interaction3f
    prev_pdf: Any  # Float
    prev_delta: Any  # Bool
    #: First-hit state (surface, distance, normal[, texel, textured]); empty without maps.
    first: tuple
    alive: Any  # Bool
    #: Whether the camera ray has had its first vertex that is not a null event (masks).
    seen: Any  # Bool
    #: Specular band throughputs and accumulators (gloss loop only).
    sbands: list = field(default_factory=list)  # list[Float]
    sacc: list = field(default_factory=list)  # list[Float]


@dataclass(frozen=True)
class _Vertex:
    """What a vertex's sampling gives: the light and weight of the emitter sample, its mask,
    Mitsuba's BSDF sample and weight, and (gloss) ``(a, μ)`` of both directions."""

    light: UInt
    nee: tuple[mi.Spectrum, ...]  # RGB weights (emitter, then extra maps) times the path throughput
    active_em: Bool
    bsdf_sample: mi.BSDFSample3f
    bsdf_weight: mi.SpectrumEntry
    em_lobes: tuple[Float, ...] = ()
    bs_lobes: tuple[Float, ...] = ()


class BandKernel:
    """The loop of ``path.cpp`` on band throughputs (module docstring); *it* is the integrator
    (depths, sizes, lookups). *gloss* switches on the (G1) factors and, outside the white loop,
    the specular accumulators; *white* is the white-at-metal loop."""

    def __init__(
        self,
        mi: ModuleType,
        dr: ModuleType,
        it: Any,  # the BandPath integrator, a class made at run time (band_path.integrator)
        scene: mi.Scene,
        *,
        gloss: bool = False,
        white: bool = False,
    ) -> None:
        self.mi, self.dr, self.it, self.scene = mi, dr, it, scene
        self.gloss, self.white = gloss or white, white
        self.spec = gloss and not white
        self.masks = bool(getattr(it, "masks", False))

    # -- lookups ---------------------------------------------------------------------------

    def light_of(self, emitter: mi.EmitterPtr, mask: Bool) -> UInt:
        ids = self.dr.reinterpret_array(self.mi.UInt32, emitter)
        return self.dr.gather(self.mi.UInt32, self.it.emitter_lut, ids, mask)

    def row(self, si: mi.SurfaceInteraction3f) -> UInt:
        """Albedo-table row of the shape hit."""
        mi, dr = self.mi, self.dr
        ids = dr.reinterpret_array(mi.UInt32, si.shape)
        return dr.gather(mi.UInt32, self.it.shape_lut, ids, si.is_valid())

    def albedo(self, si: mi.SurfaceInteraction3f) -> list[Float]:
        """ρ_k of the material of the shape hit (the black row elsewhere), or of the nearest
        texel on a textured shape."""
        mi, dr, k = self.mi, self.dr, self.it.n_bands
        valid, row = si.is_valid(), self.row(si)
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

    def deposit(
        self,
        acc: list[Float],
        light: UInt,
        weights: tuple[mi.Spectrum, ...],
        bands: Sequence[Float],
        mask: Bool,
    ) -> list[Float]:
        """``acc[j·K + k] += bands[k]·weights[m_j][c_j]`` on the lanes whose emitter is light
        j's owner ``o_j``. *weights* are RGB values (``Color3f``): the emitter's own, then one
        per extra environment map (:meth:`extra_maps_at`); ``(o_j, c_j, m_j)`` =
        ``it.light_channels[j]`` (Python ints, read when traced; ``(j, 0, 0)`` for a light of
        its own). Only an environment map's channel lights take another component or
        source: the emitters are loaded white, so today's components are equal and component
        0 of the emitter's own value is exactly the scalar of before."""
        k, out = self.it.n_bands, list(acc)
        for j, (owner, channel, source) in enumerate(self.it.light_channels):
            w = self.dr.select(mask & (light == owner), weights[source][channel], 0.0)
            for b in range(k):
                out[j * k + b] = self.dr.fma(bands[b], w, out[j * k + b])
        return out

    def extra_maps_at(
        self, si: mi.SurfaceInteraction3f, scale: Float, active: Bool
    ) -> tuple[mi.Spectrum, ...]:
        """The RGB radiance of every extra environment map (``it.extra_maps``, standalone
        Mitsuba ``envmap`` emitters, not in the scene: it takes one) towards ``-si.wi``, times
        *scale* (Mitsuba's ``envmap.eval`` reads only the direction)."""
        return tuple(m.eval(si, active) * scale for m in self.it.extra_maps)

    # -- the steps of a vertex -------------------------------------------------------------

    def emitter_hit(
        self, si: mi.SurfaceInteraction3f, s: PathState
    ) -> tuple[UInt, tuple[mi.Spectrum, ...], Bool]:
        """Light, weights (the path's throughput x RGB radiance x BSDF-sampling MIS weight, of
        the emitter then of the extra maps) and mask of an emitter hit."""
        mi, dr = self.mi, self.dr
        emitter = si.emitter(self.scene)
        # a Dr.Jit pointer array, compared lane by lane (the stubs give no Bool for it)
        hit = cast("Bool", emitter != None)  # noqa: E711
        ds = mi.DirectionSample3f(self.scene, si=si, ref=s.prev_si)
        em_pdf = dr.select(
            s.prev_delta, 0.0, self.scene.pdf_emitter_direction(s.prev_si, ds, ~s.prev_delta)
        )
        active = (s.prev_pdf > 0.0) & hit
        mis = mis_weight(dr, mi, s.prev_pdf, em_pdf)
        weights = (emitter.eval(si, active) * mis, *self.extra_maps_at(si, mis, active))
        return self.light_of(emitter, hit), tuple(s.beta * w for w in weights), hit

    def lobes(
        self,
        si: mi.SurfaceInteraction3f,
        bsdf: mi.BSDFPtr,
        wo: mi.Vector3f,
        delta: Bool,
        active: Bool,
    ) -> tuple[Float, ...]:
        """``a = f_d / f`` at local direction *wo* (0 where *delta*; exactly 1 for a BSDF
        without non-diffuse lobes) and ``μ = |wi · h|``; with tinted glass also 1 where *wo*
        is a transmission (``cos θ_i cos θ_o`` not positive), else 0."""
        mi, dr = self.mi, self.dr
        diffuse = bsdf.eval(
            mi.BSDFContext(mi.TransportMode.Radiance, mi.BSDFFlags.Diffuse), si, wo, active
        )[0]
        full = bsdf.eval(mi.BSDFContext(), si, wo, active)[0]
        a = dr.clip(dr.select(full > 0.0, diffuse / full, 1.0), 0.0, 1.0)
        flags = bsdf.flags()
        matte = ~(mi.has_flag(flags, mi.BSDFFlags.Glossy) | mi.has_flag(flags, mi.BSDFFlags.Delta))
        a = dr.select(matte, 1.0, dr.select(delta, 0.0, a))
        h = si.wi + wo
        norm = dr.norm(h)
        mu = dr.select(norm > 0.0, dr.abs(dr.dot(si.wi, h)) / norm, 1.0)
        if not self.it.tinted:
            return a, dr.clip(mu, 0.0, 1.0)
        through = dr.select(si.wi.z * wo.z > 0.0, 0.0, 1.0)
        return a, dr.clip(mu, 0.0, 1.0), through

    def vertex(
        self, s: PathState, si: mi.SurfaceInteraction3f, bsdf: mi.BSDFPtr, active_next: Bool
    ) -> _Vertex:
        """Emitter sample (its weights times the path's throughput ``s.beta``), then BSDF
        evaluation and sample (``eval_pdf_sample``); with gloss also ``a`` and ``μ`` of both
        directions."""
        sampler = s.sampler
        mi, dr = self.mi, self.dr
        active_em = active_next & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth)
        ds, em_weight = self.scene.sample_emitter_direction(si, sampler.next_2d(), True, active_em)
        active_em &= ds.pdf != 0.0
        sample_1, sample_2 = sampler.next_1d(), sampler.next_2d()
        wo_em = si.to_local(ds.d)
        bsdf_val, bsdf_pdf, bsdf_sample, bsdf_weight = bsdf.eval_pdf_sample(
            mi.BSDFContext(), si, wo_em, sample_1, sample_2
        )
        mis_em = dr.select(ds.delta, 1.0, mis_weight(dr, mi, ds.pdf, bsdf_pdf))
        nee = (bsdf_val[0] * em_weight * mis_em,)  # RGB: an environment map's channels
        if self.it.extra_maps:  # their radiance over the pdf the loaded emitter sampled by
            towards = dr.zeros(mi.SurfaceInteraction3f)
            towards.wi = -ds.d
            nee += self.extra_maps_at(towards, bsdf_val[0] * mis_em / ds.pdf, active_em)
        nee = tuple(s.beta * w for w in nee)
        light = self.light_of(ds.emitter, active_em)
        if not self.gloss:
            return _Vertex(light, nee, active_em, bsdf_sample, bsdf_weight[0])
        em_lobes = self.lobes(si, bsdf, wo_em, mi.Bool(False), active_em)
        delta = mi.has_flag(bsdf_sample.sampled_type, mi.BSDFFlags.Delta)
        bs_lobes = self.lobes(si, bsdf, bsdf_sample.wo, delta, active_next)
        if self.it.tinted:  # the sampled lobe says it exactly, also in a bump map's frame
            through = mi.has_flag(bsdf_sample.sampled_type, mi.BSDFFlags.Transmission)
            bs_lobes = (*bs_lobes[:2], dr.select(through, 1.0, 0.0))
        return _Vertex(light, nee, active_em, bsdf_sample, bsdf_weight[0], em_lobes, bs_lobes)

    def specular_bands(self, row: UInt, mu: Float, valid: Bool) -> list[Float]:
        """``s_k(μ)`` of table row *row*: linear interpolation over the μ nodes."""
        mi, dr, k, n = self.mi, self.dr, self.it.n_bands, self.it.n_nodes
        x = mu * (n - 1)
        j = dr.minimum(mi.UInt32(dr.floor(x)), n - 2)
        t = x - mi.Float(j)
        base = (row * n + j) * k
        out = []
        for b in range(k):
            lo = dr.gather(mi.Float, self.it.specular, base + b, valid)
            hi = dr.gather(mi.Float, self.it.specular, base + k + b, valid)
            out.append(dr.fma(t, hi - lo, lo))
        return out

    def factors(
        self, rho: list[Float], row: UInt, lobes: tuple[Float, ...], valid: Bool
    ) -> tuple[list[Float], list[Float]]:
        """(G1) ``c_k`` and its non-diffuse part ``s_k (1 − a)`` for ``lobes = (a, μ)``, or
        ``(a, μ, through)`` with tinted glass (``s_k`` times ``T_k`` where *through* is 1, else
        ``R_k``)."""
        a, mu = lobes[:2]
        bands = self.specular_bands(row, mu, valid)
        if self.it.tinted:
            bands = [s * self.tint(row, b, lobes[2], valid) for b, s in enumerate(bands)]
        spec = [s * (1.0 - a) for s in bands]
        return [self.dr.fma(r, a, s) for r, s in zip(rho, spec, strict=True)], spec

    def tint(self, row: UInt, band: int, through: Float, valid: Bool) -> Float:
        """``T_k`` of table row *row* where *through* is 1 (a transmission), else ``R_k``."""
        mi, dr = self.mi, self.dr
        at = row * self.it.n_bands + band
        t = dr.gather(mi.Float, self.it.transmittance, at, valid)
        r = dr.gather(mi.Float, self.it.reflection_tint, at, valid)
        return dr.select(through > 0.0, t, r)

    # -- first-hit maps --------------------------------------------------------------------

    def first_hit(self, si: mi.SurfaceInteraction3f, now: Bool, first: tuple) -> tuple:
        """Surface index, ray distance and shading normal of the hit *si* on the lanes where
        it is the camera ray's first vertex so far (*now*; a later one replaces it after a
        null event)."""
        mi, dr = self.mi, self.dr
        if not self.it.n_surfaces:
            return first
        valid = si.is_valid()
        surface = dr.gather(
            mi.UInt32, self.it.surface_lut, dr.reinterpret_array(mi.UInt32, si.shape), valid
        )
        surface = dr.select(valid, surface, self.it.n_surfaces)
        # through null events the ray distance adds up (a hole's wall lies behind the mask)
        distance = dr.select(valid, first[1] + si.t, 0.0)
        normal = dr.select(valid, self.shading_normal(si), mi.Vector3f(0.0))
        hit = (surface, distance, normal) + (
            texel_of(mi, dr, self.it, si) if self.it.n_texcols else ()
        )
        return tuple(dr.select(now, h, f) for h, f in zip(hit, first, strict=True))

    def shading_normal(self, si: mi.SurfaceInteraction3f) -> mi.Normal3f:
        """The hit's shading normal, perturbed on shapes with a bump or normal map."""
        mi, dr = self.mi, self.dr
        normal = si.sh_frame.n
        if not self.it.surface_maps:
            return normal
        ids = dr.reinterpret_array(mi.UInt32, si.shape)
        index = dr.gather(mi.UInt32, self.it.map_lut, ids, si.is_valid())
        for j, (kind, texture, scale) in enumerate(self.it.surface_maps):
            on = si.is_valid() & (index == j)
            bent = perturbed_normal(mi, dr, kind, texture, scale, si)
            normal = dr.select(on, bent, normal)
        return normal

    def first_state(self) -> tuple:
        """The first-hit state before any hit: no surface, no distance, no normal (no texel)."""
        mi = self.mi
        if self.white:
            return ()
        first = (mi.UInt32(self.it.n_surfaces), mi.Float(0.0), mi.Vector3f(0.0))
        return first + ((mi.UInt32(0), mi.Bool(False)) if self.it.n_texcols else ())

    def first_maps(self, first: tuple) -> list[Float]:
        """The first-hit channels (``first_hit_channels``) of the final first-hit state."""
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

    # -- the loop --------------------------------------------------------------------------

    def start(self, sampler: mi.Sampler, ray: mi.Ray3f, active: Bool) -> PathState:
        """Depth 0, throughput 1, K band throughputs 1, K·L accumulators 0, no previous vertex
        (pdf 1, delta); the specular ones 0 with gloss."""
        mi, dr, k, n = self.mi, self.dr, self.it.n_bands, self.it.n_bands * self.it.n_lights
        return PathState(
            sampler,
            mi.Ray3f(ray),
            mi.UInt32(0),
            mi.Float(1.0),
            [mi.Float(1.0) for _ in range(k)],
            [mi.Float(0.0) for _ in range(n)],
            dr.zeros(mi.Interaction3f),
            mi.Float(1.0),
            mi.Bool(True),
            self.first_state(),
            mi.Bool(active),
            mi.Bool(False),
            [mi.Float(0.0) for _ in range(k)] if self.spec else [],
            [mi.Float(0.0) for _ in range(n)] if self.spec else [],
        )

    def step(
        self, s: PathState, si: mi.SurfaceInteraction3f, v: _Vertex, bands: list[Float]
    ) -> tuple[PathState, Bool]:
        """Go on to the next vertex with the new band throughputs *bands*: ray, depth, previous
        vertex and the go-on flag. Russian roulette on the largest band (``path.cpp``: largest
        channel); off when ``rr_depth`` > ``max_depth``, but its sample is drawn either way."""
        mi, dr = self.mi, self.dr
        ray = si.spawn_ray(si.to_world(v.bsdf_sample.wo))
        depth = dr.select(si.is_valid(), s.depth + 1, s.depth)
        beta = s.beta * v.bsdf_weight
        throughput_max = beta * band_max(dr, bands)
        rr_prob = dr.minimum(throughput_max, 0.95)
        rr_active = depth >= self.it.rr_depth
        rr_continue = s.sampler.next_1d() < rr_prob
        beta = dr.select(rr_active, beta * dr.rcp(dr.detach(rr_prob)), beta)
        go_on = (~rr_active | rr_continue) & (throughput_max != 0.0)
        delta = mi.has_flag(v.bsdf_sample.sampled_type, mi.BSDFFlags.Delta)
        state = PathState(
            s.sampler, ray, depth, beta, bands, s.acc, mi.Interaction3f(si),
            v.bsdf_sample.pdf, delta, s.first, s.alive, s.seen, s.sbands, s.sacc,
        )  # fmt: skip
        return state, go_on

    def null_event(self, v: _Vertex, row: UInt | None, valid: Bool) -> Bool:
        """Whether the BSDF sample is a mask's null event: ``BSDFFlags.Null``, but not on a glass
        row (*row*, with gloss), where it is a ``thindielectric``'s straight transmission."""
        mi, dr = self.mi, self.dr
        null = valid & mi.has_flag(v.bsdf_sample.sampled_type, mi.BSDFFlags.Null)
        if row is not None:
            null &= dr.gather(mi.UInt32, self.it.non_diffuse_rows, row, valid) != GLASS_ROW
        return null

    def body(self, s: PathState) -> PathState:
        """One vertex: emitter hit, emitter sample, BSDF sample, in ``path.cpp``'s order."""
        mi, dr = self.mi, self.dr
        si = self.scene.ray_intersect(s.ray, ray_flags=mi.RayFlags.All, coherent=s.depth == 0)
        # the camera ray's first vertex: the first that is not a null event (masks)
        now, valid, swap, keep = ~s.seen, si.is_valid(), None, None
        if self.white:  # the camera ray's metal or glass hit becomes a white Lambertian vertex
            row = self.row(si)
            swap = now & (dr.gather(mi.UInt32, self.it.non_diffuse_rows, row, valid) != 0)
        else:
            s.first = self.first_hit(si, now, s.first)
        light, weight, hit = self.emitter_hit(si, s)
        # the white loop: what the camera sees directly is not reflected by the white surface
        s.acc = self.deposit(s.acc, light, weight, s.bands, hit if swap is None else hit & ~now)
        if self.spec:
            s.sacc = self.deposit(s.sacc, light, weight, s.sbands, hit)
        active_next = (s.depth + 1 < self.it.max_depth) & valid
        # a Ray3f, as prb.py passes; the stubs list only RayDifferential3f
        bsdf = si.bsdf(s.ray)  # type: ignore[call-overload]
        if swap is not None:  # the white loop goes on only from a metal first vertex ...
            keep = ~now | swap
            if not self.masks:  # ... or through a null event (masks: known once sampled)
                active_next &= keep
            bsdf = dr.select(swap, mi.BSDFPtr(self.it.white_bsdf), bsdf)
        v = self.vertex(s, si, bsdf, active_next)
        c_em = c_bs = rho = self.albedo(si)
        if swap is not None:
            rho = [dr.select(swap, 1.0, r) for r in rho]
        if self.gloss:
            row = row if self.white else self.row(si)
            c_em, s_em = self.factors(rho, row, v.em_lobes, valid)
            c_bs, s_bs = self.factors(rho, row, v.bs_lobes, valid)
        null = mi.Bool(False)
        if self.masks:  # a null event passes every band unchanged and is no first vertex
            null = self.null_event(v, row if self.gloss else None, valid)
            c_bs = [dr.select(null, 1.0, c) for c in c_bs]
            if self.spec:
                s_bs = [dr.select(null, 0.0, x) for x in s_bs]
        if self.spec:  # the first vertex starts the specular throughput; later ones scale it
            pairs = zip(s.bands, s_em, s.sbands, c_em, strict=True)
            s_nee = [dr.select(now, b * x, sb * c) for b, x, sb, c in pairs]
            pairs = zip(s.bands, s_bs, s.sbands, c_bs, strict=True)
            s.sbands = [dr.select(now, b * x, sb * c) for b, x, sb, c in pairs]
        nee_bands = [b * c for b, c in zip(s.bands, c_em, strict=True)]
        active_em = v.active_em if keep is None or not self.masks else v.active_em & keep
        s.acc = self.deposit(s.acc, v.light, v.nee, nee_bands, active_em)
        if self.spec:
            s.sacc = self.deposit(s.sacc, v.light, v.nee, s_nee, v.active_em)
        bands = nee_bands if c_bs is c_em else [b * c for b, c in zip(s.bands, c_bs, strict=True)]
        s, go_on = self.step(s, si, v, bands)
        s.alive = active_next & go_on
        if keep is not None and self.masks:
            s.alive &= keep | null
        s.seen = s.seen | ~null
        return s

    def run(
        self, sampler: mi.Sampler, ray: mi.Ray3f, active: Bool
    ) -> tuple[PathState, list[Float]]:
        """The final state of one wavefront of camera rays, and its accumulators then (gloss)
        the specular ones."""
        label = "spectrinsic " + ("white at metals" if self.white else "band path")
        (s,) = self.dr.while_loop(
            (self.start(sampler, ray, active),),
            lambda s: s.alive,
            lambda s: (self.body(s),),
            label=label + (" (glossy)" if self.spec else ""),
        )
        return s, list(s.acc) + list(s.sacc)
