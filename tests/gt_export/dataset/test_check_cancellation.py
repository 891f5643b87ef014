"""The identity check's tolerance scales with the magnitudes of the summed terms (issue 31):
float32 rounding where a large specular and residual cancel under a dark image is not a
failure, a real error of the same absolute size on small terms still is."""

from __future__ import annotations

import numpy as np

from spectrinsic.gt_export.dataset.check import IDENTITY_RTOL, _identity_problem
from spectrinsic.gt_export.layers.irradiance import residual

F32 = np.float32


def _stored(image, reflectance, shading, specular):
    """The layers as a sample stores them: float32, the residual from the stored values."""
    image, reflectance, shading, specular = (
        np.asarray(a, F32) for a in (image, reflectance, shading, specular)
    )
    res = residual(image, reflectance, shading, specular).astype(F32)
    return image, reflectance, shading, res, specular


def _cancelling(rng, n=4096):
    """A dark image (1e-3) made of a bright specular (~10) and a residual that cancels it."""
    reflectance = rng.uniform(0.05, 0.9, (n, 3))
    shading = rng.uniform(1e-4, 1e-3, (n, 3))
    specular = rng.uniform(5.0, 20.0, (n, 3))
    image = reflectance * shading + rng.uniform(0, 1e-3, (n, 3))
    return _stored(image, reflectance, shading, specular)


def test_rounding_of_cancelling_terms_passes_and_would_fail_relative_to_the_image():
    image, refl, shad, res, spec = _cancelling(np.random.default_rng(3))
    assert _identity_problem(image, refl, shad, res, spec) is None
    # the independent oracle: the same check relative to the image's own magnitude fails, by
    # the rounding of the large residual (~0.5 ulp of 10 = 5e-7 against an image of ~1e-3)
    rebuilt = refl.astype(float) * shad + res.astype(float) + spec.astype(float)
    relative_to_image = np.abs(rebuilt - image) / np.abs(image.astype(float))
    assert relative_to_image.max() > 100 * IDENTITY_RTOL


def test_a_real_error_is_still_found():
    image, refl, shad, res, spec = _cancelling(np.random.default_rng(4))
    wrong = image.copy()
    wrong[7, 1] += 1e-4 * (abs(spec[7, 1]) + abs(res[7, 1]))  # 1e-4 of the terms: ~800 eps
    problem = _identity_problem(wrong, refl, shad, res, spec)
    assert problem is not None and "at 1 channel values" in problem


def test_plain_product_identity_keeps_its_tolerance():
    rng = np.random.default_rng(5)
    refl = rng.uniform(0.05, 0.9, (256, 3)).astype(F32)
    shad = rng.uniform(0.1, 2.0, (256, 3)).astype(F32)
    image = (refl.astype(float) * shad).astype(F32)
    assert _identity_problem(image, refl, shad) is None
    assert _identity_problem(image * F32(1 + 20 * IDENTITY_RTOL), refl, shad) is not None
