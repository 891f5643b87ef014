"""Mitsuba plugin dictionaries spectrinsic builds: spectra, films and integrators.

Units: spectra are per-nm values on wavelengths in nm; films are linear HDR (``hdrfilm``,
``specfilm``) with the box reconstruction filter, so a pixel is the mean of its samples.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ...errors import SceneError

#: A spectrum whose largest value is below this (per nm) is written as Mitsuba's ``uniform``
#: spectrum of value 0: ``regular``/``irregular`` build a sampling distribution from their
#: values, which fails with no probability mass for an all-zero (or float32-underflowing)
#: spectrum such as a black material (``flat:0``, soot, velvet).
BLACK_SPECTRUM = 1e-30
#: Longest path (``max_depth``) spectrinsic asks of Mitsuba: far beyond what converges (each
#: bounce multiplies by a reflectance <= 1), and with ``rr_depth`` = depth + 1 inside the
#: 32-bit integer Mitsuba's ``path`` plugin takes.
MAX_PATH_DEPTH = 1024

__all__ = [
    "BLACK_SPECTRUM",
    "MAX_PATH_DEPTH",
    "rgb_spectrum",
    "regular_spectrum",
    "black_bsdf",
    "raw_bitmap",
    "hdr_film",
    "spectral_film",
    "path_integrator",
    "aov_integrator",
]


def rgb_spectrum(values: Sequence[float]) -> dict[str, Any]:
    """A 3-channel value for an RGB variant (a diagonal pass's channel values, unclamped)."""
    v = np.asarray(values, float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise SceneError(f"channel values {values!r}: expected 3 finite numbers")
    return {"type": "rgb", "value": [float(x) for x in v]}


def regular_spectrum(values: np.ndarray, wavelengths: np.ndarray) -> dict[str, Any]:
    """A spectrum for the spectral variant: *values* on *wavelengths* (nm), linearly interpolated.

    Uses Mitsuba's ``regular`` plugin on an evenly spaced grid, ``irregular`` otherwise, and
    a ``uniform`` 0 (which needs no sampling distribution) for a black spectrum, whose values
    are all below :data:`BLACK_SPECTRUM`.
    """
    wl = np.asarray(wavelengths, float)
    v = np.asarray(values, float)
    if np.all(np.abs(v) < BLACK_SPECTRUM):
        return {"type": "uniform", "value": 0.0}
    text = ", ".join(f"{x:.9g}" for x in v)
    if np.allclose(np.diff(wl), wl[1] - wl[0]):
        return {
            "type": "regular",
            "wavelength_min": float(wl[0]),
            "wavelength_max": float(wl[-1]),
            "values": text,
        }
    return {"type": "irregular", "wavelengths": ", ".join(f"{x:.9g}" for x in wl), "values": text}


def black_bsdf() -> dict[str, Any]:
    """Two-sided black Lambertian BSDF (area-light geometry)."""
    return {
        "type": "twosided",
        "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}},
    }


def raw_bitmap(mi: Any, values: np.ndarray, filter_type: str, wrap_mode: str) -> dict[str, Any]:
    """A ``bitmap`` texture of ``(h, w, c)`` *values* as they are (``raw``: no colour
    conversion), row 0 at v = 0 as Mitsuba looks up spectrinsic's texture coordinates."""
    return {
        "type": "bitmap",
        # a Bitmap, not a TensorXf: nanobind tries a (3, …) tensor as a colour first and
        # prints each failed conversion on stderr (same texel values, measured)
        "bitmap": mi.Bitmap(np.ascontiguousarray(values, np.float32)),
        "raw": True,
        "filter_type": filter_type,
        "wrap_mode": wrap_mode,
    }


def hdr_film(
    width: int, height: int, crop: tuple[int, int, int, int] | None = None
) -> dict[str, Any]:
    """3-channel float32 film with a box filter (no blur across pixels: ground truth aligns).

    *crop* ``(x, y, width, height)`` in pixels renders only that window of the image (Mitsuba's
    ``crop_offset_x/_y``, ``crop_width/_height``): its pixels are the full image's, at the cost
    of the window's pixels alone (converged references of a detail)."""
    film: dict[str, Any] = {
        "type": "hdrfilm",
        "width": int(width),
        "height": int(height),
        "pixel_format": "rgb",
        "component_format": "float32",
        "rfilter": {"type": "box"},
    }
    if crop is not None:
        x, y, cw, ch = (int(v) for v in crop)
        if x < 0 or y < 0 or cw < 1 or ch < 1 or x + cw > width or y + ch > height:
            raise SceneError(
                f"film crop {tuple(crop)}: expected (x, y, width, height) inside {width}x{height}"
            )
        film.update(crop_offset_x=x, crop_offset_y=y, crop_width=cw, crop_height=ch)
    return film


def spectral_film(
    width: int, height: int, curves: np.ndarray, wavelengths: np.ndarray
) -> dict[str, Any]:
    """``specfilm`` whose bands are *curves* ``(K, W)``: channel k is ``∫ L S_k dλ`` (nm).

    Bands are named ``s00``, ``s01``, ... so their order survives any sorting by name.
    """
    film: dict[str, Any] = {
        "type": "specfilm",
        "width": int(width),
        "height": int(height),
        "component_format": "float32",
        "rfilter": {"type": "box"},
    }
    for k, curve in enumerate(np.asarray(curves, float)):
        film[f"s{k:02d}"] = regular_spectrum(np.clip(curve, 0.0, None), wavelengths)
    return film


def path_integrator(max_depth: int) -> dict[str, Any]:
    """Path tracer with Russian roulette off (``rr_depth`` > ``max_depth``): passes that share a
    seed and sample count then trace identical paths (common random numbers)."""
    if not 1 <= max_depth <= MAX_PATH_DEPTH:
        raise SceneError(
            f"max_depth {max_depth}: expected 1 to {MAX_PATH_DEPTH} (2 = direct light only)"
        )
    return {"type": "path", "max_depth": int(max_depth), "rr_depth": int(max_depth) + 1}


def aov_integrator() -> dict[str, Any]:
    """AOV integrator: ray distance, shading normal and the BSDF's diffuse reflectance."""
    return {"type": "aov", "aovs": "dd:depth,nn:sh_normal,alb:albedo"}
