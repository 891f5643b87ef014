"""The image pipeline of a camera: mosaic, demosaic, white balance, colour matrix, tone curve.

Pure array functions. Mosaicking and demosaicking are colour-demosaicing's (bilinear,
Malvar 2004, Menon 2007); the camera → XYZ matrix is fitted with colour-science's
:func:`colour.characterisation.matrix_colour_correction` (Cheung 2004, three terms) on the 24
ColorChecker patches under D65, from the camera's curves, the thesis' ``S_Sen`` made explicit.
"""

from __future__ import annotations

import functools

import numpy as np

from .camera_model import CameraModel
from .colorimetry import white_normalised_responses
from .colourspace import srgb_matrices
from .registry import family_values, get_spectrum
from .sensors import cie1931

__all__ = [
    "cfa_masks",
    "mosaic",
    "demosaic",
    "white_balance_gains",
    "camera_to_xyz",
    "camera_to_srgb",
    "tone_curve",
    "quantise",
    "processing_matrix",
    "COLOUR_MATRIX_PATCHES",
]

#: The reflectances the colour matrix is fitted on (the 24 BabelColor ColorChecker patches).
COLOUR_MATRIX_PATCHES = "colorchecker"
#: Mirror padding around a CFA image before demosaicking, pixels (even: the phase is kept).
_PAD = 4


def cfa_masks(shape: tuple[int, int], pattern: str) -> np.ndarray:
    """``(H, W, 3) bool``: which colour each photosite of a Bayer *pattern* records."""
    from colour_demosaicing import masks_CFA_Bayer

    return np.stack(masks_CFA_Bayer(shape, pattern), axis=-1)


def mosaic(rgb: np.ndarray, pattern: str) -> np.ndarray:
    """``(H, W)`` CFA image: each photosite keeps the channel of *pattern* there."""
    from colour_demosaicing import mosaicing_CFA_Bayer

    return np.asarray(mosaicing_CFA_Bayer(np.asarray(rgb, np.float64), pattern), np.float64)


def demosaic(cfa: np.ndarray, pattern: str, method: str) -> np.ndarray:
    """``(H, W, 3)`` RGB from a CFA image with colour-demosaicing's *method*
    (``bilinear``, ``malvar2004`` or ``menon2007``)."""
    import colour_demosaicing as cd

    functions = {
        "bilinear": cd.demosaicing_CFA_Bayer_bilinear,
        "malvar2004": cd.demosaicing_CFA_Bayer_Malvar2004,
        "menon2007": cd.demosaicing_CFA_Bayer_Menon2007,
    }
    # padded by mirroring (an even width keeps the Bayer phase), so borders see the same
    # neighbourhood as the interior: a flat field comes back flat up to its edges
    padded = np.pad(np.asarray(cfa, np.float64), _PAD, mode="reflect")
    rgb = np.asarray(functions[method](padded, pattern), np.float64)
    return rgb[_PAD:-_PAD, _PAD:-_PAD]


def white_balance_gains(
    method: str, image: np.ndarray, illuminant_rgb: np.ndarray | None = None
) -> np.ndarray:
    """``(3,)`` per-channel gains, green kept at 1.

    ``none``: ones; ``grey-world``: the channel means of *image* made equal;
    ``illuminant``: the camera RGB of a perfect white under the known light
    (*illuminant_rgb*) made neutral.
    """
    if method == "none":
        return np.ones(3)
    if method == "grey-world":
        ref = np.asarray(image, np.float64).reshape(-1, 3).mean(axis=0)
    elif method == "illuminant":
        if illuminant_rgb is None:
            raise ValueError("white balance 'illuminant': expected the light's camera RGB")
        ref = np.asarray(illuminant_rgb, np.float64)
    else:
        raise ValueError(f"white balance {method!r}: expected none, grey-world or illuminant")
    if not np.all(ref > 0):
        return np.ones(3)
    return ref[1] / ref


@functools.lru_cache(maxsize=16)
def _fit(curves_key: tuple[float, ...], wl_key: tuple[float, ...]) -> np.ndarray:
    from colour.characterisation import matrix_colour_correction

    wl = np.asarray(wl_key)
    curves = np.asarray(curves_key).reshape(3, -1)
    rho = family_values(COLOUR_MATRIX_PATCHES, wl)
    d65 = get_spectrum("cie:D65").on(wl)
    cam = white_normalised_responses(rho, d65, curves, wl)
    white = white_normalised_responses(np.ones(wl.size), d65, curves, wl)
    xyz = white_normalised_responses(rho, d65, cie1931().on(wl), wl)
    matrix = np.asarray(matrix_colour_correction(cam / white, xyz, method="Cheung 2004", terms=3))
    # rows rescaled so that neutral camera RGB maps exactly onto the white's XYZ: a balanced
    # white stays white (the least-squares fit alone misses it by about a degree of hue)
    xyz_white = white_normalised_responses(np.ones(wl.size), d65, cie1931().on(wl), wl)
    matrix = matrix * (xyz_white / matrix.sum(axis=1))[:, None]
    matrix.setflags(write=False)
    return matrix


def camera_to_xyz(curves: np.ndarray, wavelengths: np.ndarray) -> np.ndarray:
    """``(3, 3)`` matrix from white-balanced camera RGB (the D65 white made ``(1, 1, 1)``) to
    XYZ under D65 (white Y = 1), least squares over the ColorChecker with the white kept
    (``M @ (1, 1, 1)`` is the white's XYZ): ``xyz = M @ rgb``."""
    curves = np.asarray(curves, np.float64)
    return _fit(tuple(curves.ravel().tolist()), tuple(np.asarray(wavelengths, float).tolist()))


def camera_to_srgb(curves: np.ndarray, wavelengths: np.ndarray) -> np.ndarray:
    """``(3, 3)``: :func:`camera_to_xyz` followed by XYZ → linear sRGB (IEC 61966-2-1)."""
    return srgb_matrices()[0] @ camera_to_xyz(curves, wavelengths)


def tone_curve(linear: np.ndarray, curve: str) -> np.ndarray:
    """Encode linear values in ``[0, 1]`` (clipped first): ``srgb`` (IEC 61966-2-1),
    ``gamma2.2`` or ``linear``."""
    x = np.clip(np.asarray(linear, np.float64), 0.0, 1.0)
    if curve == "srgb":
        return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    if curve == "gamma2.2":
        return x ** (1 / 2.2)
    if curve == "linear":
        return x
    raise ValueError(f"tone curve {curve!r}: expected srgb, gamma2.2 or linear")


def quantise(encoded: np.ndarray, bits: int) -> np.ndarray:
    """Integer codes of values in ``[0, 1]`` at *bits* (8 → uint8, 16 → uint16)."""
    top = 2**bits - 1
    codes = np.rint(np.clip(encoded, 0.0, 1.0) * top)
    return codes.astype(np.uint8 if bits == 8 else np.uint16)


def processing_matrix(model: CameraModel, curves: np.ndarray, wl: np.ndarray) -> np.ndarray:
    """The colour matrix the chain applies after white balance: :func:`camera_to_srgb`, or the
    identity when ``model.colour_matrix`` is off."""
    if not model.colour_matrix:
        return np.eye(3)
    return camera_to_srgb(curves, wl)
