"""Spectral helpers: camera curves, cube-to-sensor weights and the chapter-4 photometric matrices
(thesis sections 4.2-4.4).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...spectra import family_values, fit_matrix, get_sensors, get_spectrum

# Responses with the light's white at Y = 1; under D65 with sRGB sensors, the canonical p^{s,c}.
from ...spectra import white_normalised_responses as canonical_responses
from ...spectra.grid import integration_weights
from .records import TRAINING_FAMILY

__all__ = ["camera_curves", "cube_to_sensors", "photometric_matrices"]


def camera_curves(name: str, wavelengths: np.ndarray, *, data_dir: Any = None) -> np.ndarray:
    """``(3, W)`` sensitivities of camera *name* on *wavelengths*, scaled so that the perfect
    white under D65 has mean channel 1 in :func:`canonical_responses` (one factor for all
    channels: the camera's own white balance is kept)."""
    curves = get_sensors(name, data_dir=data_dir).on(wavelengths)
    d65 = get_spectrum("cie:D65").on(wavelengths)
    white = canonical_responses(np.ones(wavelengths.size), d65, curves, wavelengths)
    if not white.mean() > 0:
        raise DatasetError(f"camera {name!r} has no response to D65 on 360-830 nm")
    return curves / white.mean()


def cube_to_sensors(
    cube_sensors: np.ndarray, curves: np.ndarray, wavelengths: np.ndarray
) -> np.ndarray:
    """``(K, B)`` weights ``A`` with ``S ≈ A @ bands`` (least squares on *wavelengths*).

    A band cube with values ``∫ L B_b dλ`` then gives ``∫ L S_k dλ ≈ Σ_b A_kb cube_b``; for
    disjoint box bands ``A_kb`` is the mean of ``S_k`` over band ``b``. Light outside the
    bands' support is not seen.
    """
    w = integration_weights(wavelengths)
    gram = (cube_sensors * w) @ cube_sensors.T
    cross = (curves * w) @ cube_sensors.T
    return np.linalg.solve(gram.T, cross.T).T


def _training_reflectances(wavelengths: np.ndarray) -> np.ndarray:
    return family_values(TRAINING_FAMILY, wavelengths)


def photometric_matrices(
    illuminants: Mapping[str, np.ndarray],
    sensor_spaces: Mapping[str, np.ndarray],
    wavelengths: np.ndarray,
    *,
    training: np.ndarray | None = None,
) -> dict[str, Any]:
    """Fit ``S_Sen`` per camera and ``L_CLig`` per illuminant and sensor space (thesis 4.2–4.4).

    Following section 4.4.1, over the training reflectances (1269 Munsell chips):
    ``p^{s,c}`` are canonical responses under D65 with sRGB sensors, ``p^c`` under D65 with a
    camera, ``p`` under the scene illuminant with that camera; ``S_Sen`` is the least-squares
    3×3 with ``p^c ≈ S_Sen p^{s,c}`` and ``L_CLig`` the one with ``p ≈ L_CLig p^c``
    (Eq. 4.11, 4.13; matrices act on column vectors).

    Parameters
    ----------
    illuminants
        ``{label: (W,) SPD}``, e.g. ``{"scene": ..., "light 0": ...}``.
    sensor_spaces
        ``{name: (3, W) curves}``; must contain ``"srgb"``.

    Returns
    -------
    dict
        ``{"S_Sen": {camera: 3×3 list}, "L_CLig": {space: {label: 3×3 list}},
        "L_CLig_diagonal": {...}}`` (the diagonal fits are the von Kries models of SC2/SC3).
    """
    rho = _training_reflectances(wavelengths) if training is None else training
    d65 = get_spectrum("cie:D65").on(wavelengths)
    canon = {k: canonical_responses(rho, d65, s, wavelengths) for k, s in sensor_spaces.items()}
    out: dict[str, Any] = {"S_Sen": {}, "L_CLig": {}, "L_CLig_diagonal": {}}
    for space, curves in sensor_spaces.items():
        if space != "srgb":
            out["S_Sen"][space] = fit_matrix(canon["srgb"], canon[space]).tolist()
        full, diag = {}, {}
        for label, spd in illuminants.items():
            p = canonical_responses(rho, spd, curves, wavelengths)
            full[label] = fit_matrix(canon[space], p).tolist()
            diag[label] = np.diag(fit_matrix(canon[space], p, diagonal=True)).tolist()
        out["L_CLig"][space] = full
        out["L_CLig_diagonal"][space] = diag
    return out
