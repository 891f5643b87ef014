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
from dataclasses import dataclass
from typing import Any

import numpy as np

from spectrinsic.errors import RenderError

__all__ = ["INTEGRATOR_NAME", "BandTables", "band_path_class", "band_path", "transport_channels"]

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
    """

    albedo: np.ndarray
    shape_rows: dict[str, int]
    emitter_lights: dict[int, int]
    n_lights: int


def transport_channels(n_lights: int, n_bands: int) -> list[str]:
    """AOV names of the transport channels, light-major: ``t<l>_<k>``."""
    return [f"t{l:02d}_{k:02d}" for l in range(n_lights) for k in range(n_bands)]


def _mis_weight(dr: Any, mi: Any, pdf_a: Any, pdf_b: Any) -> Any:
    """Power heuristic exactly as ``path.cpp``'s ``mis_weight``."""
    a, b = pdf_a * pdf_a, pdf_b * pdf_b
    w = a / (a + b)
    return dr.detach(dr.select(dr.isfinite(w), w, mi.Float(0.0)))


@functools.cache
def band_path_class(variant: str) -> type:
    """The :class:`BandPath` integrator class for the active *variant* (defined per variant,
    since ``mi.SamplingIntegrator`` is the variant's), registered as :data:`INTEGRATOR_NAME`."""
    from spectrinsic.render.variants import import_mitsuba

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
            self._albedo = mi.Float(np.zeros(self.n_bands, np.float32))
            self._shape_lut = mi.UInt32(np.zeros(1, np.uint32))
            self._emitter_lut = mi.UInt32(np.zeros(1, np.uint32))

        def set_tables(self, scene: Any, tables: BandTables) -> None:
            """Point the lookups at *tables* for the loaded *scene* (no recompilation)."""
            albedo = np.asarray(tables.albedo, np.float32)
            if albedo.ndim != 2 or albedo.shape[1] != self.n_bands or tables.n_lights != self.n_lights:
                raise RenderError(f"band tables {albedo.shape} for {tables.n_lights} lights do not fit an "
                                  f"integrator of {self.n_bands} bands and {self.n_lights} lights")
            black = albedo.shape[0] - 1
            shapes = list(scene.shapes())
            ids = np.array(dr.reinterpret_array(mi.UInt32, mi.ShapePtr(shapes)), np.int64) if shapes else np.zeros(0, np.int64)
            lut = np.full(int(ids.max(initial=0)) + 1, black, np.uint32)
            for sid, shape in zip(ids, shapes, strict=True):
                lut[sid] = tables.shape_rows.get(shape.id(), black)
            eids = tables.emitter_lights
            elut = np.zeros(max(eids, default=0) + 1, np.uint32)
            for eid, light in eids.items():
                elut[eid] = light
            self._albedo = mi.Float(albedo.ravel())
            self._shape_lut = mi.UInt32(lut)
            self._emitter_lut = mi.UInt32(elut)

        def aov_names(self) -> list[str]:
            return transport_channels(self.n_lights, self.n_bands)

        def _deposit(self, acc: list, light: Any, weight: Any, bands: Sequence, mask: Any) -> list:
            """``acc[l·K + k] += bands[k]·weight`` for the lanes whose light is l."""
            k = self.n_bands
            out = list(acc)
            for l in range(self.n_lights):
                w = dr.select(mask & (light == l), weight, 0.0)
                for b in range(k):
                    out[l * k + b] = dr.fma(bands[b], w, out[l * k + b])
            return out

        def sample(self, scene: Any, sampler: Any, ray_: Any, medium: Any = None, active: Any = True) -> tuple:
            k = self.n_bands
            bsdf_ctx = mi.BSDFContext()
            ray = mi.Ray3f(ray_)
            depth = mi.UInt32(0)
            beta = mi.Float(1.0)  # band-independent throughput (white BSDF weights)
            bands = [mi.Float(1.0) for _ in range(k)]  # Π ρ_k along the path
            acc = [mi.Float(0.0) for _ in range(k * self.n_lights)]
            prev_si = dr.zeros(mi.Interaction3f)
            prev_bsdf_pdf = mi.Float(1.0)
            prev_bsdf_delta = mi.Bool(True)
            alive = mi.Bool(active)

            def cond(sampler, ray, depth, beta, bands, acc, prev_si, prev_bsdf_pdf, prev_bsdf_delta, alive):
                return alive

            def body(sampler, ray, depth, beta, bands, acc, prev_si, prev_bsdf_pdf, prev_bsdf_delta, alive):
                si = scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=depth == 0)
                # ---- emitter hit (MIS with the previous vertex's BSDF sample)
                emitter = si.emitter(scene)
                hit_em = emitter != None  # noqa: E711 (Dr.Jit pointer comparison)
                ds = mi.DirectionSample3f(scene, si=si, ref=prev_si)
                em_pdf = scene.pdf_emitter_direction(prev_si, ds, ~prev_bsdf_delta)
                em_pdf = dr.select(prev_bsdf_delta, 0.0, em_pdf)
                mis_bsdf = _mis_weight(dr, mi, prev_bsdf_pdf, em_pdf)
                radiance = emitter.eval(si, (prev_bsdf_pdf > 0.0) & hit_em)[0]
                light = dr.gather(mi.UInt32, self._emitter_lut, dr.reinterpret_array(mi.UInt32, emitter), hit_em)
                acc = self._deposit(acc, light, beta * radiance * mis_bsdf, bands, hit_em)

                active_next = (depth + 1 < self.max_depth) & si.is_valid()
                bsdf = si.bsdf(ray)
                # ---- next-event estimation (sampler calls in path.cpp's order)
                active_em = active_next & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth)
                ds, em_weight = scene.sample_emitter_direction(si, sampler.next_2d(), True, active_em)
                active_em &= ds.pdf != 0.0
                wo = si.to_local(ds.d)
                sample_1 = sampler.next_1d()
                sample_2 = sampler.next_2d()
                bsdf_val, bsdf_pdf, bsdf_sample, bsdf_weight = bsdf.eval_pdf_sample(
                    bsdf_ctx, si, wo, sample_1, sample_2)
                row = dr.gather(mi.UInt32, self._shape_lut, dr.reinterpret_array(mi.UInt32, si.shape), si.is_valid())
                rho = [dr.gather(mi.Float, self._albedo, row * k + b, si.is_valid()) for b in range(k)]
                next_bands = [bands[b] * rho[b] for b in range(k)]
                mis_em = dr.select(ds.delta, 1.0, _mis_weight(dr, mi, ds.pdf, bsdf_pdf))
                light = dr.gather(mi.UInt32, self._emitter_lut, dr.reinterpret_array(mi.UInt32, ds.emitter), active_em)
                acc = self._deposit(acc, light, beta * bsdf_val[0] * em_weight[0] * mis_em, next_bands, active_em)
                # ---- BSDF sampling: continue the path
                ray = si.spawn_ray(si.to_world(bsdf_sample.wo))
                beta = beta * bsdf_weight[0]
                bands = next_bands
                prev_si = mi.Interaction3f(si)
                prev_bsdf_pdf = bsdf_sample.pdf
                prev_bsdf_delta = mi.has_flag(bsdf_sample.sampled_type, mi.BSDFFlags.Delta)
                depth = dr.select(si.is_valid(), depth + 1, depth)
                # ---- stopping criterion (Russian roulette on the largest band, as path.cpp
                # does on the largest channel; off when rr_depth > max_depth)
                throughput_max = beta * _band_max(dr, bands)
                rr_prob = dr.minimum(throughput_max, 0.95)
                rr_active = depth >= self.rr_depth
                rr_continue = sampler.next_1d() < rr_prob
                beta = dr.select(rr_active, beta * dr.rcp(dr.detach(rr_prob)), beta)
                alive = active_next & (~rr_active | rr_continue) & (throughput_max != 0.0)
                return sampler, ray, depth, beta, bands, acc, prev_si, prev_bsdf_pdf, prev_bsdf_delta, alive

            state = dr.while_loop(
                (sampler, ray, depth, beta, bands, acc, prev_si, prev_bsdf_pdf, prev_bsdf_delta, alive),
                cond, body, label="spectrinsic band path",
            )
            acc = state[5]
            return mi.Spectrum(0.0), mi.Bool(True), list(acc)

        def to_string(self) -> str:
            return f"BandPath[max_depth={self.max_depth}, n_bands={self.n_bands}, n_lights={self.n_lights}]"

    mi.register_integrator(INTEGRATOR_NAME, lambda props: BandPath(props))
    return BandPath


def _band_max(dr: Any, bands: Sequence) -> Any:
    """Largest band value per lane (a balanced tree of ``dr.maximum``)."""
    values = list(bands)
    while len(values) > 1:
        values = [dr.maximum(values[i], values[i + 1]) if i + 1 < len(values) else values[i]
                  for i in range(0, len(values), 2)]
    return values[0]


def band_path(mi: Any, *, max_depth: int, n_bands: int, n_lights: int) -> Any:
    """A :class:`BandPath` instance for the active variant (rr off: ``rr_depth`` > ``max_depth``)."""
    band_path_class(mi.variant())
    return mi.load_dict({"type": INTEGRATOR_NAME, "max_depth": int(max_depth), "rr_depth": int(max_depth) + 1,
                         "n_bands": int(n_bands), "n_lights": int(n_lights)})
