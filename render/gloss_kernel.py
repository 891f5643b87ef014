"""The band-path loop for scenes with glossy materials, splitting off the first hit's specular part.

:class:`~spectrinsic.render.integrator.BandPath` loads every surface white, so a vertex's
band-independent factor is Mitsuba's own BSDF sample or evaluation. For a Lambertian vertex the
band factor is the albedo ρ_k. A glossy material is loaded as Mitsuba's ``plastic`` /
``roughplastic`` with a white base, or as a perfect-mirror ``conductor`` / ``roughconductor``
(:func:`~spectrinsic.render.translate.material_bsdf`). Its white BSDF is ``f = f_d + f_s``
(diffuse and non-diffuse lobes, told apart by evaluating with a ``BSDFContext`` whose
``type_mask`` is ``BSDFFlags.Diffuse``), and its true band BSDF is ``ρ_k f_d + s_k f_s``:
the plastic's diffuse lobe is linear in the base reflectance (``nonlinear: false``) and its
coat reflection band-independent (scalar ior), so ``s_k = 1``; a metal has ``f_d = 0`` and
``s_k = F_k(μ)``, the band Fresnel of its η/k at ``μ = |wi · h|`` (h the half vector, the
microfacet normal Mitsuba evaluates Fresnel at), read from a per-row table
(:func:`spectrinsic.spectra.conductors.fresnel_table`). So with ``a = f_d / f`` at the
direction used (0 for a delta-sampled lobe), the band factor of the vertex is exactly::

    c_k = ρ_k a + s_k (1 − a)                                                    (G1)

in both the emitter sample (next-event estimation) and the BSDF sample; for a Lambertian vertex
``a = 1`` and ``c_k = ρ_k``. The **specular transport** ``S`` is the part of the transport whose
first camera-ray vertex went through the non-diffuse lobe: its band throughput starts as
``s_k (1 − a)`` at that vertex and is multiplied by (G1) afterwards. The transport ``T`` and
the diffuse part ``T − S`` follow; emitters the camera sees directly are in neither S nor the
diffuse part's first-hit lobe (they are the residual of the layers).

A metal has no diffuse lobe, so its shading ``W = P_diff / ρ`` is 0/0. It is defined instead
as at every other surface, the radiance a **white Lambertian** surface would reflect there,
``W_k = E_k / π`` (the white-surface radiance, interreflections included). Scenes with metals
get a second loop over the same camera rays (after the first, so the first loop's paths are
unchanged): where the first hit is a metal, that vertex is a white ``diffuse`` BSDF (ρ_k = 1)
and the path goes on through the true scene with (G1) factors; elsewhere the lane stops at
once. Its accumulators ``M`` (:func:`metal_white_channels`) average over all of a pixel's
samples, so ``M = c_metal · W`` with ``c_metal`` the pixel's metal coverage.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from spectrinsic.errors import RenderError
from spectrinsic.render.integrator import (
    _Kernel,
    _mis_weight,
    band_path_class,
    first_hit_channels,
    transport_channels,
)
from spectrinsic.render.variants import import_mitsuba
from spectrinsic.spectra.conductors import FRESNEL_NODES

__all__ = [
    "GLOSS_INTEGRATOR_NAME",
    "GlossKernel",
    "gloss_path_class",
    "gloss_path",
    "specular_channels",
    "metal_white_channels",
]

#: Name the glossy integrator is registered under.
GLOSS_INTEGRATOR_NAME = "spectrinsic_bandpath_gloss"


def specular_channels(n_lights: int, n_bands: int) -> list[str]:
    """AOV names of the specular transport channels, light-major: ``s<l>_<k>``."""
    return [f"s{j:02d}_{k:02d}" for j in range(n_lights) for k in range(n_bands)]


def metal_white_channels(n_lights: int, n_bands: int) -> list[str]:
    """AOV names of the white-at-metal channels (module docstring), light-major: ``m<l>_<k>``."""
    return [f"m{j:02d}_{k:02d}" for j in range(n_lights) for k in range(n_bands)]


class GlossKernel(_Kernel):
    """:class:`~spectrinsic.render.integrator._Kernel` with (G1) band factors and the
    specular accumulators (module docstring); same sampler calls, in the same order."""

    def lobes(self, si: Any, bsdf: Any, wo: Any, delta: Any, active: Any) -> tuple[Any, Any]:
        """``a = f_d / f`` at local direction *wo* (0 where *delta*; exactly 1 for a BSDF
        without non-diffuse lobes) and ``μ = |wi · h|``."""
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
        return a, dr.clip(mu, 0.0, 1.0)

    def specular_bands(self, row: Any, mu: Any, valid: Any) -> list:
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

    def factors(self, rho: list, row: Any, a: Any, mu: Any, valid: Any) -> tuple[list, list]:
        """(G1) ``c_k`` and its non-diffuse part ``s_k (1 − a)``."""
        spec = [s * (1.0 - a) for s in self.specular_bands(row, mu, valid)]
        return [self.dr.fma(r, a, s) for r, s in zip(rho, spec, strict=True)], spec

    def row(self, si: Any) -> Any:
        mi, dr = self.mi, self.dr
        return dr.gather(
            mi.UInt32, self.it.shape_lut, dr.reinterpret_array(mi.UInt32, si.shape), si.is_valid()
        )

    def vertex_gloss(self, sampler: Any, si: Any, bsdf: Any, active_next: Any) -> tuple:
        """:meth:`_Kernel.vertex` plus ``a`` and ``μ`` of the emitter and the BSDF sample."""
        mi, dr = self.mi, self.dr
        active_em = active_next & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth)
        ds, em_weight = self.scene.sample_emitter_direction(si, sampler.next_2d(), True, active_em)
        active_em &= ds.pdf != 0.0
        sample_1, sample_2 = sampler.next_1d(), sampler.next_2d()
        wo_em = si.to_local(ds.d)
        bsdf_val, bsdf_pdf, bsdf_sample, bsdf_weight = bsdf.eval_pdf_sample(
            mi.BSDFContext(), si, wo_em, sample_1, sample_2
        )
        mis_em = dr.select(ds.delta, 1.0, _mis_weight(dr, mi, ds.pdf, bsdf_pdf))
        nee = bsdf_val[0] * em_weight[0] * mis_em
        em_lobes = self.lobes(si, bsdf, wo_em, mi.Bool(False), active_em)
        delta = mi.has_flag(bsdf_sample.sampled_type, mi.BSDFFlags.Delta)
        bs_lobes = self.lobes(si, bsdf, bsdf_sample.wo, delta, active_next)
        return (
            self.light_of(ds.emitter, active_em),
            nee,
            active_em,
            bsdf_sample,
            bsdf_weight[0],
            em_lobes,
            bs_lobes,
        )

    def gloss_body(
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
        sbands: list,
        sacc: list,
    ) -> tuple:
        """:meth:`_Kernel.body` with the (G1) factors and the specular throughput and accumulators."""
        mi, dr = self.mi, self.dr
        si = self.scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=depth == 0)
        first = self.first_hit(si, depth, first)
        light, weight, hit = self.emitter_hit(si, prev_si, prev_pdf, prev_delta)
        acc = self.deposit(acc, light, beta * weight, bands, hit)
        sacc = self.deposit(sacc, light, beta * weight, sbands, hit)
        active_next = (depth + 1 < self.it.max_depth) & si.is_valid()
        light, nee, active_em, bsdf_sample, bsdf_weight, em_lobes, bs_lobes = self.vertex_gloss(
            sampler, si, si.bsdf(ray), active_next
        )
        rho, row, valid, now = self.albedo(si), self.row(si), si.is_valid(), depth == 0
        c_em, s_em = self.factors(rho, row, em_lobes[0], em_lobes[1], valid)
        c_bs, s_bs = self.factors(rho, row, bs_lobes[0], bs_lobes[1], valid)
        # the first vertex starts the specular throughput; later ones scale it as the total
        s_nee = [
            dr.select(now, b * s, sb * c)
            for b, s, sb, c in zip(bands, s_em, sbands, c_em, strict=True)
        ]
        sbands = [
            dr.select(now, b * s, sb * c)
            for b, s, sb, c in zip(bands, s_bs, sbands, c_bs, strict=True)
        ]
        acc = self.deposit(
            acc, light, beta * nee, [b * c for b, c in zip(bands, c_em, strict=True)], active_em
        )
        sacc = self.deposit(sacc, light, beta * nee, s_nee, active_em)
        bands = [b * c for b, c in zip(bands, c_bs, strict=True)]
        state, go_on = self.next_state(
            sampler, si, bsdf_sample, bsdf_weight, depth, beta, bands, acc
        )
        return (*state, first, active_next & go_on, sbands, sacc)

    def white_body(
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
        alive: Any,
    ) -> tuple:
        """One vertex of the white-at-metal loop: the camera ray's metal hit is a white
        Lambertian (ρ_k = 1, ``a`` = 1), later vertices are the true scene's (G1)."""
        mi, dr = self.mi, self.dr
        si = self.scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=depth == 0)
        now, valid, row = depth == 0, si.is_valid(), self.row(si)
        swap = now & (dr.gather(mi.UInt32, self.it.metal_rows, row, valid) != 0)
        light, weight, hit = self.emitter_hit(si, prev_si, prev_pdf, prev_delta)
        # what the camera sees directly is not reflected by the white surface
        acc = self.deposit(acc, light, beta * weight, bands, hit & ~now)
        active_next = (depth + 1 < self.it.max_depth) & valid & (~now | swap)
        bsdf = dr.select(swap, mi.BSDFPtr(self.it.white_bsdf), si.bsdf(ray))
        light, nee, active_em, bsdf_sample, bsdf_weight, em_lobes, bs_lobes = self.vertex_gloss(
            sampler, si, bsdf, active_next
        )
        rho = [dr.select(swap, 1.0, r) for r in self.albedo(si)]
        c_em = self.factors(rho, row, em_lobes[0], em_lobes[1], valid)[0]
        c_bs = self.factors(rho, row, bs_lobes[0], bs_lobes[1], valid)[0]
        acc = self.deposit(
            acc, light, beta * nee, [b * c for b, c in zip(bands, c_em, strict=True)], active_em
        )
        bands = [b * c for b, c in zip(bands, c_bs, strict=True)]
        state, go_on = self.next_state(
            sampler, si, bsdf_sample, bsdf_weight, depth, beta, bands, acc
        )
        return (*state, active_next & go_on)

    def run_white(self, sampler: Any, ray: Any, active: Any) -> list:
        """The K·L white-at-metal accumulators ``M`` of the camera rays *ray*."""
        state = (*self.path_state(sampler, ray), self.mi.Bool(active))
        state = self.dr.while_loop(
            state, lambda *s: s[-1], self.white_body, label="spectrinsic white at metals"
        )
        return list(state[5])

    def run(self, sampler: Any, ray: Any, active: Any) -> list:
        """The K·L transport accumulators, the K·L specular ones, the K·L white-at-metal ones
        (scenes with metals), then the first-hit maps."""
        mi, k = self.mi, self.it.n_bands
        state = (
            *self.path_state(sampler, ray),
            self.first_state(),
            mi.Bool(active),
            [mi.Float(0.0) for _ in range(k)],  # specular band throughputs
            [mi.Float(0.0) for _ in range(k * self.it.n_lights)],  # specular accumulators
        )
        state = self.dr.while_loop(
            state, lambda *s: s[10], self.gloss_body, label="spectrinsic band path (glossy)"
        )
        out = list(state[5]) + list(state[12])
        if self.it.metals:
            out += self.run_white(sampler, ray, active)
        return out + self.first_maps(state[9])


@functools.cache
def gloss_path_class(variant: str) -> type:
    """The band-path integrator class with :class:`GlossKernel`, registered as
    :data:`GLOSS_INTEGRATOR_NAME`; properties as ``BandPath``'s plus ``n_nodes`` (μ nodes of
    the band Fresnel tables). Its AOVs: the L·K transports, the L·K specular transports, then
    the first-hit maps."""
    base = band_path_class(variant)
    mi = import_mitsuba()
    import drjit as dr

    class GlossPath(base):  # type: ignore[misc, valid-type]
        """``BandPath`` whose vertices split diffuse and non-diffuse lobes (module docstring)."""

        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.n_nodes = int(props.get("n_nodes", FRESNEL_NODES))
            self.specular = mi.Float(np.ones(self.n_nodes * self.n_bands, np.float32))
            self.metals = bool(props.get("metals", False))
            self.metal_rows = mi.UInt32(np.zeros(1, np.uint32))
            # two-sided as every material of the scene; Mitsuba's diffuse defaults to 0.5
            self.white_bsdf = mi.load_dict(
                {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": 1.0}}
            )

        def set_metals(self, rows: np.ndarray) -> None:
            """``(R,)`` bool: which albedo-table rows are metals (no diffuse lobe)."""
            self.metal_rows = mi.UInt32(np.asarray(rows, bool).astype(np.uint32))

        def set_specular(self, table: np.ndarray) -> None:
            """``(R, n_nodes, K)`` band factors ``s_k(μ_j)`` per albedo-table row."""
            shape = np.shape(table)
            if len(shape) != 3 or shape[1:] != (self.n_nodes, self.n_bands):
                raise RenderError(
                    f"specular table {shape} does not fit {self.n_nodes} nodes x {self.n_bands} bands"
                )
            self.specular = mi.Float(np.asarray(table, np.float32).ravel())

        def aov_names(self) -> list[str]:
            return (
                transport_channels(self.n_lights, self.n_bands)
                + specular_channels(self.n_lights, self.n_bands)
                + (metal_white_channels(self.n_lights, self.n_bands) if self.metals else [])
                + first_hit_channels(self.n_surfaces, self.n_texcols)
            )

        def sample(
            self, scene: Any, sampler: Any, ray: Any, medium: Any = None, active: Any = True
        ) -> tuple:
            return (
                mi.Spectrum(0.0),
                mi.Bool(True),
                GlossKernel(mi, dr, self, scene).run(sampler, ray, active),
            )

    mi.register_integrator(GLOSS_INTEGRATOR_NAME, lambda props: GlossPath(props))
    return GlossPath


def gloss_path(
    mi: Any,
    *,
    max_depth: int,
    n_bands: int,
    n_lights: int,
    n_surfaces: int = 0,
    metals: bool = False,
    n_texcols: int = 0,
) -> Any:
    """A glossy band-path integrator for the active variant (rr off), as
    :func:`~spectrinsic.render.integrator.band_path`; with *metals* it also estimates the
    white-surface radiance at metal first hits (module docstring)."""
    gloss_path_class(mi.variant())
    return mi.load_dict(
        {
            "type": GLOSS_INTEGRATOR_NAME,
            "max_depth": int(max_depth),
            "rr_depth": int(max_depth) + 1,
            "n_bands": int(n_bands),
            "n_lights": int(n_lights),
            "n_surfaces": int(n_surfaces),
            "metals": bool(metals),
            "n_texcols": int(n_texcols),
        }
    )
