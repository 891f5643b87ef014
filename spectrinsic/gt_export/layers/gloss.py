"""The gloss family: ``specular``, ``non_diffuse``, ``metallic``, ``roughness`` and (scenes with
glass) ``transmissive``, for scenes with glossy materials
(:class:`~spectrinsic.scenes.model.Material` ``plastic``/``conductor``/``dielectric``/
``thindielectric``).

The single traversal returns, per diagonal mode, the raw channels ``P_spec`` of the light the
camera rays' first hits return through their non-diffuse lobes (coat reflection, metal), with
everything those lobes reflect (:attr:`~spectrinsic.render.result.RenderResult.specular`).
With ``P`` the raw image, ρ the pixel's band albedo and X the mode's raw → XYZ matrix::

    P_diff   = P − P_spec                 the first hits' diffuse lobes (and the light seen directly)
    W        = P_diff / ρ                 white-surface radiance (Eq. 1 of irradiance), per band
    specular = RGB(X · P_spec)            working-space RGB, render units (< 0 only out of gamut)
    image    = reflectance ∘ shading + specular + residual

Scenes without glossy materials get none of these layers (their specular part is 0, every
surface is diffuse with roughness 1), so their samples are those of before.

**Glass and mirrors** (no diffuse lobe, like metals): at a pixel whose first hit is glass or a
mirror, ``reflectance`` is 0, ``shading`` the white-Lambertian ``W = E/π`` at that hit (as at
metals, :mod:`~spectrinsic.gt_export.layers.irradiance`), and everything the camera sees in or
through the glass or in the mirror (reflection and transmission chains and whatever lies
behind) is in ``specular``; the identity holds there as everywhere. ``transmissive`` (scenes
with glass only, so other samples are unchanged; its description carries the glass words, the
other layers' descriptions are those of before) and ``metallic`` (metals and mirrors) say
where, so a user can exclude or in-paint those pixels (spectrinsic/scenes/FORMAT.md, "Ground
truth on glass, mirrors and masks").
"""

from __future__ import annotations

import numpy as np

from ...render.result import SPECULAR as SPECULAR_PART
from .imaging import coverage_weighted
from .records import RGB, UNITS_IMAGE, Layer, SampleInputs, make_layer

__all__ = [
    "SPECULAR",
    "SPECULAR_BANDS",
    "specular_raw",
    "diffuse_raw",
    "specular_rgb",
    "gloss_layers",
]

#: The layer the glossy part becomes (a part that becomes a layer keeps its part name,
#: :data:`~spectrinsic.render.result.SPECULAR`), and the specular term's role in an
#: identity (``meta.json["identities"]``); every module naming the layer imports it from here.
SPECULAR = SPECULAR_PART
#: The per-band specular layer (``spectral.exr``).
SPECULAR_BANDS = f"{SPECULAR}_bands"


def specular_raw(s: SampleInputs) -> np.ndarray | None:
    """``(H, W, K)`` float64 raw specular channels of the reference mode, or ``None`` (matte)."""
    spec = s.result.specular
    return np.asarray(spec[s.ref], np.float64) if s.ref in spec else None


def diffuse_raw(s: SampleInputs, raw: np.ndarray) -> np.ndarray:
    """*raw* less its specular part (``P_diff``); *raw* itself for matte scenes."""
    spec = specular_raw(s)
    return raw if spec is None else np.asarray(raw, np.float64) - spec


def specular_rgb(s: SampleInputs, to_xyz: np.ndarray) -> np.ndarray | None:
    """``(H, W, 3)`` working-space RGB of the specular channels, or ``None`` (matte)."""
    spec = specular_raw(s)
    return None if spec is None else s.space.rgb(np.einsum("hwk,ck->hwc", spec, to_xyz))


def gloss_layers(s: SampleInputs, coverage: np.ndarray, specular: np.ndarray | None) -> list[Layer]:
    """``specular`` (given, working-space RGB) and the coverage-weighted material maps; none if matte."""
    if specular is None:
        return []
    mats = s.scene.materials
    glossy = np.array([[float(m.kind != "diffuse")] for m in mats])
    metal = np.array([[float(m.kind == "conductor")] for m in mats])
    alpha = np.array([[m.roughness if m.kind != "diffuse" else 1.0] for m in mats])
    return _shared_layers(specular, coverage, glossy, metal, alpha) + _glass_layers(s, coverage)


def _glass_layers(s: SampleInputs, coverage: np.ndarray) -> list[Layer]:
    """``transmissive``, in scenes with glass only."""
    glass = np.array([[float(m.transmissive)] for m in s.scene.materials])
    if not glass.any():
        return []
    return [
        make_layer(
            "transmissive",
            coverage_weighted(coverage, glass)[..., 0],
            ("Y",),
            "fraction of the pixel covered by glass (dielectric, thindielectric: no diffuse "
            "lobe, reflectance 0; all that is seen in and through it, its reflection and "
            "transmission chains, is in specular; non_diffuse counts it too, metallic counts "
            "mirrors); 0 background",
            "geometry",
            nonnegative=True,
        )
    ]


def _shared_layers(
    specular: np.ndarray,
    coverage: np.ndarray,
    glossy: np.ndarray,
    metal: np.ndarray,
    alpha: np.ndarray,
) -> list[Layer]:
    """``specular``, ``non_diffuse``, ``metallic`` and ``roughness``."""
    return [
        make_layer(
            SPECULAR,
            specular,
            RGB,
            UNITS_IMAGE + "; light the first hit returns through its non-diffuse lobes (coat "
            "reflection, metal), with everything those lobes reflect; not denoised",
            "intrinsics",
        ),
        make_layer(
            "non_diffuse",
            coverage_weighted(coverage, glossy)[..., 0],
            ("Y",),
            "fraction of the pixel covered by materials with a non-diffuse lobe (plastic, "
            "conductor); 0 background",
            "geometry",
            nonnegative=True,
        ),
        make_layer(
            "metallic",
            coverage_weighted(coverage, metal)[..., 0],
            ("Y",),
            "fraction of the pixel covered by metals (no diffuse lobe: reflectance 0 there "
            "means metal, not black paint); 0 background",
            "geometry",
            nonnegative=True,
        ),
        make_layer(
            "roughness",
            coverage_weighted(coverage, alpha)[..., 0],
            ("Y",),
            "coverage-weighted GGX alpha of the surface lobe (0 smooth; 1 for Lambertian "
            "surfaces); 0 background",
            "geometry",
            nonnegative=True,
        ),
    ]
