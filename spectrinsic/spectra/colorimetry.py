"""Integration of spectra against sensors, and colour-space conversions.

Conventions: a *response* is ``p_k = ∫ x(λ) S_k(λ) dλ`` in nm units (the rectangle rule on the
grid, as colour-science's ``"Integration"`` method), where ``x`` is a spectral radiance or a
product ``f(λ) L(λ)`` (thesis Eq. 4.9). Linear sRGB is never gamma-encoded here.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..arrays import Responses, SensorCurves, SpectralValues, Wavelengths
from ..errors import SpectralDataError
from .colourspace import srgb_matrices
from .grid import COLORIMETRIC_WAVELENGTHS, integration_weights
from .records import Spectrum
from .registry import get_sensors, get_spectrum

__all__ = [
    "XYZ_TO_LINEAR_SRGB",
    "LINEAR_SRGB_TO_XYZ",
    "responses",
    "diagonal_values",
    "xyz_to_linear_srgb",
    "linear_srgb_to_xyz",
    "luminance",
    "xyz_to_xy",
    "xy_to_duv",
    "white_normalised_responses",
    "absolute_reflectance",
    "srgb_responses",
    "encode_srgb",
    "decode_srgb",
]


#: IEC 61966-2-1 sRGB matrices (D65 white), from colour-science: declared here, computed on
#: first access by :func:`__getattr__` (they are not bound at import).
XYZ_TO_LINEAR_SRGB: np.ndarray
LINEAR_SRGB_TO_XYZ: np.ndarray
_LAZY_MATRICES = {"XYZ_TO_LINEAR_SRGB": 0, "LINEAR_SRGB_TO_XYZ": 1}


def __getattr__(name: str) -> np.ndarray:
    """``XYZ_TO_LINEAR_SRGB`` and ``LINEAR_SRGB_TO_XYZ``: the IEC 61966-2-1 sRGB matrices (D65
    white) from colour-science, ``(3, 3)`` float64, read-only, computed on first access rather
    than at import (:func:`spectrinsic.spectra.colourspace.srgb_matrices`)."""
    if name in _LAZY_MATRICES:
        return srgb_matrices()[_LAZY_MATRICES[name]]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _check(values: np.ndarray, curves: np.ndarray, wavelengths: np.ndarray) -> None:
    if values.shape[-1] != wavelengths.size or curves.shape[-1] != wavelengths.size:
        raise SpectralDataError(
            f"spectra {values.shape} and sensors {curves.shape} must both end in the "
            f"{wavelengths.size} samples of the wavelength grid"
        )


def responses(spectra: SpectralValues, curves: SensorCurves, wavelengths: Wavelengths) -> Responses:
    """Sensor responses ``p_k = Σ_λ x(λ) S_k(λ) Δλ`` (thesis Eq. 4.9 / 5.5).

    Parameters
    ----------
    spectra
        ``(..., W)`` spectral values on *wavelengths*.
    curves
        ``(K, W)`` sensor sensitivities on *wavelengths*.
    wavelengths
        ``(W,)`` nm.

    Returns
    -------
    ``(..., K)`` float64.

    >>> wl = np.array([500.0, 505.0]); responses(np.ones(2), np.ones((1, 2)), wl).tolist()
    [10.0]
    """
    x = np.asarray(spectra, float)
    s = np.asarray(curves, float)
    wl = np.asarray(wavelengths, float)
    _check(x, s, wl)
    # einsum's own loop rather than BLAS: its summation order does not depend on the thread
    # count or the CPU kernel, so fitted matrices and written files are reproducible anywhere.
    # The weights go on the K curves, not on the many spectra (the same bits on the 1 nm grid,
    # whose weights are 1).
    return np.einsum("...w,kw->...k", x, s * integration_weights(wl))


def diagonal_values(
    spectra: SpectralValues, curves: SensorCurves, wavelengths: Wavelengths
) -> Responses:
    """Channel values of a K-channel diagonal render: ``∫ f S_k dλ / ∫ S_k dλ`` (Eq. 5.4, normalised).

    With material values from this function and light values ``∫ L S_k dλ`` (:func:`responses`),
    their product approximates ``∫ f L S_k dλ`` (Eq. 5.2) whatever the scale of each sensor.
    """
    s = np.asarray(curves, float)
    area = responses(np.ones(s.shape[-1]), s, wavelengths)
    if np.any(area == 0):
        raise SpectralDataError("a sensor has zero area on the wavelength grid")
    return responses(spectra, s, wavelengths) / area


def xyz_to_linear_srgb(xyz: np.ndarray) -> np.ndarray:
    """CIE XYZ (..., 3) to linear sRGB (..., 3) with the IEC 61966-2-1 matrix; no gamma.

    einsum's own loop, not BLAS's matrix product: the bits must not change with the CPU kernel.
    """
    return np.einsum("...j,kj->...k", np.asarray(xyz, float), srgb_matrices()[0])


def linear_srgb_to_xyz(rgb: np.ndarray) -> np.ndarray:
    """Linear sRGB (..., 3) to CIE XYZ (..., 3) (einsum, as :func:`xyz_to_linear_srgb`)."""
    return np.einsum("...j,kj->...k", np.asarray(rgb, float), srgb_matrices()[1])


def luminance(rgb: np.ndarray) -> np.ndarray:
    """CIE Y of linear sRGB ``(..., 3)`` -> ``(...)``: the one definition of luminance, the
    second row of the sRGB-to-XYZ matrix (:data:`LINEAR_SRGB_TO_XYZ`)."""
    return np.asarray(rgb, float) @ srgb_matrices()[1][1]


def xyz_to_xy(xyz: np.ndarray) -> np.ndarray:
    """CIE 1931 xy chromaticity of XYZ (..., 3); black maps to (0, 0)."""
    xyz = np.asarray(xyz, float)
    s = xyz.sum(axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        xy = np.where(s > 0, xyz[..., :2] / np.where(s == 0, 1, s), 0.0)
    return xy


def xy_to_duv(xy: np.ndarray) -> np.ndarray:
    """Signed distance Duv of CIE 1931 chromaticities (..., 2) from the Planckian locus in the
    CIE 1960 UCS (u, v) diagram, by Ohno (2013) (colour-science ``uv_to_CCT_Ohno2013``),
    shape (...). Positive above the locus (greenish), negative below (pinkish/purple); lights
    with |Duv| >= 0.02 are visibly tinted rather than whites of another temperature.
    """
    import colour

    uv = colour.xy_to_UCS_uv(np.asarray(xy, float))
    # beyond the method's 1000-100000 K table (very saturated lights) colour warns and measures
    # from the table's end: still a large |Duv|, which is all a saturation test needs
    with colour.utilities.suppress_warnings(colour_runtime_warnings=True):
        return np.asarray(colour.temperature.uv_to_CCT_Ohno2013(uv), float)[..., 1]


def white_normalised_responses(
    reflectances: SpectralValues,
    illuminant: SpectralValues,
    curves: SensorCurves,
    wavelengths: Wavelengths,
) -> Responses:
    """Responses of reflectances under a light, scaled so the perfect white has luminance Y = 1.

    ``p_k = Σ ρ E S_k Δλ / Σ E ȳ Δλ`` (thesis Eq. 4.9 with the light's own white as unit).

    Parameters
    ----------
    reflectances
        ``(..., W)`` fractions in [0, 1] on *wavelengths* (nm).
    illuminant
        ``(W,)`` relative spectral power.
    curves
        ``(K, W)`` sensor sensitivities.

    Returns
    -------
    ``(..., K)`` float64, dimensionless.
    """
    light = np.asarray(illuminant, float)
    ybar = get_sensors("cie1931").on(wavelengths)[1:2]
    white_y = float(responses(light, ybar, wavelengths)[0])
    if not white_y > 0:
        raise SpectralDataError("illuminant has no luminance on the wavelength grid")
    return responses(np.asarray(reflectances, float) * light, curves, wavelengths) / white_y


def absolute_reflectance(
    reflectances: Spectrum | str | Sequence[Spectrum | str],
    *,
    data_dir: str | None = None,
) -> np.ndarray:
    """Absolute reflectance: linear sRGB of reflectances under D65 with sRGB sensors.

    The thesis' canonical conditions (section 4.2, ``p^{s,c}``): ``XYZ = Σ ρ E_D65 x̄ Δλ /
    Σ E_D65 ȳ Δλ`` on the 1 nm CIE grid (360–830 nm), then the sRGB matrix, so the perfect white
    is ``(1, 1, 1)``.

    Returns
    -------
    ``(3,)`` for one spectrum, ``(N, 3)`` for a sequence; float64, linear sRGB.
    """
    single = isinstance(reflectances, (Spectrum, str))
    items: list[Spectrum | str] = (
        [reflectances] if isinstance(reflectances, (Spectrum, str)) else list(reflectances)
    )
    spectra = [get_spectrum(s, data_dir=data_dir) if isinstance(s, str) else s for s in items]
    wl = COLORIMETRIC_WAVELENGTHS
    cmf = get_sensors("cie1931").on(wl)
    d65 = get_spectrum("cie:D65").on(wl)
    rho = np.stack([s.on(wl) for s in spectra]) if spectra else np.zeros((0, wl.size))
    rgb = xyz_to_linear_srgb(white_normalised_responses(rho, d65, cmf, wl))
    return rgb[0] if single else rgb


def srgb_responses(
    reflectances: SpectralValues, illuminant: SpectralValues, wavelengths: Wavelengths
) -> Responses:
    """Linear sRGB ``(N, 3)`` of reflectances ``(N, W)`` under a light ``(W,)``, white Y = 1.

    :func:`white_normalised_responses` with the sRGB sensors (the CIE 1931 observer followed
    by the sRGB matrix) on *wavelengths* (nm). Under D65 this is the absolute reflectance
    ``p^{s,c}`` (Eq. 4.15), normalised like :func:`absolute_reflectance` but integrated on
    *wavelengths*. Linear: no transfer function.
    """
    return white_normalised_responses(
        reflectances, illuminant, get_sensors("srgb").on(wavelengths), wavelengths
    )


def encode_srgb(linear: np.ndarray) -> np.ndarray:
    """IEC 61966-2-1 sRGB encoding (colour-science's ``cctf_encoding``) of linear values.

    Values are clipped to [0, 1] first and NaN maps to 0, so the result is a float array in
    [0, 1] of the input's shape. The one home of sRGB encoding in spectrinsic.

    >>> encode_srgb(np.array([0.0, 0.0031308, 1.0, 2.0])).round(6).tolist()
    [0.0, 0.04045, 1.0, 1.0]
    """
    import colour

    x = np.nan_to_num(np.asarray(linear, float), nan=0.0, posinf=1.0, neginf=0.0)
    return np.asarray(colour.cctf_encoding(np.clip(x, 0.0, 1.0), function="sRGB"), float)


def decode_srgb(encoded: np.ndarray) -> np.ndarray:
    """Inverse of :func:`encode_srgb`: sRGB-encoded values in [0, 1] -> linear (clipped first).

    >>> decode_srgb(encode_srgb(np.array([0.25]))).round(12).tolist()
    [0.25]
    """
    import colour

    return np.asarray(
        colour.cctf_decoding(np.clip(np.asarray(encoded, float), 0.0, 1.0), function="sRGB"), float
    )
