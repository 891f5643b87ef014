"""spectrinsic.spectra: measured spectra, sensor sets and the colour maths of thesis chapters 4–5.

Pure functions on arrays and small frozen records; numpy and colour-science only. Only
:mod:`spectrinsic.spectra.io` reads files.
"""

import numpy as _np

from . import colorimetry as _colorimetry
from .colorimetry import (
    absolute_reflectance,
    diagonal_values,
    linear_srgb_to_xyz,
    responses,
    srgb_responses,
    white_normalised_responses,
    xy_to_duv,
    xyz_to_linear_srgb,
    xyz_to_xy,
)
from .grid import (
    COLORIMETRIC_WAVELENGTHS,
    DEFAULT_WAVELENGTHS,
    resample,
    validate_wavelengths,
    wavelength_grid,
)
from .illuminants import ILLUMINANT_SETS, illuminant_set, planck_law
from .photometric import (
    ESTIMATE_SCENARIOS,
    angular_error,
    fit_matrix,
    fit_projection,
    scenario_estimates,
    sharpening_transform,
)
from .reconstruction import (
    one_bounce_errors,
    ordered_pairs,
    pair_responses,
    relative_error,
    two_bounce_errors,
)
from .records import SensorSet, Spectrum
from .registry import family_values, get_sensors, get_spectrum, list_spectra
from .sensors import box_bands, gaussian_sensors

__all__ = [
    "COLORIMETRIC_WAVELENGTHS",
    "DEFAULT_WAVELENGTHS",
    "ESTIMATE_SCENARIOS",
    "ILLUMINANT_SETS",
    "LINEAR_SRGB_TO_XYZ",
    "XYZ_TO_LINEAR_SRGB",
    "SensorSet",
    "Spectrum",
    "absolute_reflectance",
    "angular_error",
    "box_bands",
    "diagonal_values",
    "family_values",
    "fit_matrix",
    "fit_projection",
    "gaussian_sensors",
    "get_sensors",
    "get_spectrum",
    "illuminant_set",
    "linear_srgb_to_xyz",
    "list_spectra",
    "one_bounce_errors",
    "ordered_pairs",
    "pair_responses",
    "planck_law",
    "relative_error",
    "resample",
    "responses",
    "scenario_estimates",
    "sharpening_transform",
    "srgb_responses",
    "two_bounce_errors",
    "validate_wavelengths",
    "wavelength_grid",
    "white_normalised_responses",
    "xyz_to_linear_srgb",
    "xy_to_duv",
    "xyz_to_xy",
]


#: The sRGB matrices of :mod:`~spectrinsic.spectra.colorimetry`, computed on first access.
XYZ_TO_LINEAR_SRGB: _np.ndarray
LINEAR_SRGB_TO_XYZ: _np.ndarray


def __getattr__(name: str) -> _np.ndarray:
    """``XYZ_TO_LINEAR_SRGB``, ``LINEAR_SRGB_TO_XYZ``: the sRGB matrices, computed on first access
    (see :mod:`spectrinsic.spectra.colorimetry`), so importing the package computes nothing."""
    if name in ("XYZ_TO_LINEAR_SRGB", "LINEAR_SRGB_TO_XYZ"):
        return getattr(_colorimetry, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
