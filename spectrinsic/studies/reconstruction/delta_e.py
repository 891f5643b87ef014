"""The two-pass method's colour error: CIEDE2000 against the exact spectral colour (section 5.2.3).

The exact colour is ``XYZ = ∫ f L x̄ / ∫ L ȳ`` (one bounce) or ``∫ f₂ f₁ L x̄ / ∫ L ȳ`` (two); the
two-pass colour regresses 6 diagonal channel values back to XYZ (:func:`delta_e_rows`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...spectra import (
    diagonal_values,
    fit_projection,
    gaussian_sensors,
    get_sensors,
    ordered_pairs,
    pair_responses,
    responses,
)
from .settings import ExtensionSettings

__all__ = ["DeltaERow", "delta_e_rows"]


@dataclass(frozen=True)
class DeltaERow:
    """CIEDE2000 of an approximate render against the exact spectral colour.

    ``method``: ``"two-pass"`` (diagonal 6-sensor values regressed to colour),
    ``"projection-only"`` (exact 6-sensor responses regressed: the regression's own share) or
    ``"cie1931-diagonal"`` (a 3-channel diagonal render with the CIE 1931 observer as sensors).
    """

    method: str
    bounces: int
    illuminant: str
    reflectances: str
    n_sensors: int
    mean_de2000: float
    sd_de2000: float
    p95_de2000: float
    max_de2000: float
    count: int


def _cie_lab(xyz: np.ndarray) -> np.ndarray:
    """CIE L*a*b* of XYZ (white Y = 1) relative to the D65 white of the CIE 1931 observer."""
    import colour

    white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    return np.asarray(colour.XYZ_to_Lab(xyz, white), float)


def _delta_e(lab_a: np.ndarray, lab_b: np.ndarray) -> np.ndarray:
    import colour

    return np.asarray(colour.delta_E(lab_a, lab_b, method="CIE 2000"), float)


def _de_row(
    method: str, bounces: int, illuminant: str, family: str, n: int, de: np.ndarray
) -> DeltaERow:
    return DeltaERow(
        method,
        bounces,
        illuminant,
        family,
        n,
        float(de.mean()),
        float(de.std()),
        float(np.percentile(de, 95)),
        float(de.max()),
        int(de.size),
    )


@dataclass(frozen=True)
class _Fit:
    """The exact one-bounce colours and the two-pass regression for one light, on one grid.

    ``f``: the kept reflectances ``(N, W)``; ``cmf``/``s6``: the CIE 1931 observer and the
    projection sensors ``(3|n, W)``; ``norm``: ``∫ L ȳ``; ``xyz_1``/``p6``: exact XYZ and
    6-sensor responses; ``proj``: ``P`` (3×n); ``s6_f``/``s6_l`` and ``cm_f``/``cm_l``: the
    diagonal values of surfaces and light in the projection sensors and in the observer.
    """

    f: np.ndarray
    cmf: np.ndarray
    s6: np.ndarray
    norm: float
    xyz_1: np.ndarray
    p6: np.ndarray
    proj: np.ndarray
    s6_f: np.ndarray
    s6_l: np.ndarray
    cm_f: np.ndarray
    cm_l: np.ndarray


def _fit(
    reflectances: np.ndarray, illuminant: np.ndarray, wl: np.ndarray, settings: ExtensionSettings
) -> _Fit:
    base = settings.base
    f_all = np.asarray(reflectances, float)
    f = f_all[f_all.mean(axis=1) >= base.chip_threshold]
    cmf = get_sensors("cie1931").on(wl)
    width = (base.sensor_end - base.sensor_start) / settings.projection_sensors
    s6 = gaussian_sensors(
        settings.projection_sensors,
        base.sensor_start,
        base.sensor_end,
        sigma=width * base.sigma_fraction,
        wavelengths=wl,
    ).curves
    norm = float(responses(illuminant, cmf[1:2], wl)[0])
    xyz_1 = responses(f * illuminant, cmf, wl) / norm
    p6 = responses(f * illuminant, s6, wl) / norm
    return _Fit(
        f,
        cmf,
        s6,
        norm,
        xyz_1,
        p6,
        fit_projection(p6, xyz_1),
        diagonal_values(f, s6, wl),
        responses(illuminant, s6, wl) / norm,
        diagonal_values(f, cmf, wl),
        responses(illuminant, cmf, wl) / norm,
    )


def _project(values: np.ndarray, proj: np.ndarray) -> np.ndarray:
    """``values @ proj.T``, ``(N, n) x (3, n) -> (N, 3)``, summed term by term in a fixed order.

    These numbers are written to files. A BLAS product's last bits depend on its kernel, threads
    and the operands' memory alignment, and so do einsum's vectorised sums here: both gave
    0.7312853703161359 or ...136 for one ΔE2000 mean across runs of the same code.
    """
    out = values[:, 0, None] * proj[None, :, 0]
    for k in range(1, proj.shape[1]):
        out = out + values[:, k, None] * proj[None, :, k]
    return out


def _one_bounce(fit: _Fit) -> dict[str, np.ndarray]:
    """ΔE2000 per surface of each method for one bounce."""
    lab_1 = _cie_lab(fit.xyz_1)
    return {
        "two-pass": _delta_e(lab_1, _cie_lab(_project(fit.s6_f * fit.s6_l, fit.proj))),
        "projection-only": _delta_e(lab_1, _cie_lab(_project(fit.p6, fit.proj))),
        "cie1931-diagonal": _delta_e(lab_1, _cie_lab(fit.cm_f * fit.cm_l)),
    }


def _two_bounce(
    fit: _Fit, illuminant: np.ndarray, wl: np.ndarray, settings: ExtensionSettings
) -> dict[str, np.ndarray]:
    """ΔE2000 per ordered pair of each method for two bounces, chunk by chunk."""
    base = settings.base
    found: dict[str, list[np.ndarray]] = {
        "two-pass": [],
        "projection-only": [],
        "cie1931-diagonal": [],
    }
    for i, j, exact, _ in pair_responses(
        fit.f,
        illuminant,
        np.concatenate([fit.cmf, fit.s6]),
        wl,
        pair_threshold=base.pair_threshold,
        include_self_pairs=base.include_self_pairs,
        chunk_size=base.chunk_size,
    ):
        exact = exact / fit.norm
        lab_exact = _cie_lab(exact[:, :3])
        for method, approx in (
            ("projection-only", _project(exact[:, 3:], fit.proj)),
            ("two-pass", _project(fit.s6_f[i] * fit.s6_f[j] * fit.s6_l, fit.proj)),
            ("cie1931-diagonal", fit.cm_f[i] * fit.cm_f[j] * fit.cm_l),
        ):
            found[method].append(ordered_pairs(_delta_e(lab_exact, _cie_lab(approx)), i, j))
    return {method: np.concatenate(parts) for method, parts in found.items()}


def delta_e_rows(
    reflectances: np.ndarray,
    illuminant: np.ndarray,
    wavelengths: np.ndarray,
    *,
    illuminant_name: str,
    family: str,
    settings: ExtensionSettings,
) -> list[DeltaERow]:
    """CIEDE2000 of the two-pass method (and two references) for one and two bounces.

    The exact colour is ``XYZ = ∫ f L x̄ / ∫ L ȳ`` (one bounce) or ``∫ f₂ f₁ L x̄ / ∫ L ȳ`` (two),
    the CIE 1931 observer on *wavelengths* (nm); Lab is taken relative to the D65 white. The
    two-pass colour is ``P · (f ∘ L)`` (resp. ``P · (f₂ ∘ f₁ ∘ L)``) with 6 diagonal channel
    values and ``P`` (3×6) the least-squares regression of exact one-bounce colours on exact
    6-sensor responses over the reflectances (section 5.2.3;
    :func:`spectrinsic.spectra.fit_projection`). Dark surfaces and pairs are discarded by the
    same rules as ε. Regressing onto XYZ or onto linear sRGB gives the same colours: least
    squares is equivariant under a linear map of the targets.
    """
    fit = _fit(reflectances, illuminant, wavelengths, settings)
    n6 = settings.projection_sensors
    rows = []
    for bounces, errors in (
        (1, _one_bounce(fit)),
        (2, _two_bounce(fit, illuminant, wavelengths, settings)),
    ):
        for method, de in errors.items():
            n_s = 3 if method == "cie1931-diagonal" else n6
            rows.append(_de_row(method, bounces, illuminant_name, family, n_s, de))
    return rows
