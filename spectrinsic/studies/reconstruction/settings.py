"""Settings of the reconstruction-error study: every free choice of Table 5.2 and its extension."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import SpectralDataError
from ...spectra import gaussian_sensors, wavelength_grid

__all__ = ["ReconstructionSettings", "ExtensionSettings"]


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
            n,
            self.sensor_start,
            self.sensor_end,
            sigma=width * self.sigma_fraction,
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
