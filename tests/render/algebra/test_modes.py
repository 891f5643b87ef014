"""The colour maths of render modes (no Mitsuba)."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.errors import SpectrinsicError
from spectrinsic.render.algebra import modes
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as WL
from spectrinsic.spectra import family_values, get_sensors, get_spectrum, responses

#: Exact identities in float64.
EXACT = 1e-10
#: Error of a 31 × 10 nm band cube integrated against the CMFs, for smooth radiances
#: (Munsell chips under Planckian/daylight light): measured at most 0.57 % (Z of 5G 6/8
#: under 2800 K, where z̄ peaks and the radiance is steep within a band).
BAND_INTEGRATION_TOL = 1e-2
#: Mean relative XYZ error of the 6-Gaussian regression on its own training radiances
#: (thesis Table 5.2 reports 0.19 % mean for one bounce under D65 with 6 sensors; the
#: regression to XYZ adds its own error, measured ~0.5 %).
REGRESSION_MEAN_TOL = 0.02


def test_unknown_mode_suggests_close_names():
    with pytest.raises(SpectrinsicError, match="did you mean 'rgb6'"):
        modes.get_mode("rgb7")


def test_pass_counts():
    assert [
        modes.n_passes(modes.get_mode(m)) for m in ("spectral", "rgb3", "gauss3", "rgb6", "bands31")
    ] == [1, 1, 1, 2, 11]


def test_pad_to_passes_zero_pads_last_block():
    blocks = modes.pad_to_passes(np.arange(8.0).reshape(2, 4))
    assert len(blocks) == 2
    np.testing.assert_array_equal(blocks[1], [[3, 0, 0], [7, 0, 0]])


def test_integration_matrix_is_exact_for_flat_radiance():
    bands, cmf = get_sensors("bands:31@400-700"), get_sensors("cie1931")
    t = modes.integration_matrix(bands, cmf)
    flat = np.full(WL.size, 0.7)
    raw = responses(flat, bands.on(WL), WL)
    np.testing.assert_allclose(t @ raw, responses(flat, cmf.on(WL), WL), rtol=EXACT)


@pytest.mark.parametrize("reflectance", ["munsell:5R 5/12", "munsell:5G 6/8", "munsell:5PB 4/10"])
@pytest.mark.parametrize("light", ["planck:2800K", "daylight:6500K"])
def test_integration_matrix_recovers_xyz_of_smooth_radiance(reflectance, light):
    bands, cmf = get_sensors("bands:31@400-700"), get_sensors("cie1931")
    radiance = get_spectrum(reflectance).on(WL) * get_spectrum(light).on(WL)
    xyz = modes.integration_matrix(bands, cmf) @ responses(radiance, bands.on(WL), WL)
    np.testing.assert_allclose(xyz, responses(radiance, cmf.on(WL), WL), rtol=BAND_INTEGRATION_TOL)


def test_regression_matrix_projects_six_sensors_to_xyz():
    g6, cmf = get_sensors("gaussian:6@400-700"), get_sensors("cie1931")
    light = get_spectrum("planck:3500K").on(WL)
    p = modes.regression_matrix(g6, cmf, light[None])
    rho = family_values("munsell", WL)  # the matte Munsell chips
    xyz = responses(rho * light, cmf.on(WL), WL)
    est = responses(rho * light, g6.on(WL), WL) @ p.T
    err = np.linalg.norm(est - xyz, axis=1) / np.linalg.norm(xyz, axis=1)
    assert p.shape == (3, 6)
    assert float(np.mean(err)) < REGRESSION_MEAN_TOL


def test_channel_values_follow_eq_5_2(make_plane):
    scene = make_plane("flat:0.4", "cie:D65", power=2.0)
    sensors = get_sensors("gaussian:6@400-700")
    values = modes.channel_values(scene, sensors)
    # a flat reflectance keeps its value in every channel (Eq. 5.4 normalised)
    np.testing.assert_allclose(values.materials, 0.4, rtol=EXACT)
    expected = 2.0 * responses(get_spectrum("cie:D65").on(WL), sensors.on(WL), WL)
    np.testing.assert_allclose(values.lights[0], expected, rtol=EXACT)


def test_identity_modes_need_three_sensors(make_plane):
    scene = make_plane("flat:0.4", "cie:D65")
    np.testing.assert_array_equal(modes.to_xyz_matrix(modes.get_mode("rgb3"), scene), np.eye(3))


def test_raw_to_xyz_is_the_float64_product_over_chunk_boundaries():
    """Chunked einsum (no BLAS) against exact sums: float64 output within a few ulps of
    ``math.fsum`` of the products, float32 output that value rounded once."""
    import math

    rng = np.random.default_rng(5)
    raw = rng.uniform(-1.0, 4.0, (3, 101, 97, 31)).astype(np.float32)  # 29391 pixels: 4 chunks
    matrix = rng.standard_normal((3, 31))
    wide = modes.raw_to_xyz(raw, matrix, np.float64)
    narrow = modes.raw_to_xyz(raw, matrix)
    assert wide.shape == narrow.shape == (3, 101, 97, 3)
    assert wide.dtype == np.float64 and narrow.dtype == np.float32
    assert np.array_equal(narrow, wide.astype(np.float32))
    flat_raw, flat_wide = raw.reshape(-1, 31).astype(np.float64), wide.reshape(-1, 3)
    for i in rng.choice(flat_raw.shape[0], 200, replace=False):
        for c in range(3):
            exact = math.fsum(flat_raw[i] * matrix[c])
            scale = math.fsum(np.abs(flat_raw[i] * matrix[c]))
            assert abs(flat_wide[i, c] - exact) <= 64 * np.finfo(float).eps * scale
