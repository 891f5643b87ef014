"""One path traversal for every band of every diagonal mode, split by light (issue 20).

Today's diagonal modes render ⌈K/3⌉ RGB passes that trace identical paths (common random
numbers) and differ only in the channel values of materials and lights (Eq. 5.2). A Lambertian
vertex multiplies the throughput by its material's band albedo ρ_k and a light adds its band
value E_k; neither changes the path. So one traversal can carry all K bands at once:
:class:`BandPath` (built by :func:`band_path_class`) runs the one loop of
:class:`~spectrinsic.render.band_path.kernel.BandKernel` (Mitsuba's ``path`` on K band
throughputs, its ``gloss`` and ``metals`` features switched on when traced; that module says
how) on the scene loaded with white Lambertian surfaces (area-light shapes black) and unit
white emitters. Its output is the **light transport** of each light for unit emission,
``T_{l,k}`` per pixel, ``(H, W, L·K)``; the K-channel image is ``Σ_l E_{l,k} T_{l,k}``, equal
to the diagonal passes' image to float rounding (same seed, spp and paths), and each light's
share is exact: the per-light images sum to the total.

Material and emitter indices come from Mitsuba's registry ids of ``si.shape`` and
``ds.emitter`` (``dr.reinterpret_array``), mapped through lookup tables built after loading.
Tables are Dr.Jit arrays, not literals, so the compiled kernel is reused for every scene with
the same number of bands and lights.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import RenderError
from ...spectra.conductors import FRESNEL_NODES
from ..base.surface_maps import map_textures
from ..base.textures import TextureTables, shape_id_table, texture_lookups
from ..base.variants import import_mitsuba
from ..result import METAL_WHITE, PARTS, SPECULAR
from .kernel import BandKernel

__all__ = [
    "INTEGRATOR_NAME",
    "BandTables",
    "band_path_class",
    "band_path",
    "aov_channels",
    "part_channels",
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
        The texel tables of textured meshes (:mod:`~spectrinsic.render.base.textures`), or ``None``.
    shape_textures
        ``{Mitsuba shape id: texture slot}`` of textured shapes.
    light_channels
        Per light j, ``(o_j, c_j, m_j)``: it takes RGB component ``c_j`` of source ``m_j`` on
        the lanes whose emitter was loaded as light ``o_j``; source 0 is that emitter's own
        value, source ``1 + i`` extra map i. An environment map's channel lights share the one
        loaded ``envmap``; empty: ``(j, 0, 0)`` for every light.
    extra_maps
        Standalone Mitsuba ``envmap`` emitters of the scene's other environment maps (Mitsuba
        loads one per scene), evaluated by the kernel where the loaded one is hit or sampled.
    map_scales
        ``{Mitsuba shape id: bump scale}`` of shapes with a bump or normal map, whose perturbed
        normal the first-hit maps hold (:mod:`~spectrinsic.render.base.surface_maps`).
    masks
        Whether a shape has an opacity mask (null events: :mod:`~spectrinsic.render.band_path.kernel`).
    transmittance
        ``(R, K)`` band transmittances per row (tinted glass; 1 on every other row, the black
        one too), or ``None`` where no glass is tinted.
    specular_reflectance
        ``(R, K)`` band reflection tints per row, as :attr:`transmittance`.
    """

    albedo: np.ndarray
    shape_rows: dict[str, int]
    emitter_lights: dict[int, int]
    n_lights: int
    shape_surfaces: dict[str, int] = field(default_factory=dict)
    textures: TextureTables | None = None
    shape_textures: dict[str, int] = field(default_factory=dict)
    light_channels: tuple[tuple[int, int, int], ...] = ()
    extra_maps: tuple[object, ...] = ()
    map_scales: dict[str, float] = field(default_factory=dict)
    masks: bool = False
    transmittance: np.ndarray | None = None
    specular_reflectance: np.ndarray | None = None

    def channels(self) -> tuple[tuple[int, int, int], ...]:
        """:attr:`light_channels`, or ``(j, 0, 0)`` per light where empty."""
        return self.light_channels or tuple((j, 0, 0) for j in range(self.n_lights))


def part_channels(part: str, n_lights: int, n_bands: int) -> list[str]:
    """AOV names of the transport's (*part* ``"transport"``: ``t<l>_<k>``) or a part's
    channels, light-major, by the part's letter in :data:`~spectrinsic.render.result.PARTS`
    (``s<l>_<k>`` specular, ``w<l>_<k>`` white at metals)."""
    letter = "t" if part == "transport" else PARTS[part].lower()
    return [f"{letter}{j:02d}_{k:02d}" for j in range(n_lights) for k in range(n_bands)]


def aov_channels(
    n_lights: int,
    n_bands: int,
    n_surfaces: int = 0,
    n_texcols: int = 0,
    *,
    gloss: bool = False,
    metals: bool = False,
) -> list[str]:
    """Every AOV of a :class:`BandPath`, in order: the L·K transports, with *gloss* (or
    *metals*) the L·K specular ones, with *metals* the L·K white-at-metal ones, then the
    first-hit maps."""
    return (
        part_channels("transport", n_lights, n_bands)
        + (part_channels(SPECULAR, n_lights, n_bands) if gloss or metals else [])
        + (part_channels(METAL_WHITE, n_lights, n_bands) if metals else [])
        + first_hit_channels(n_surfaces, n_texcols)
    )


def first_hit_channels(n_surfaces: int, n_texcols: int = 0) -> list[str]:
    """AOV names of the first-hit maps after the transport: the coverage of each surface, the
    texel weights of each textured coverage column (:class:`TextureTables`), the ray distance
    and the shading normal (as Mitsuba's ``aov`` integrator's ``depth`` and ``sh_normal``);
    none without surfaces."""
    if n_surfaces == 0:
        return []
    cover = [f"cov{i:03d}" for i in range(n_surfaces)] + [f"tex{g:03d}" for g in range(n_texcols)]
    return [*cover, "depth", "normal.x", "normal.y", "normal.z"]


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
        or len(tables.channels()) != it.n_lights
        or any(
            not (0 <= o < it.n_lights and 0 <= c < 3 and 0 <= m <= len(tables.extra_maps))
            for o, c, m in tables.channels()
        )
    ):
        raise RenderError(
            f"band tables {shape} for {tables.n_lights} lights and {n_texcols} texture columns "
            f"do not fit an integrator of {it.n_bands} bands, {it.n_lights} lights and "
            f"{it.n_texcols} texture columns"
        )


def _init_gloss(mi: Any, it: Any, props: Any) -> None:
    """The glossy properties of integrator *it*: flags, μ nodes, specular and transmittance
    tables of ones, no non-diffuse rows, and the white BSDF the white-at-metal loop swaps in."""
    it.metals = bool(props.get("metals", False))
    it.gloss = bool(props.get("gloss", False)) or it.metals
    it.tinted = bool(props.get("tinted", False)) and it.gloss
    it.n_nodes = int(props.get("n_nodes", FRESNEL_NODES))
    if it.gloss:
        it.specular = mi.Float(np.ones(it.n_nodes * it.n_bands, np.float32))
        it.transmittance = mi.Float(np.ones(it.n_bands, np.float32))
        it.reflection_tint = mi.Float(np.ones(it.n_bands, np.float32))
        it.non_diffuse_rows = mi.UInt32(np.zeros(1, np.uint32))
        # two-sided as every material of the scene; Mitsuba's diffuse defaults to 0.5
        it.white_bsdf = mi.load_dict(
            {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": 1.0}}
        )


def _empty_tables(mi: Any, it: Any) -> None:
    """Integrator *it*'s lookups before :meth:`set_tables`: one zero entry each, every light
    its own emitter's component 0, no extra map and no bump or normal map."""
    it.surface_lut = mi.UInt32(np.zeros(1, np.uint32))
    it.albedo = mi.Float(np.zeros(it.n_bands, np.float32))
    it.shape_lut = mi.UInt32(np.zeros(1, np.uint32))
    it.emitter_lut = mi.UInt32(np.zeros(1, np.uint32))
    it.light_channels = tuple((j, 0, 0) for j in range(it.n_lights))
    it.extra_maps = ()
    it.map_lut = mi.UInt32(np.zeros(1, np.uint32))
    #: (kind, texture, bump scale) of each bump- or normal-mapped shape (surface_maps)
    it.surface_maps = []


def _set_transmittance(mi: Any, it: Any, tables: BandTables) -> None:
    """Integrator *it*'s ``(R, K)`` band transmittances and reflection tints per albedo-table
    row from *tables* (tinted glass; kept as they are where *tables* have none)."""
    for table, name in (
        (tables.transmittance, "transmittance"),
        (tables.specular_reflectance, "reflection_tint"),
    ):
        if table is None:
            continue
        if np.ndim(table) != 2 or np.shape(table)[1] != it.n_bands:
            raise RenderError(f"{name} table {np.shape(table)} does not fit {it.n_bands} bands")
        setattr(it, name, mi.Float(np.asarray(table, np.float32).ravel()))


def _set_maps(mi: Any, dr: Any, it: Any, scene: Any, tables: BandTables) -> None:
    """Point integrator *it* at the bump and normal maps of the loaded *scene*'s shapes
    named in *tables* (their texture objects, shape id -> map index)."""
    lut, it.surface_maps = map_textures(mi, scene, tables.map_scales)
    it.map_lut = mi.UInt32(shape_id_table(mi, dr, scene, lut, len(lut)))


def _check_specular(it: Any, table: np.ndarray) -> None:
    """Raise unless *table* is ``(R, n_nodes, K)`` for integrator *it*."""
    shape = np.shape(table)
    if len(shape) != 3 or shape[1:] != (it.n_nodes, it.n_bands):
        raise RenderError(
            f"specular table {shape} does not fit {it.n_nodes} nodes x {it.n_bands} bands"
        )


def _make_class(mi: Any, dr: Any) -> type:
    """The :class:`BandPath` class of the active variant (module docstring)."""

    class BandPath(mi.SamplingIntegrator):  # type: ignore[misc, name-defined]
        """``path`` with K band throughputs and L·K per-light accumulators; with ``gloss`` the
        (G1) factors and the specular accumulators, with ``metals`` the white-at-metal loop."""

        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.max_depth = int(props.get("max_depth", 8))
            self.rr_depth = int(props.get("rr_depth", self.max_depth + 1))
            self.n_bands = int(props.get("n_bands", 3))
            self.n_lights = int(props.get("n_lights", 1))
            self.n_surfaces = int(props.get("n_surfaces", 0))
            self.n_texcols = int(props.get("n_texcols", 0))
            self.masks = bool(props.get("masks", False))
            _empty_tables(mi, self)
            _init_gloss(mi, self, props)

        def set_tables(self, scene: Any, tables: BandTables) -> None:
            """Point the lookups at *tables* for the loaded *scene* (no recompilation)."""
            _check_fit(self, tables)
            self.albedo, self.shape_lut, self.emitter_lut, self.surface_lut = _lookups(
                mi, dr, scene, tables
            )
            lookups = texture_lookups(mi, dr, scene, tables.textures, tables.shape_textures)
            self.slot_lut, self.tex_widths, self.tex_heights, self.tex_offsets = lookups[:4]
            self.texel_albedo, self.texel_weights = lookups[4:]
            self.light_channels, self.extra_maps = tables.channels(), tuple(tables.extra_maps)
            _set_maps(mi, dr, self, scene, tables)
            _set_transmittance(mi, self, tables)

        def set_non_diffuse(self, rows: np.ndarray) -> None:
            """``(R,)`` per row: 0, ``MIRROR_ROW`` or ``GLASS_ROW`` (kernel: ``non_diffuse_rows``)."""
            self.non_diffuse_rows = mi.UInt32(np.asarray(rows, np.uint32))

        def set_specular(self, table: np.ndarray) -> None:
            """``(R, n_nodes, K)`` band factors ``s_k(μ_j)`` per albedo-table row."""
            _check_specular(self, table)
            self.specular = mi.Float(np.asarray(table, np.float32).ravel())

        def aov_names(self) -> list[str]:
            return aov_channels(
                self.n_lights, self.n_bands, self.n_surfaces, self.n_texcols,
                gloss=self.gloss, metals=self.metals,
            )  # fmt: skip

        def sample(
            self, scene: Any, sampler: Any, ray: Any, medium: Any = None, active: Any = True
        ) -> tuple:
            kernel = BandKernel(mi, dr, self, scene, gloss=self.gloss)
            state, out = kernel.run(sampler, ray, active)
            if self.metals:  # after the first loop, so its paths are unchanged
                out += BandKernel(mi, dr, self, scene, white=True).run(sampler, ray, active)[1]
            return mi.Spectrum(0.0), mi.Bool(True), out + kernel.first_maps(state.first)

        def to_string(self) -> str:
            return (
                f"BandPath[max_depth={self.max_depth}, n_bands={self.n_bands}, "
                f"n_lights={self.n_lights}, gloss={self.gloss}, metals={self.metals}]"
            )

    return BandPath


@functools.cache
def band_path_class(variant: str) -> type:
    """The :class:`BandPath` integrator class for the active *variant* (defined per variant,
    since ``mi.SamplingIntegrator`` is the variant's), registered as :data:`INTEGRATOR_NAME`.

    Properties: ``max_depth``, ``rr_depth`` (as ``path``), ``n_bands`` (K), ``n_lights`` (L),
    ``n_surfaces``, ``n_texcols``, ``gloss``, ``metals``, ``masks``, ``tinted``, ``n_nodes``
    (μ nodes of the band Fresnel tables). Its AOVs are :func:`aov_channels`; its RGB output is zero.
    """
    mi = import_mitsuba()
    if mi.variant() != variant:
        raise RenderError(f"band_path_class({variant!r}) called while {mi.variant()!r} is active")
    import drjit as dr

    cls = _make_class(mi, dr)
    mi.register_integrator(INTEGRATOR_NAME, lambda props: cls(props))
    return cls


def band_path(
    mi: Any,
    *,
    max_depth: int,
    n_bands: int,
    n_lights: int,
    n_surfaces: int = 0,
    n_texcols: int = 0,
    gloss: bool = False,
    metals: bool = False,
    masks: bool = False,
    tinted: bool = False,
) -> Any:
    """A :class:`BandPath` instance for the active variant (rr off: ``rr_depth`` > ``max_depth``),
    with first-hit maps of *n_surfaces* surfaces if not 0, textures of *n_texcols* coverage
    columns (:class:`TextureTables`) if not 0, the glossy (G1) factors and specular part with
    *gloss*, and the white-surface radiance at metal first hits with *metals* (implies *gloss*;
    :mod:`~spectrinsic.render.band_path.kernel`), null events through opacity masks with
    *masks*, and the band transmittance and reflection tint of tinted glass
    (:attr:`BandTables.transmittance`, :attr:`BandTables.specular_reflectance`) with *tinted*."""
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
            "gloss": bool(gloss),
            "metals": bool(metals),
            "masks": bool(masks),
            "tinted": bool(tinted),
        }
    )
