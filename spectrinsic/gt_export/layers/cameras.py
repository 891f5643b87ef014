"""The camera family: camera images from the 31-band cube, relative reflectance, camera shading,
and the chapter-4 matrices of the scene's lights.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ...spectra import get_sensors, get_spectrum

# Responses with the light's white at Y = 1; under D65 with sRGB sensors, the canonical p^{s,c}.
from ...spectra import white_normalised_responses as canonical_responses
from ..formats.names import camera_slug
from . import irradiance as irr
from .gloss import diffuse_raw
from .imaging import coverage_weighted
from .intrinsics import shading_set
from .records import (
    RGB,
    UNITS_CAMERA,
    Layer,
    SampleInputs,
    camera_key,
    cube_sensor_name,
    make_layer,
)
from .spectral import camera_curves, cube_to_sensors, photometric_matrices

__all__ = ["camera_layers", "matrices_of"]


def camera_layers(
    s: SampleInputs,
    cam: str,
    curves: np.ndarray,
    coverage: np.ndarray,
    w: irr.WhiteRadiance,
    *,
    denoised: bool,
) -> list[Layer]:
    """Camera image from the cube, relative reflectance, and shading/residual/illuminant from
    ``W`` in the camera's RGB (relative to its own white under D65)."""
    band_set = get_sensors(cube_sensor_name(s.result), data_dir=s.data_dir)
    weights = cube_to_sensors(
        band_set.curves,
        camera_curves(cam, band_set.wavelengths, data_dir=s.data_dir),
        band_set.wavelengths,
    )
    key = camera_key(cam)
    slug = "camera-" + camera_slug(key)
    image = np.asarray(s.result.raw["bands31"], float) @ weights.T
    refl = coverage_weighted(coverage, canonical_responses(s.material_rho, s.d65, curves, s.wl))
    white = canonical_responses(np.ones(s.wl.size), s.d65, curves, s.wl)
    out = [
        make_layer(f"image_camera/{key}", image, RGB, UNITS_CAMERA, slug, nonnegative=True),
        make_layer(
            f"reflectance_camera/{key}",
            refl,
            RGB,
            "dimensionless relative reflectance S_Sen·I^a: camera RGB under D65 "
            "(perfect white has mean channel 1)",
            slug,
            nonnegative=True,
        ),
    ]
    spec = s.result.specular.get("bands31")
    specular = None if spec is None else np.asarray(spec, float) @ weights.T
    if specular is not None:
        out.append(
            make_layer(
                f"specular_camera/{key}",
                specular,
                RGB,
                UNITS_CAMERA + "; the specular layer in camera RGB",
                slug,
            )
        )
    used = image
    if denoised:
        used = irr.recompose(w, diffuse_raw(s, s.result.raw["bands31"])) @ weights.T
        used = used if specular is None else used + specular
        out.append(
            make_layer(
                f"image_camera_denoised/{key}",
                used,
                RGB,
                UNITS_CAMERA + "; rebuilt from the denoised white-surface radiance",
                slug,
            )
        )
    names = (f"shading_camera/{key}", f"residual_camera/{key}", f"illuminant_camera/{key}")
    return out + shading_set(
        w,
        w.bands @ weights.T,
        white,
        used,
        refl,
        names=names,
        group=slug,
        space="camera RGB",
        specular=specular,
    )


def matrices_of(
    s: SampleInputs, shares: np.ndarray, spaces: Mapping[str, np.ndarray], training: Any
) -> dict[str, Any]:
    """The chapter-4 matrices for the scene's effective light and for each light."""
    spds = [get_spectrum(light.spectrum, data_dir=s.data_dir).on(s.wl) for light in s.scene.lights]
    illum: dict[str, np.ndarray] = {}
    if spds:
        illum["scene"] = np.einsum("l,lw->w", shares, np.stack(spds))
        illum.update({f"light {i}": spd for i, spd in enumerate(spds)})
    matrices = photometric_matrices(illum, spaces, s.wl, training=training) if illum else {}
    matrices["convention"] = (
        "p = M @ q on column vectors; S_Sen: canonical (D65, sRGB) -> camera under D65; "
        "L_CLig: sensor space under D65 -> under the illuminant; 'scene' is the share-weighted "
        "mix of the lights; least squares over the 1269 Munsell chips, lights at unit luminance"
    )
    return {
        k: ({camera_key(c): v for c, v in m.items()} if isinstance(m, dict) else m)
        for k, m in matrices.items()
    }
