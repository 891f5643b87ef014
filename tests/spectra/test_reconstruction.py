"""The reconstruction error of the diagonal model: Eq. 5.7 and its dark rule."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.spectra import relative_error


def test_relative_error_is_eq_5_7():
    ref = np.array([[[1.0, 2.0, 2.0], [0.0, 0.0, 0.0]]])
    est = np.array([[[1.0, 2.0, 5.0], [1.0, 1.0, 1.0]]])
    err = relative_error(est, ref)
    assert err[0, 0] == pytest.approx(1.0)  # ‖(0, 0, 3)‖ / ‖(1, 2, 2)‖
    assert np.isnan(err[0, 1])


def test_dark_rule_is_a_fraction_of_the_99th_percentile_norm():
    """Dark: ‖p‖ at most dark_fraction × P99 of the positive norms (in *where*); filled."""
    ref = np.zeros((1, 101, 3))
    ref[0, :, 1] = np.arange(101.0)  # norms 0..100; P99 of the positive ones is 99.01
    est = 1.1 * ref
    err = relative_error(est, ref, dark_fraction=0.5, fill=0.0)
    assert np.all(err[0, :50] == 0.0)  # ‖p‖ <= 49.505
    np.testing.assert_allclose(err[0, 50:], 0.1, rtol=1e-12)
    where = np.zeros((1, 101), bool)
    where[0, 90:] = True
    err = relative_error(est, ref, where=where)
    assert np.isnan(err[0, :90]).all() and np.isfinite(err[0, 90:]).all()
