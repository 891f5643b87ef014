"""Spectral irradiance at every pixel, and the shading-illumination layers derived from it.

For a Lambertian surface the outgoing radiance is ``L_o(λ) = ρ(λ) E(λ, x) / π`` at every
wavelength, with ``E`` the spectral irradiance arriving at ``x``, interreflections included.
A K-band diagonal pass multiplies channel by channel along each path, so in the band cube

    cube_k(x) = ρ_k · E_k(x) / π,      ρ_k = ∫ ρ S_k dλ / ∫ S_k dλ                    (1)

holds per band and per single-material pixel (``ρ_k`` are the very values the renderer gave
the material, :func:`spectrinsic.render.channel_values`). A pixel shared by several materials
(coverage ``c_m``, from the same pixel samples as the colour passes) gives
``cube_k = Σ_m c_m ρ_mk E_mk / π``; dividing by the coverage-weighted albedo ``Σ_m c_m ρ_mk``
returns the albedo-weighted mean of the materials' irradiances, which is ``E_k`` wherever they
see the same light. ``W_k = E_k / π`` is the radiance a perfect white surface would reflect at
``x``: the *white-surface radiance*, in the render units of ``image``.

From ``W`` (one function per layer, all pure):

* ``shading``: the colour of ``W`` in a sensor space, relative to that space's perfect white
  under D65 (``(1, 1, 1)`` to 1e-4 for linear sRGB), clipped at 0. So a grey surface under any
  light, and any surface under D65 without interreflection, has ``image = reflectance ∘ shading``;
* ``residual = image − reflectance ∘ shading``: what light and surface do not multiply channel
  by channel (spectral non-commutativity), plus the out-of-gamut part removed by the clip;
* ``shading_grey``: the luminance ``Y`` of ``W``;
* ``illuminant``: ``shading / shading_grey``, the colour of the light that arrives, at unit
  luminance;
* per-light shares of ``Y(W)`` from the per-light renders.

Where surfaces cover less than :data:`COVERAGE_MIN` of a pixel (background, light sources,
silhouette fringes) ``W`` is undefined: every layer is 0 there and ``residual = image``.

``W`` comes from the render of the reference ``image`` itself, so the residual holds no Monte
Carlo difference between renders: the 31-band cube when rendered (exact per band), else the
3- or 6-band diagonal render, or the spectral render's XYZ divided by the materials' XYZ-band
albedos (a 3-band estimate; the residual then also holds its spectral error).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import DatasetError
from ...render.algebra.batch_means import relative_standard_error

__all__ = [
    "COVERAGE_MIN",
    "ALBEDO_FLOOR",
    "WhiteRadiance",
    "white_radiance",
    "coverage_albedo",
    "covered",
    "relative_shading",
    "luminance_of",
    "unit_luminance",
    "residual",
    "recompose",
    "unlit_masked",
    "share_maps",
    "relative_standard_error",
    "noise_figures",
]

#: Fraction of a pixel that surfaces must cover for its irradiance to be estimated.
COVERAGE_MIN = 0.5
#: Coverage-weighted band albedo below which a band's irradiance is not observable (a material
#: black in that band reflects nothing to measure it by); the division uses this floor instead.
ALBEDO_FLOOR = 1e-4


@dataclass(frozen=True, eq=False)
class WhiteRadiance:
    """The white-surface radiance ``W_k = E_k / π`` of one rendered image.

    Attributes
    ----------
    mode
        Render mode whose raw channels it comes from.
    bands
        ``(H, W, K)`` float64, render units; 0 where not :attr:`valid`.
    albedo
        ``(H, W, K)`` coverage-weighted band albedo ``Σ_m c_m ρ_mk`` it was divided by.
    valid
        ``(H, W)`` bool, surfaces cover at least :data:`COVERAGE_MIN` of the pixel.
    to_xyz
        ``(3, K)`` the mode's map from raw channels to CIE 1931 XYZ.
    """

    mode: str
    bands: np.ndarray = field(repr=False)
    albedo: np.ndarray = field(repr=False)
    valid: np.ndarray = field(repr=False)
    to_xyz: np.ndarray = field(repr=False)

    def with_bands(self, bands: np.ndarray) -> WhiteRadiance:
        """The same record with other band values (a batch, or the denoised estimate)."""
        return WhiteRadiance(
            self.mode,
            np.where(self.valid[..., None], bands, 0.0),
            self.albedo,
            self.valid,
            self.to_xyz,
        )

    def from_raw(self, raw: np.ndarray) -> WhiteRadiance:
        """``W`` of other raw channels of the same pixels (an independent batch), Eq. 1."""
        return self.with_bands(np.asarray(raw, np.float64) / np.maximum(self.albedo, ALBEDO_FLOOR))

    def xyz(self) -> np.ndarray:
        """``(H, W, 3)`` CIE XYZ of ``W`` (render units)."""
        return np.einsum("hwk,ck->hwc", self.bands, self.to_xyz)

    def surface(self) -> np.ndarray:
        """``(H, W, K)`` raw channels of the surfaces themselves, ``albedo ∘ W`` (Eq. 1)."""
        return self.albedo * self.bands


def white_radiance(
    raw: np.ndarray,
    coverage: np.ndarray,
    band_albedos: np.ndarray,
    to_xyz: np.ndarray,
    *,
    mode: str,
    metal_white: np.ndarray | None = None,
    metal_coverage: np.ndarray | None = None,
) -> WhiteRadiance:
    """``W = raw / (coverage @ band_albedos)`` per band (Eq. 1), 0 where surfaces cover less than
    :data:`COVERAGE_MIN` of the pixel.

    Metals have no diffuse lobe (albedo 0); their ``W`` is the white-surface radiance the
    renderer estimated at their hits, ``metal_white = c_metal · W_metal``
    (:mod:`spectrinsic.render.band_path.kernel`). So a metal counts as a white surface in both the
    numerator and the denominator: ``W = (raw + metal_white) / (coverage @ band_albedos +
    c_metal)``, which is ``W_metal`` on a metal-only pixel and Eq. 1 where there is no metal.

    Parameters
    ----------
    raw
        ``(H, W, K)`` raw channels of a diagonal render (or XYZ of the spectral one).
    coverage
        ``(H, W, M)`` fraction of each pixel's samples hitting material m.
    band_albedos
        ``(M, K)`` ``∫ρ_m S_k / ∫S_k``, the channel values the renderer gave each material.
    to_xyz
        ``(3, K)`` the mode's raw -> XYZ matrix.

    >>> cov = np.ones((1, 1, 1)); rho = np.array([[0.5, 0.25]])
    >>> white_radiance(np.array([[[1.0, 1.0]]]), cov, rho, np.eye(3)[:, :2], mode="x").bands.tolist()
    [[[2.0, 4.0]]]
    """
    raw = np.asarray(raw, np.float64)
    coverage = np.asarray(coverage, np.float64)
    band_albedos = np.asarray(band_albedos, np.float64)
    if coverage.shape[-1] != band_albedos.shape[0] or raw.shape[-1] != band_albedos.shape[-1]:
        raise DatasetError(
            f"irradiance from {mode!r}: raw {raw.shape}, coverage {coverage.shape} and band "
            f"albedos {band_albedos.shape} do not match"
        )
    albedo = coverage_albedo(coverage, band_albedos)
    valid = covered(coverage)
    if metal_white is None or metal_coverage is None:
        bands = np.where(valid[..., None], raw / np.maximum(albedo, ALBEDO_FLOOR), 0.0)
    else:
        total = raw + np.asarray(metal_white, np.float64)
        weight = albedo + np.asarray(metal_coverage, np.float64)[..., None]
        bands = np.where(valid[..., None], total / np.maximum(weight, ALBEDO_FLOOR), 0.0)
    return WhiteRadiance(mode, bands, albedo, valid, np.asarray(to_xyz, np.float64))


def coverage_albedo(coverage: np.ndarray, band_albedos: np.ndarray) -> np.ndarray:
    """``(H, W, K)`` coverage-weighted band albedo ``Σ_m c_m ρ_mk`` in float64, summed material
    by material in index order with elementwise operations only, so every machine and numpy
    build gives the same bits (readers rebuild ``reflectance_bands`` from it and compare its
    SHA-256; an ``einsum``'s summation order depends on the SIMD width).

    Each material is added only on the pixels it covers (``c_m != 0``): a pixel covers one or
    two of a room's 19 materials, and the term ``0 · ρ_mk`` left out elsewhere is a zero, whose
    addition changes no bit of a sum that starts at ``+0`` (which is never ``-0``). So the
    result is that of the sum over every material, in a fifth of the time (60 against 300 ms
    at 256², measured 5 December 2026); with a non-finite albedo (``0 · inf`` is NaN, not a
    zero) every pixel is summed.

    >>> coverage_albedo(np.array([[[0.25, 0.75]]]), np.array([[1.0, 0.0], [0.5, 1.0]])).tolist()
    [[[0.625, 0.75]]]
    """
    coverage = np.asarray(coverage, np.float64)
    band_albedos = np.asarray(band_albedos, np.float64)
    flat = coverage.reshape(-1, coverage.shape[-1])
    out = np.zeros((flat.shape[0], band_albedos.shape[-1]))
    every_pixel = not np.isfinite(band_albedos).all()
    for m in range(band_albedos.shape[0]):
        pixels = slice(None) if every_pixel else np.flatnonzero(flat[:, m])
        out[pixels] += flat[pixels, m, None] * band_albedos[m]
    return out.reshape(*coverage.shape[:-1], band_albedos.shape[-1])


def covered(coverage: np.ndarray) -> np.ndarray:
    """``(H, W)`` whether surfaces cover at least :data:`COVERAGE_MIN` of each pixel (the
    coverage summed material by material in index order, as :func:`coverage_albedo`)."""
    coverage = np.asarray(coverage, np.float64)
    total = np.zeros(coverage.shape[:-1])
    for m in range(coverage.shape[-1]):
        total += coverage[..., m]
    return total >= COVERAGE_MIN


def relative_shading(
    colour: np.ndarray, white: np.ndarray, valid: np.ndarray, *, clip: bool = True
) -> np.ndarray:
    """Shading in a sensor space: ``max(colour / white, 0)`` (``colour / white`` without
    *clip*), 0 where not *valid*.

    *colour* ``(H, W, 3)`` is ``W`` seen by the space's sensors; *white* ``(3,)`` is the space's
    response to the perfect white under D65 at unit luminance (its reflectance of white), so
    ``reflectance ∘ shading`` reproduces a white or grey surface exactly. Negative values
    (light out of the space's gamut after bounces off saturated surfaces) are clipped if
    *clip*; the residual keeps them.
    """
    shading = np.asarray(colour, np.float64) / np.asarray(white, np.float64)
    return np.where(valid[..., None], np.clip(shading, 0.0, None) if clip else shading, 0.0)


def luminance_of(radiance: WhiteRadiance) -> np.ndarray:
    """``(H, W)`` luminance Y of ``W``: the grey shading (render units), ≥ 0."""
    return np.clip(radiance.xyz()[..., 1], 0.0, None)


def unit_luminance(shading: np.ndarray, grey: np.ndarray) -> np.ndarray:
    """``shading / grey``: the light's colour at unit luminance, 0 where no light arrives."""
    lit = grey > 0
    return np.where(lit[..., None], shading / np.where(lit, grey, 1.0)[..., None], 0.0)


def residual(
    image: np.ndarray,
    reflectance: np.ndarray,
    shading: np.ndarray,
    specular: np.ndarray | None = None,
) -> np.ndarray:
    """``image − reflectance ∘ shading [− specular]``, so ``image = reflectance ∘ shading
    [+ specular] + residual``.

    Computed from the float32 values that are stored, in float64, so the identity holds on
    the stored layers to float32 rounding of the residual alone.
    """
    f32 = np.float32
    out = np.asarray(image, f32).astype(np.float64) - np.asarray(reflectance, f32).astype(
        np.float64
    ) * np.asarray(shading, f32).astype(np.float64)
    return out if specular is None else out - np.asarray(specular, f32).astype(np.float64)


def unlit_masked(
    estimate: WhiteRadiance, raw: WhiteRadiance, batches: tuple[np.ndarray, ...] = ()
) -> WhiteRadiance:
    """*estimate* (a denoised ``W``) set to exactly 0 at the pixels where no light arrives: the
    raw ``W`` and the raw channels of every independent batch are 0 in every band there, and so
    are most of its 8 neighbours. A denoiser spreads light from lit neighbours into such
    pixels, and ``illuminant`` divides by the tiny luminance it leaves (saturated colours); the
    layers are documented as 0 there. A pixel whose samples all missed the light but whose
    neighbours mostly saw it (:data:`HOLE_NEIGHBOURS` of 8 or more) is a sampling hole of a lit
    region, not a shadow: it keeps the estimate (``room-corner`` at the preview preset, 4 spp:
    15 of 2304 covered pixels of ``image_denoised`` were exactly 0, black specks, and 7 are now;
    the 7 lie in clusters of unlit pixels)."""
    seen = np.any(raw.bands != 0, axis=-1)
    for batch in batches:
        seen |= np.any(np.asarray(batch) != 0, axis=-1)
    lit = seen | (_lit_neighbours(seen) >= HOLE_NEIGHBOURS)
    return estimate.with_bands(np.where(lit[..., None], estimate.bands, 0.0))


#: Lit neighbours (of 8) that make an unlit pixel a sampling hole of a lit region.
HOLE_NEIGHBOURS = 5


def _lit_neighbours(lit: np.ndarray) -> np.ndarray:
    """``(H, W)`` count of the 8 neighbours of each pixel that are lit (outside the image:
    unlit)."""
    padded = np.pad(lit.astype(np.int32), 1)
    h, w = lit.shape
    return sum(  # type: ignore[return-value]
        padded[1 + dy : 1 + dy + h, 1 + dx : 1 + dx + w]
        for dy in (-1, 0, 1)
        for dx in (-1, 0, 1)
        if dy or dx
    )


def recompose(radiance: WhiteRadiance, raw: np.ndarray) -> np.ndarray:
    """Raw channels of the image rebuilt from ``W`` (Eq. 1) where valid, *raw* elsewhere."""
    return np.where(radiance.valid[..., None], radiance.surface(), np.asarray(raw, np.float64))


def share_maps(per_light_y: np.ndarray) -> np.ndarray:
    """``(H, W, L)`` each light's fraction of the light arriving, from per-light luminances.

    *per_light_y* is ``(L, H, W)`` luminance of each light's own render. At a pixel every
    light's render sees the same surface, so the ratio of their luminances is the ratio of the
    irradiances' luminances. Shares sum to 1 where any light arrives, 0 elsewhere.
    """
    y = np.clip(np.asarray(per_light_y, np.float64), 0.0, None)
    total = y.sum(axis=0)
    lit = total > 0
    return np.moveaxis(np.where(lit, y / np.where(lit, total, 1.0), 0.0), 0, -1)


def noise_figures(rel_se: np.ndarray, valid: np.ndarray) -> dict[str, float | int]:
    """Median, 95th percentile and RMS of a relative-standard-error map over *valid* pixels.

    The RMS is the unbiased figure: with two batches each pixel's estimate has one degree of
    freedom, so its median sits at about 0.67 of the typical standard error.
    """
    values = rel_se[valid & (rel_se > 0)]
    if not values.size:
        return {"median": 0.0, "p95": 0.0, "rms": 0.0, "pixels": 0}
    return {
        "median": float(np.median(values)),
        "p95": float(np.percentile(values, 95)),
        "rms": float(np.sqrt(np.mean(values**2))),
        "pixels": int(values.size),
    }
