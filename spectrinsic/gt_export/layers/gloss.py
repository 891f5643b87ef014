"""The gloss family: ``specular``, ``non_diffuse``, ``metallic`` and ``roughness``, for scenes
with glossy materials (:class:`~spectrinsic.scenes.model.Material` ``plastic``/``conductor``).

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
"""

from __future__ import annotations

import numpy as np

from ...render.algebra.shares import SPECULAR as SPECULAR_PART
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
#: :data:`~spectrinsic.render.algebra.shares.SPECULAR`), and the specular term's role in an
#: identity (``meta.json["identities"]``); every module naming the layer imports it from here.
SPECULAR = SPECULAR_PART
#: The per-band specular layer (``spectral.exr``).
SPECULAR_BANDS = f"{SPECULAR}_bands"


def specular_raw(s: SampleInputs) -> np.ndarray | None:
    """``(H, W, K)`` float64 raw specular channels of the reference mode, or ``None`` (matte)."""
    spec = getattr(s.result, "specular", None) or {}
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
