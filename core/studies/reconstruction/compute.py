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
from dataclasses import dataclass, field, replace

import numpy as np

from spectrinsic.config import resolve_data_dir
from spectrinsic.errors import SpectralDataError
from spectrinsic.spectra import (
    diagonal_values,
    family_values,
    fit_projection,
    gaussian_sensors,
    get_sensors,
    get_spectrum,
    one_bounce_errors,
    ordered_pairs,
    pair_responses,
    responses,
    two_bounce_errors,
    wavelength_grid,
)
from spectrinsic.typing import StepProgress

__all__ = [
    "THESIS_TABLE_5_2",
    "ReconstructionSettings",
    "ExtensionSettings",
    "ErrorRow",
    "DeltaERow",
    "TableResult",
    "ExtensionResult",
    "reflectance_matrix",
    "delta_e_rows",
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
class ReconstructionSettings:
    """Every free choice of the reconstruction-error experiment; defaults reproduce Table 5.2.

    Attributes
    ----------
    sensor_counts
        Numbers n of Gaussian sensors to evaluate.
    bounces
        Bounce counts: 1 (Eq. 5.3) and/or 2 (the interreflection term of Eq. 5.6).
    illuminant
        Spectrum name of the light (thesis: D65).
    reflectances
        Reflectance family listed by :func:`spectrinsic.spectra.list_spectra` (``"munsell"``:
        the 1269 chips; ``"sfu"``: Barnard's 1995, needs a data directory).
    wavelength_start, wavelength_end, wavelength_step
        Integration grid in nm (rectangle rule).
    sensor_start, sensor_end
        Range in nm split into n equal bins, one Gaussian centred in each.
    sigma_fraction
        σ of each Gaussian as a fraction of the bin width.
    pair_threshold
        Two bounces: ordered pairs (f₁, f₂) of distinct reflectances with mean ``f₁ f₂`` over the
        grid below this are discarded as dark.
    chip_threshold
        One bounce: reflectances with mean ``f`` over the grid below this are discarded.
    include_self_pairs
        Two bounces: also count a surface reflecting onto itself (f₁ = f₂).
    chunk_size
        Rows of reflectances per chunk of the pair computation (memory ∝ chunk · N · n).
    """

    sensor_counts: tuple[int, ...] = (3, 6, 9)
    bounces: tuple[int, ...] = (1, 2)
    illuminant: str = "cie:D65"
    reflectances: str = "munsell"
    wavelength_start: float = 400.0
    wavelength_end: float = 700.0
    wavelength_step: float = 5.0
    sensor_start: float = 400.0
    sensor_end: float = 700.0
    sigma_fraction: float = 0.25
    pair_threshold: float = 0.0325
    chip_threshold: float = 0.0325
    include_self_pairs: bool = False
    chunk_size: int = 128

    def __post_init__(self) -> None:
        if not self.sensor_counts or min(self.sensor_counts) < 1:
            raise SpectralDataError(f"sensor_counts {self.sensor_counts!r}: expected numbers >= 1")
        if not set(self.bounces) <= {1, 2} or not self.bounces:
            raise SpectralDataError(f"bounces {self.bounces!r}: expected a selection of 1 and 2")
        if not self.sigma_fraction > 0:
            raise SpectralDataError(f"sigma_fraction {self.sigma_fraction!r}: expected > 0")
        if self.chunk_size < 1:
            raise SpectralDataError(f"chunk_size {self.chunk_size!r}: expected >= 1")

    @property
    def wavelengths(self) -> np.ndarray:
        """The integration grid, ``(W,)`` nm."""
        return wavelength_grid(self.wavelength_start, self.wavelength_end, self.wavelength_step)

    def sensors(self, n: int) -> np.ndarray:
        """``(n, W)`` unit-area Gaussian sensors on :attr:`wavelengths`."""
        width = (self.sensor_end - self.sensor_start) / n
        return gaussian_sensors(
            n, self.sensor_start, self.sensor_end, sigma=width * self.sigma_fraction,
            wavelengths=self.wavelengths,
        ).curves


@dataclass(frozen=True)
class ExtensionSettings:
    """The extended study: more sensors, lights and reflectances, and the two-pass colour error.

    Attributes
    ----------
    base
        Grid, sensor shape and dark-surface rules shared with the table.
    sensor_counts
        n swept for the relative error (3..12).
    illuminants
        Lights: D65, a 2800 K Planckian and the narrow-band fluorescent FL11.
    reflectance_sets
        Families; ``"sfu"`` is skipped with a note when no data directory is configured.
    projection_sensors
        Sensors of the two-pass method (thesis: 6), regressed back to colour.
    colorimetric_start, colorimetric_end, colorimetric_step
        Grid (nm) of the exact colour (CIE 1931 observer) and of the projected sensors.
    """

    base: ReconstructionSettings = field(default_factory=ReconstructionSettings)
    sensor_counts: tuple[int, ...] = tuple(range(3, 13))
    illuminants: tuple[str, ...] = ("cie:D65", "planck:2800K", "cie:FL11")
    reflectance_sets: tuple[str, ...] = ("munsell", "sfu")
    projection_sensors: int = 6
    colorimetric_start: float = 380.0
    colorimetric_end: float = 780.0
    colorimetric_step: float = 5.0


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


def reflectance_matrix(family: str, wavelengths: np.ndarray, *, data_dir: str | None = None) -> np.ndarray:
    """``(N, W)`` reflectances of a listable family (``"munsell"``, ``"sfu"``...) on *wavelengths*."""
    return family_values(family, wavelengths, data_dir=data_dir)


def _stats(errors: np.ndarray) -> tuple[float, float, float]:
    if errors.size == 0:
        raise SpectralDataError("no reflectance passed the dark-surface threshold; lower it")
    return float(errors.mean()), float(errors.std()), float(errors.max())


def _errors_for(
    settings: ReconstructionSettings, reflectances: np.ndarray, illuminant: np.ndarray,
    n: int, bounces: int,
) -> np.ndarray:
    wl = settings.wavelengths
    curves = settings.sensors(n)
    if bounces == 1:
        return one_bounce_errors(reflectances, illuminant, curves, wl, chip_threshold=settings.chip_threshold)
    return two_bounce_errors(
        reflectances, illuminant, curves, wl, pair_threshold=settings.pair_threshold,
        include_self_pairs=settings.include_self_pairs, chunk_size=settings.chunk_size,
    )


def _error_rows(
    settings: ReconstructionSettings, *, data_dir: str | None, progress: StepProgress | None,
    keep_errors: bool = False,
) -> tuple[list[ErrorRow], dict[tuple[int, int], np.ndarray]]:
    wl = settings.wavelengths
    f = reflectance_matrix(settings.reflectances, wl, data_dir=data_dir)
    light = get_spectrum(settings.illuminant, data_dir=data_dir).on(wl)
    rows, kept = [], {}
    for b in settings.bounces:
        for n in settings.sensor_counts:
            if progress is not None:
                progress(f"{settings.reflectances} / {settings.illuminant}: {n} sensors, {b} bounce(s)")
            err = _errors_for(settings, f, light, n, b)
            mean, sd, mx = _stats(err)
            rows.append(ErrorRow(n, b, mean, sd, mx, int(err.size), settings.illuminant, settings.reflectances))
            if keep_errors:
                kept[(n, b)] = err.astype(np.float32)
    return rows, kept


def reconstruction_table(
    settings: ReconstructionSettings | None = None, *, data_dir: str | None = None,
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


def _cie_lab(xyz: np.ndarray) -> np.ndarray:
    """CIE L*a*b* of XYZ (white Y = 1) relative to the D65 white of the CIE 1931 observer."""
    import colour

    white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    return np.asarray(colour.XYZ_to_Lab(xyz, white), float)


def _delta_e(lab_a: np.ndarray, lab_b: np.ndarray) -> np.ndarray:
    import colour

    return np.asarray(colour.delta_E(lab_a, lab_b, method="CIE 2000"), float)


def _de_row(method: str, bounces: int, illuminant: str, family: str, n: int, de: np.ndarray) -> DeltaERow:
    return DeltaERow(
        method, bounces, illuminant, family, n, float(de.mean()), float(de.std()),
        float(np.percentile(de, 95)), float(de.max()), int(de.size),
    )


def delta_e_rows(
    reflectances: np.ndarray, illuminant: np.ndarray, wavelengths: np.ndarray, *,
    illuminant_name: str, family: str, settings: ExtensionSettings,
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
    base = settings.base
    f_all = np.asarray(reflectances, float)
    f = f_all[f_all.mean(axis=1) >= base.chip_threshold]
    wl = wavelengths
    cmf = get_sensors("cie1931").on(wl)
    width = (base.sensor_end - base.sensor_start) / settings.projection_sensors
    s6 = gaussian_sensors(
        settings.projection_sensors, base.sensor_start, base.sensor_end,
        sigma=width * base.sigma_fraction, wavelengths=wl,
    ).curves
    norm = float(responses(illuminant, cmf[1:2], wl)[0])
    xyz_1 = responses(f * illuminant, cmf, wl) / norm
    p6 = responses(f * illuminant, s6, wl) / norm
    proj = fit_projection(p6, xyz_1)
    s6_f, s6_l = diagonal_values(f, s6, wl), responses(illuminant, s6, wl) / norm
    cm_f, cm_l = diagonal_values(f, cmf, wl), responses(illuminant, cmf, wl) / norm
    lab_1 = _cie_lab(xyz_1)
    n6 = settings.projection_sensors
    rows = [
        _de_row("two-pass", 1, illuminant_name, family, n6, _delta_e(lab_1, _cie_lab((s6_f * s6_l) @ proj.T))),
        _de_row("projection-only", 1, illuminant_name, family, n6, _delta_e(lab_1, _cie_lab(p6 @ proj.T))),
        _de_row("cie1931-diagonal", 1, illuminant_name, family, 3, _delta_e(lab_1, _cie_lab(cm_f * cm_l))),
    ]
    # Two bounces: the exact interreflection colour and its two approximations, chunk by chunk.
    de_two: dict[str, list[np.ndarray]] = {"two-pass": [], "projection-only": [], "cie1931-diagonal": []}
    both = np.concatenate([cmf, s6])
    for i, j, exact, _ in pair_responses(
        f, illuminant, both, wl, pair_threshold=base.pair_threshold,
        include_self_pairs=base.include_self_pairs, chunk_size=base.chunk_size,
    ):
        exact = exact / norm
        lab_exact = _cie_lab(exact[:, :3])
        for method, approx in (
            ("projection-only", exact[:, 3:] @ proj.T),
            ("two-pass", (s6_f[i] * s6_f[j] * s6_l) @ proj.T),
            ("cie1931-diagonal", cm_f[i] * cm_f[j] * cm_l),
        ):
            de_two[method].append(ordered_pairs(_delta_e(lab_exact, _cie_lab(approx)), i, j))
    for method, parts in de_two.items():
        n_s = 3 if method == "cie1931-diagonal" else n6
        rows.append(_de_row(method, 2, illuminant_name, family, n_s, np.concatenate(parts)))
    return rows


def run_extension(
    settings: ExtensionSettings | None = None, *, data_dir: str | None = None,
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
    wl_c = wavelength_grid(settings.colorimetric_start, settings.colorimetric_end, settings.colorimetric_step)
    for family in settings.reflectance_sets:
        if family == "sfu" and resolve_data_dir(data_dir) is None:
            skipped.append("sfu: no spectral data directory (--data-dir or SPECTRINSIC_DATA)")
            logger.info("skipping the SFU reflectances: no data directory configured")
            continue
        f_c = reflectance_matrix(family, wl_c, data_dir=data_dir)
        for light in settings.illuminants:
            run = replace(
                settings.base, sensor_counts=settings.sensor_counts, illuminant=light, reflectances=family,
            )
            found, _ = _error_rows(run, data_dir=data_dir, progress=progress)
            rows.extend(found)
            if progress is not None:
                progress(f"{family} / {light}: two-pass ΔE2000")
            de_rows.extend(delta_e_rows(
                f_c, get_spectrum(light).on(wl_c), wl_c, illuminant_name=light, family=family,
                settings=settings,
            ))
    return ExtensionResult(settings, tuple(rows), tuple(de_rows), tuple(skipped))
