"""Ground-truth layers computed from a render result and the scene's spectra (pure functions).

Nothing here reads or writes files or touches a renderer: inputs are a :class:`Scene` (which
names every spectrum) and a :class:`spectrinsic.render.result.RenderResult` (read by its
typed fields: a renamed field fails in mypy, not by a silently missing layer). :func:`compute_ground_truth` composes one function per family of
layers: images and errors, geometry, reflectance, irradiance shading (with noise and
denoising), lights, cameras and the chapter-4 matrices.

Colour conventions (thesis chapter 4, Eq. 4.9–4.16). For sensor curves ``S`` (sRGB = the
IEC 61966-2-1 matrix applied to the CIE 1931 CMFs, or a camera), the *canonical response* of a
reflectance ``ρ`` under an illuminant ``E`` is

    p(ρ; E, S) = ∫ ρ E S dλ / ∫ E ȳ dλ,

so the perfect white has luminance 1 under any light, and under D65 with sRGB sensors
``p = p^{s,c}`` is the absolute reflectance of :func:`spectrinsic.spectra.absolute_reflectance`
(white = (1, 1, 1) up to the 1 nm integration of D65). Camera curves are first scaled by one
factor so that the mean channel of the perfect white under D65 is 1 (white balance is left to
the camera, as the thesis' relative reflectance ``S_Sen · I^a`` keeps it). Every integral uses
the 1 nm CIE grid (360–830 nm). Shading, residual and illuminant come from the spectral
irradiance (:mod:`spectrinsic.gt_export.layers.irradiance`). The RGB layers (``image*``,
``reflectance``, ``shading*``, ``illuminant``, ``specular``, ``residual*``) are in the working
space (:mod:`spectrinsic.spectra.working_space`: ACEScg by default, its matrix applied to the
same XYZ; linear sRGB with ``working_space="srgb"``); the chapter-4 matrices stay sRGB.
"""

from .compose import compute_ground_truth, identities
from .imaging import coverage_weighted, light_shares, relative_error_map, shading_ratio
from .records import (
    DEFAULT_CUBE_SENSORS,
    REFERENCE_MODES,
    REFLECTANCE_FLOOR,
    GroundTruth,
    Layer,
    LightRecord,
    reference_mode,
)
from .settings import DEFAULT_CAMERAS, LayerSettings
from .spectral import camera_curves, canonical_responses, cube_to_sensors, photometric_matrices

__all__ = [
    "DEFAULT_CAMERAS",
    "LayerSettings",
    "Layer",
    "LightRecord",
    "GroundTruth",
    "REFERENCE_MODES",
    "DEFAULT_CUBE_SENSORS",
    "REFLECTANCE_FLOOR",
    "compute_ground_truth",
    "reference_mode",
    "canonical_responses",
    "camera_curves",
    "cube_to_sensors",
    "coverage_weighted",
    "shading_ratio",
    "relative_error_map",
    "light_shares",
    "photometric_matrices",
    "identities",
]
