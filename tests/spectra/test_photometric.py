"""The photometric model's fits and the scenario estimates of thesis Table 4.3."""

from __future__ import annotations

import numpy as np

from spectrinsic.spectra import angular_error, fit_matrix, scenario_estimates

#: Float round-off bound for exact algebraic recoveries (degrees or matrix entries).
EXACT_TOL = 1e-8
#: arccos near 1 loses half the digits: identical vectors come out up to ~1e-6 degrees apart.
ANGLE_ROUNDOFF_DEG = 1e-5


def test_full_fit_recovers_a_known_transform():
    rng = np.random.default_rng(1)
    q = rng.random((50, 3))
    m = np.array([[0.9, 0.2, -0.1], [0.05, 1.1, 0.1], [-0.02, 0.15, 0.7]])
    np.testing.assert_allclose(fit_matrix(q, q @ m.T), m, atol=EXACT_TOL)
    d = np.diag([1.7, 1.0, 0.4])
    np.testing.assert_allclose(fit_matrix(q, q @ d.T, diagonal=True), d, atol=EXACT_TOL)


def test_scenarios_invert_a_synthetic_model_exactly():
    """p = L · S · p^{s,c} with known S and a diagonal L: SC1 and SC2 recover p^{s,c}; SC3 (no
    sensor correction) leaves the relative reflectance S · p^{s,c}; SC4 is p itself."""
    rng = np.random.default_rng(2)
    p_sc = rng.random((140, 3)) + 0.05
    s = np.array([[0.8, 0.3, 0.0], [0.1, 1.0, 0.2], [0.0, 0.2, 0.6]])
    light = np.diag([1.6, 1.0, 0.5])
    p_c = p_sc @ s.T
    p = p_c @ light.T
    est = scenario_estimates(p, p_c, p_sc)
    for sc in ("SC1", "SC2"):
        np.testing.assert_allclose(est[sc], p_sc, rtol=1e-9)
        assert angular_error(est[sc], p_sc).max() < ANGLE_ROUNDOFF_DEG
    np.testing.assert_allclose(est["SC3"], p_c, rtol=1e-9)
    np.testing.assert_array_equal(est["SC4"], p)
