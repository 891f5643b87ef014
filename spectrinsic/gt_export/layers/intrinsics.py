"""The intrinsic family: shading from the spectral irradiance, residual, grey shading, illuminant,
the ratio shading, the noise maps of independent batches and the out-of-gamut clip
(:mod:`spectrinsic.gt_export.layers.irradiance`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...render.algebra.modes import channel_values, get_mode, to_xyz_matrix
from ...render.result import METAL_WHITE
from ...spectra import get_sensors
from . import irradiance as irr
from .gloss import diffuse_raw
from .imaging import shading_ratio
from .records import REFLECTANCE_FLOOR, RGB, UNITS_IMAGE, Layer, SampleInputs, make_layer

__all__ = [
    "band_albedos",
    "white_radiance",
    "rgb_white",
    "rgb_of",
    "shading_set",
    "intrinsic_layers",
    "noise_of",
    "clipping_of",
    "from_denoised",
]


_RESIDUAL_UNITS = (
    "image − reflectance ∘ shading (render units): spectral non-commutativity and "
    "out-of-gamut light; the image itself where no surface"
)
_RESIDUAL_UNITS_GLOSSY = (
    "image − reflectance ∘ shading − specular (render units): spectral "
    "non-commutativity and out-of-gamut light; the image less specular where no surface"
)


def _as_stored(values: np.ndarray) -> np.ndarray:
    """*values* as a float32 layer stores them, in float64: a layer computed from stored
    layers this way is rebuilt bit for bit from them (:mod:`spectrinsic.gt_export.sample.layer_storage`)."""
    return np.asarray(values, np.float32).astype(np.float64)


def band_albedos(s: SampleInputs) -> np.ndarray:
    """``(M, K)`` channel albedo of every material in the reference mode's channels, the values
    the renderer gave them (Eq. 5.4 normalised); a pixel's is ``coverage @ band_albedos``."""
    sensors = (s.result.meta or {}).get("sensors", {}).get(s.ref, get_mode(s.ref).sensors)
    return channel_values(
        s.scene, get_sensors(sensors, data_dir=s.data_dir), data_dir=s.data_dir
    ).materials


def white_radiance(s: SampleInputs, coverage: np.ndarray) -> irr.WhiteRadiance:
    """``W = E/π`` from the reference render, Eq. 1 of
    :mod:`~spectrinsic.gt_export.layers.irradiance`, with the band albedos the renderer used."""
    mode = get_mode(s.ref)
    albedos = band_albedos(s)
    matrices = s.result.meta.get("to_xyz", {})
    to_xyz = (
        np.asarray(matrices[s.ref], float)
        if s.ref in matrices
        else to_xyz_matrix(mode, s.scene, data_dir=s.data_dir)
    )
    raw = s.result.raw[s.ref] if s.ref in s.result.raw else s.result.images[s.ref]
    metals = np.array([m.non_diffuse for m in s.scene.materials], bool)
    metal_white = s.result.parts.get(METAL_WHITE, {}).get(s.ref)
    # W of the first hits' diffuse lobes only: the specular part is its own layer; at metals
    # the renderer's white-surface estimate
    return irr.white_radiance(
        diffuse_raw(s, raw),
        coverage,
        albedos,
        to_xyz,
        mode=s.ref,
        metal_white=metal_white,
        metal_coverage=coverage[..., metals].sum(axis=-1) if metal_white is not None else None,
    )


def rgb_white(s: SampleInputs) -> np.ndarray:
    """The working space's colour of the perfect white under D65 at Y = 1 (``(3,)``)."""
    return np.asarray(s.space.white, np.float64)


def rgb_of(s: SampleInputs, w: irr.WhiteRadiance) -> np.ndarray:
    """``(H, W, 3)`` working-space RGB of ``W`` (render units)."""
    return s.space.rgb(w.xyz())


def shading_set(
    w: irr.WhiteRadiance,
    colour: np.ndarray,
    white: np.ndarray,
    image: np.ndarray,
    reflectance: np.ndarray,
    *,
    names: tuple[str, ...],
    group: str,
    space: str,
    specular: np.ndarray | None = None,
    clip: bool = True,
) -> list[Layer]:
    """``shading``, ``residual`` and, if a third name is given, ``illuminant`` of one sensor
    space from ``W``'s colour (the residual less *specular*, if given); the shading clipped at
    0 if *clip*, else its negative (out-of-gamut) components kept."""
    shading = irr.relative_shading(colour, white, w.valid, clip=clip)
    grey = irr.luminance_of(w)
    sign = "≥ 0" if clip else "negative components kept"
    layers = [
        make_layer(
            names[0],
            shading,
            RGB,
            f"shading-illumination: {space} of the light a perfect white would reflect here "
            f"(render units, relative to that space's white under D65; {sign}, 0 where no "
            "surface)",
            group,
            nonnegative=clip,
        ),
        make_layer(
            names[1],
            irr.residual(image, reflectance, shading, specular),
            RGB,
            _RESIDUAL_UNITS if specular is None else _RESIDUAL_UNITS_GLOSSY,
            group,
        ),
    ]
    if len(names) > 2:
        layers.append(
            make_layer(
                names[2],
                # of the stored (float32) shading and grey: readers rebuild it bit for bit
                irr.unit_luminance(_as_stored(shading), _as_stored(grey)),
                RGB,
                f"{space} colour of the light arriving at unit luminance "
                "(D65 = (1, 1, 1)); 0 where none arrives",
                group,
                nonnegative=clip,
            )
        )
    return layers


def _denoised_image(
    s: SampleInputs,
    w_raw: irr.WhiteRadiance,
    w: irr.WhiteRadiance,
    image: np.ndarray,
    reflectance: np.ndarray,
    specular: np.ndarray | None,
) -> tuple[np.ndarray, list[Layer]]:
    """``image_denoised`` (the reflectance-weighted denoised ``W`` plus the raw *specular*) and
    the raw shading and residual it replaces, ``shading_raw``/``residual_raw``."""
    white = rgb_white(s)
    out: list[Layer] = []
    raw = s.result.raw[s.ref] if s.ref in s.result.raw else s.result.images[s.ref]
    used = s.space.rgb(np.einsum("hwk,ck->hwc", irr.recompose(w, diffuse_raw(s, raw)), w.to_xyz))
    used = used if specular is None else used + specular
    out.append(
        make_layer(
            "image_denoised",
            used,
            RGB,
            UNITS_IMAGE + "; rebuilt as reflectance-weighted denoised white-surface "
            "radiance (the raw image where no surface)"
            + ("" if specular is None else ", plus the raw specular layer"),
            "image",
        )
    )
    out += shading_set(
        w_raw,
        rgb_of(s, w_raw),
        white,
        image,
        reflectance,
        space=_space_words(s),
        names=("shading_raw", "residual_raw"),
        group="intrinsics",
        specular=specular,
        clip=s.space.clip_shading,
    )
    return used, out


def intrinsic_layers(
    s: SampleInputs,
    w_raw: irr.WhiteRadiance,
    w: irr.WhiteRadiance,
    image: np.ndarray,
    reflectance: np.ndarray,
    *,
    denoised: bool,
    specular: np.ndarray | None = None,
) -> list[Layer]:
    """Working-space shading, residual and illuminant (from the denoised ``W`` if asked, with
    ``image_denoised`` rebuilt from it plus the raw *specular*, and the raw ``shading_raw``/
    ``residual_raw``), grey shading and ratio shading."""
    white = rgb_white(s)
    used = image
    out: list[Layer] = []
    if denoised:
        used, denoised_layers = _denoised_image(s, w_raw, w, image, reflectance, specular)
        out += denoised_layers
    out += shading_set(
        w,
        rgb_of(s, w),
        white,
        used,
        reflectance,
        space=_space_words(s),
        names=("shading", "residual", "illuminant"),
        group="intrinsics",
        specular=specular,
        clip=s.space.clip_shading,
    )
    out.append(
        make_layer(
            "shading_grey",
            irr.luminance_of(w),
            ("Y",),
            "luminance Y of the light a perfect white would reflect (render units)",
            "intrinsics",
            nonnegative=True,
        )
    )
    out.append(
        make_layer(
            "shading_ratio",
            shading_ratio(_as_stored(image), _as_stored(reflectance)),
            RGB,
            "image / reflectance per channel (thesis Fig. 5.8; ill-conditioned where a "
            f"reflectance channel is small); 0 where |reflectance| <= {REFLECTANCE_FLOOR:g}",
            "intrinsics",
        )
    )
    return out


def noise_of(s: SampleInputs, w: irr.WhiteRadiance) -> tuple[list[Layer], dict[str, Any]]:
    """Relative standard error maps of ``image`` and ``shading`` from the independent batches."""
    batches = [b[s.ref] for b in s.result.batch_raw if s.ref in b]
    if len(batches) < 2:
        return [], {}
    white = rgb_white(s)
    clip = s.space.clip_shading
    images = [
        s.space.rgb(np.einsum("hwk,ck->hwc", np.asarray(b, float), w.to_xyz)) for b in batches
    ]
    shadings = [
        irr.relative_shading(rgb_of(s, w.from_raw(b)), white, w.valid, clip=clip) for b in batches
    ]
    lit = w.valid
    maps = {
        "image": irr.relative_standard_error(images, lit),
        "shading_raw": irr.relative_standard_error(shadings, lit),
    }
    layers = [
        make_layer(
            f"noise_{k}",
            v,
            ("Y",),
            f"relative standard error of the raw {k.removesuffix('_raw')} per pixel, "
            f"‖se‖₂/‖mean‖₂ over channels, from {len(batches)} independent batches",
            "noise",
            nonnegative=True,
        )
        for k, v in maps.items()
    ]
    figures: dict[str, Any] = {k: irr.noise_figures(v, lit) for k, v in maps.items()}
    figures["batches"] = len(batches)
    return layers, figures


def _space_words(s: SampleInputs) -> str:
    return f"linear {s.space.colourspace}"


def clipping_of(colour: np.ndarray, lit: np.ndarray) -> dict[str, float]:
    """How much of the working-space shading is out of gamut (a negative component): the
    share of lit pixels, and the negative part's norm relative to the shading's. The ``srgb``
    space clips it into the residual; the others keep it in the shading."""
    values = colour[lit]
    if not values.size:
        return {"pixels": 0.0, "mean": 0.0, "max": 0.0}
    clipped = np.linalg.norm(np.clip(values, None, 0.0), axis=-1)
    rel = clipped / np.maximum(np.linalg.norm(values, axis=-1), np.finfo(float).tiny)
    hit = clipped > 0
    return {
        "pixels": float(hit.mean()),
        "mean": float(rel[hit].mean()) if hit.any() else 0.0,
        "max": float(rel.max()),
    }


def from_denoised(name: str) -> bool:
    base = name.split("/", 1)[0]
    return base in (
        "image_denoised",
        "shading",
        "residual",
        "illuminant",
        "shading_grey",
        "light_share",
        "image_camera_denoised",
        "shading_camera",
        "residual_camera",
        "illuminant_camera",
        "image_bands",
        "shading_bands",
        "residual_bands",
    )
