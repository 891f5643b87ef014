"""Photometric pre-correction undoes known light and sensor matrices (Eqs. 4.16, 4.23)."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.decompose._validation import ImageShapeError
from spectrinsic.decompose.evaluation.photometric import correction_matrix, photometric_correction
from spectrinsic.errors import SpectrinsicError

EXACT = 1e-10


@pytest.fixture()
def setup():
    rng = np.random.default_rng(11)
    canonical = rng.uniform(0.1, 1.0, (8, 9, 3))
    light = np.eye(3) * [1.3, 1.0, 0.6] + 0.05 * rng.standard_normal((3, 3))
    sensor = np.eye(3) + 0.1 * rng.standard_normal((3, 3))
    camera = canonical @ (light @ sensor).T  # p = L_CLig S_Sen p^{s,c} per pixel
    return canonical, light, sensor, camera


def test_sc1_recovers_the_canonical_image(setup):
    canonical, light, sensor, camera = setup
    out = photometric_correction(camera, "SC1", L_CLig=light, S_Sen=sensor)
    np.testing.assert_allclose(out, canonical, atol=EXACT)


def test_sc3b_removes_the_light_only(setup):
    canonical, light, _, _ = setup
    out = photometric_correction(canonical @ light.T, "SC3b", L_CLig=light)
    np.testing.assert_allclose(out, canonical, atol=EXACT)


def test_sc4_is_the_identity_and_bad_input_is_refused(setup):
    _, light, sensor, camera = setup
    np.testing.assert_array_equal(photometric_correction(camera, "SC4"), camera)
    with pytest.raises(ImageShapeError, match="needs the S_Sen"):
        correction_matrix("SC1", L_CLig=light)
    with pytest.raises(ImageShapeError, match="singular"):
        correction_matrix("SC3b", L_CLig=np.zeros((3, 3)))
    with pytest.raises(SpectrinsicError, match="did you mean 'SC3b'"):
        correction_matrix("SC3", L_CLig=light)
