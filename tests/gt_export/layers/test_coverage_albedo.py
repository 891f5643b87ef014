"""The coverage-weighted albedo summed only where each material covers a pixel (issue 45) has
the bits of the sum over every material, the rule readers rebuild ``reflectance_bands`` by."""

from __future__ import annotations

import numpy as np

from spectrinsic.gt_export.layers.irradiance import coverage_albedo


def _every_material(coverage: np.ndarray, band_albedos: np.ndarray) -> np.ndarray:
    """The sum as it was: every material on every pixel, in index order."""
    out = np.zeros((*coverage.shape[:-1], band_albedos.shape[-1]))
    for m in range(band_albedos.shape[0]):
        out += coverage[..., m, None] * band_albedos[m]
    return out


def _coverage(rng: np.random.Generator) -> np.ndarray:
    """One to three materials per pixel, with exact zeros, a -0, a NaN and an unused material."""
    coverage = rng.random((24, 20, 7)) * (rng.random((24, 20, 7)) < 0.3)
    coverage[..., 6] = 0.0  # a material no pixel shows
    coverage[0, 0, :] = -0.0
    coverage[1, 1, 2] = np.nan
    coverage[2, 2] = [1e-300, 0, 0, 1e300, 0, 0, 0]
    return coverage


def test_the_sum_over_covered_pixels_has_the_bits_of_the_full_sum():
    rng = np.random.default_rng(45)
    coverage = _coverage(rng)
    for band_albedos in (
        rng.random((7, 31)),
        rng.normal(size=(7, 5)),  # negative values: no ρ is, but the rule does not need it
    ):
        with np.errstate(invalid="ignore", over="ignore"):
            got = coverage_albedo(coverage, band_albedos)
            want = _every_material(coverage, band_albedos)
        assert got.tobytes() == want.tobytes()  # NaN and signed zeros included
        assert got.shape == (24, 20, band_albedos.shape[1])
    assert np.signbit(coverage_albedo(coverage, rng.random((7, 3)))[0, 0]).sum() == 0


def test_a_non_finite_albedo_spreads_as_in_the_full_sum():
    """0 · inf is NaN, not a zero: such an albedo is summed on every pixel."""
    rng = np.random.default_rng(7)
    coverage = _coverage(rng)
    band_albedos = rng.random((7, 4))
    band_albedos[3, 1] = np.inf
    with np.errstate(invalid="ignore"):
        got = coverage_albedo(coverage, band_albedos)
        want = _every_material(coverage, band_albedos)
    assert got.tobytes() == want.tobytes()
    assert not np.isfinite(got[..., 1]).any()  # NaN where 0 · inf, inf where material 3 shows
