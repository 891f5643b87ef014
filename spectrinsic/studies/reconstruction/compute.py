"""Numbers of the reconstruction-error study: Table 5.2, its extension and the two-pass ΔE2000.

Settings that reproduce Table 5.2 (13 of 18 numbers exactly, the rest within 0.07 points; see
:data:`THESIS_TABLE_5_2` and ``tests/studies``), all fields of :class:`ReconstructionSettings`:

* 400–700 nm sampled at 5 nm, the rectangle rule;
* n Gaussian sensors centred in n equal bins of 400–700 nm, σ = bin width / 4, each normalised to
  unit discrete area (:func:`spectrinsic.spectra.gaussian_sensors`);
* two bounces measured on the interreflection term alone, ``∫ f₂ f₁ L S`` against
  ``f₂ ∘ f₁ ∘ L``, over ordered pairs of distinct chips, discarding pairs whose mean ``f₁ f₂``
  over the grid is below 0.0325;
* one bounce: the analogous rule keeps chips whose mean reflectance over the grid is at least
  0.0325. No Munsell chip is that dark (the darkest averages 0.043), so for the table the rule
  discards nothing; it matters for the SFU set, whose darkest surfaces are far darker.
  Any threshold up to 0.043 reproduces the table; a rule on mean ``f²`` (a chip paired with
  itself) with the same threshold would drop 422 chips and give 0.56 / 0.40 / 2.35 % for three
  sensors, away from the thesis' 0.58 / 0.44 / 2.88 %.

Standard deviations are population deviations (``ddof=0``). With unit-area sensors,
:func:`spectrinsic.spectra.diagonal_values` equals ``∫ f S_k dλ``, so the general normalised form
used here is Eq. 5.2 itself. The errors themselves (Eq. 5.7) come from
:mod:`spectrinsic.spectra.reconstruction`.

Nothing here writes files or text: :mod:`.report` and :mod:`.plot` do.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace

import numpy as np

from ...arrays import StepProgress
from ...data_dir import resolve_data_dir
from ...errors import SpectralDataError
from ...spectra import (
    family_values,
    get_spectrum,
    one_bounce_errors,
    two_bounce_errors,
    wavelength_grid,
)
from .delta_e import DeltaERow, delta_e_rows
from .settings import ExtensionSettings, ReconstructionSettings

__all__ = [
    "THESIS_TABLE_5_2",
    "ErrorRow",
    "TableResult",
    "ExtensionResult",
    "reflectance_matrix",
    "reconstruction_table",
    "run_extension",
]

logger = logging.getLogger(__name__)

#: Thesis Table 5.2 (section 5.2.3): ``(n_sensors, bounces) -> (mean, s.d., max)`` in percent.
THESIS_TABLE_5_2: dict[tuple[int, int], tuple[float, float, float]] = {
    (3, 1): (0.58, 0.44, 2.88),
    (6, 1): (0.19, 0.14, 1.25),
    (9, 1): (0.12, 0.08, 0.86),
    (3, 2): (1.38, 1.62, 23.84),
    (6, 2): (0.55, 0.55, 9.06),
    (9, 2): (0.34, 0.29, 3.77),
}


@dataclass(frozen=True)
class ErrorRow:
    """Statistics of ε (Eq. 5.7) in percent for one configuration."""

    n_sensors: int
    bounces: int
    mean_pct: float
    sd_pct: float
    max_pct: float
    count: int
    illuminant: str = "cie:D65"
    reflectances: str = "munsell"


@dataclass(frozen=True)
class TableResult:
    """Rows of the table and the per-configuration errors (for plots), keyed ``(n, bounces)``."""

    settings: ReconstructionSettings
    rows: tuple[ErrorRow, ...]
    errors: dict[tuple[int, int], np.ndarray]


@dataclass(frozen=True)
class ExtensionResult:
    """Rows of the extension: ε per configuration, the ΔE2000 rows and the skipped sets."""

    settings: ExtensionSettings
    rows: tuple[ErrorRow, ...]
    delta_e: tuple[DeltaERow, ...]
    skipped: tuple[str, ...]


def reflectance_matrix(
    family: str, wavelengths: np.ndarray, *, data_dir: str | None = None
) -> np.ndarray:
    """``(N, W)`` reflectances of a listable family (``"munsell"``, ``"sfu"``...) on *wavelengths*."""
    return family_values(family, wavelengths, data_dir=data_dir)


def _stats(errors: np.ndarray) -> tuple[float, float, float]:
    if errors.size == 0:
        raise SpectralDataError("no reflectance passed the dark-surface threshold; lower it")
    return float(errors.mean()), float(errors.std()), float(errors.max())


def _errors_for(
    settings: ReconstructionSettings,
    reflectances: np.ndarray,
    illuminant: np.ndarray,
    n: int,
    bounces: int,
) -> np.ndarray:
    wl = settings.wavelengths
    curves = settings.sensors(n)
    if bounces == 1:
        return one_bounce_errors(
            reflectances, illuminant, curves, wl, chip_threshold=settings.chip_threshold
        )
    return two_bounce_errors(
        reflectances,
        illuminant,
        curves,
        wl,
        pair_threshold=settings.pair_threshold,
        include_self_pairs=settings.include_self_pairs,
        chunk_size=settings.chunk_size,
    )


def _error_rows(
    settings: ReconstructionSettings,
    *,
    data_dir: str | None,
    progress: StepProgress | None,
    keep_errors: bool = False,
) -> tuple[list[ErrorRow], dict[tuple[int, int], np.ndarray]]:
    wl = settings.wavelengths
    f = reflectance_matrix(settings.reflectances, wl, data_dir=data_dir)
    light = get_spectrum(settings.illuminant, data_dir=data_dir).on(wl)
    rows, kept = [], {}
    for b in settings.bounces:
        for n in settings.sensor_counts:
            if progress is not None:
                progress(
                    f"{settings.reflectances} / {settings.illuminant}: {n} sensors, {b} bounce(s)"
                )
            err = _errors_for(settings, f, light, n, b)
            mean, sd, mx = _stats(err)
            rows.append(
                ErrorRow(
                    n, b, mean, sd, mx, int(err.size), settings.illuminant, settings.reflectances
                )
            )
            if keep_errors:
                kept[(n, b)] = err.astype(np.float32)
    return rows, kept


def reconstruction_table(
    settings: ReconstructionSettings | None = None,
    *,
    data_dir: str | None = None,
    progress: StepProgress | None = None,
) -> TableResult:
    """Compute Table 5.2 (or its analogue for other *settings*).

    Returns
    -------
    TableResult
        One :class:`ErrorRow` per (bounces, n), one-bounce rows first, and the individual errors
        (percent, float32).
    """
    settings = settings or ReconstructionSettings()
    rows, errors = _error_rows(settings, data_dir=data_dir, progress=progress, keep_errors=True)
    return TableResult(settings, tuple(rows), errors)


def run_extension(
    settings: ExtensionSettings | None = None,
    *,
    data_dir: str | None = None,
    progress: StepProgress | None = None,
) -> ExtensionResult:
    """ε for n = 3..12 under several lights and reflectance sets, and the two-pass ΔE2000.

    Reflectance sets needing a data directory are skipped (and named in ``skipped``) when none is
    configured.
    """
    settings = settings or ExtensionSettings()
    rows: list[ErrorRow] = []
    de_rows: list[DeltaERow] = []
    skipped: list[str] = []
    wl_c = wavelength_grid(
        settings.colorimetric_start, settings.colorimetric_end, settings.colorimetric_step
    )
    for family in settings.reflectance_sets:
        if family == "sfu" and resolve_data_dir(data_dir) is None:
            skipped.append("sfu: no spectral data directory (--data-dir or SPECTRINSIC_DATA)")
            logger.info("skipping the SFU reflectances: no data directory configured")
            continue
        f_c = reflectance_matrix(family, wl_c, data_dir=data_dir)
        for light in settings.illuminants:
            run = replace(
                settings.base,
                sensor_counts=settings.sensor_counts,
                illuminant=light,
                reflectances=family,
            )
            found, _ = _error_rows(run, data_dir=data_dir, progress=progress)
            rows.extend(found)
            if progress is not None:
                progress(f"{family} / {light}: two-pass ΔE2000")
            de_rows.extend(
                delta_e_rows(
                    f_c,
                    get_spectrum(light).on(wl_c),
                    wl_c,
                    illuminant_name=light,
                    family=family,
                    settings=settings,
                )
            )
    return ExtensionResult(settings, tuple(rows), tuple(de_rows), tuple(skipped))
