"""The image family: ``image`` (the reference mode), the other modes, their error maps (Eq. 5.7)
and the raw multispectral ``cube``.
"""

from __future__ import annotations

import numpy as np

from ...errors import DatasetError
from ...render.algebra.modes import RENDER_MODES
from ...spectra import get_sensors
from .imaging import relative_error_map
from .records import RGB, UNITS_IMAGE, Layer, SampleInputs, make_layer

# Responses with the light's white at Y = 1; under D65 with sRGB sensors, the canonical p^{s,c}.

__all__ = ["image_layers", "cube_layer"]


def _shares_paths(mode: str, reference: str) -> bool:
    """Whether two render modes trace the same light paths (both K-channel diagonal passes of
    one scene, same seed and spp), so that their per-pixel difference is purely spectral."""
    return all(m in RENDER_MODES and RENDER_MODES[m].kind == "diagonal" for m in (mode, reference))


def image_layers(s: SampleInputs) -> list[Layer]:
    """``image`` (the reference mode), every other mode, and error maps of the modes that
    share the reference's light paths (Eq. 5.7 per pixel)."""
    ref_xyz = np.asarray(s.result.images[s.ref], float)
    out = [
        make_layer(
            "image",
            s.space.rgb(ref_xyz),
            RGB,
            UNITS_IMAGE + f"; render mode {s.ref!r}",
            "image",
        )
    ]
    for mode in sorted(m for m in s.result.images if m != s.ref):
        xyz = np.asarray(s.result.images[mode], float)
        out.append(
            make_layer(
                f"image_{mode}",
                s.space.rgb(xyz),
                RGB,
                UNITS_IMAGE + f"; render mode {mode!r}",
                "image",
            )
        )
        if _shares_paths(mode, s.ref):  # else independent paths: the difference would be noise
            out.append(
                make_layer(
                    f"error_{mode}",
                    relative_error_map(xyz, ref_xyz),
                    ("Y",),
                    f"dimensionless ‖XYZ_{mode} − XYZ_{s.ref}‖₂ / ‖XYZ_{s.ref}‖₂ per pixel (0 where unlit)",
                    "image",
                    nonnegative=True,
                )
            )
    return out


def cube_layer(s: SampleInputs, cube_name: str | None) -> Layer:
    if cube_name is None:
        raise DatasetError("write_cube needs the 31-band cube (render mode 'bands31')")
    cube = np.asarray(s.result.raw["bands31"], float)
    band_set = get_sensors(cube_name, data_dir=s.data_dir)
    if band_set.n != cube.shape[-1]:
        raise DatasetError(
            f"cube has {cube.shape[-1]} channels but its sensors {cube_name!r} have {band_set.n}"
        )
    return make_layer(
        "cube",
        cube,
        band_set.channels,
        f"band radiance ∫ L B_b dλ (render units) for the bands of {cube_name!r}",
        "cube",
        nonnegative=True,
    )
