"""Issue 48's stress variants of an MIT object, on a synthetic object (no data needed)."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.decompose.evaluation.mit import MitObject
from spectrinsic.decompose.evaluation.mit_variants import VARIANTS, apply_variant


def _object() -> MitObject:
    rng = np.random.default_rng(0)
    refl = rng.uniform(0.1, 0.9, (10, 13, 3))
    shade = np.linspace(0.2, 1.0, 13)[None, :].repeat(10, axis=0)
    mask = np.ones((10, 13), bool)
    mask[0, 0] = False
    return MitObject("thing", refl * shade[:, :, None], refl, shade, mask)


def test_exposure_scales_and_saturates_like_a_sensor() -> None:
    obj = _object()
    dark = apply_variant("exposure-x0.25", obj)
    np.testing.assert_allclose(dark.image, 0.25 * obj.image, atol=1.0 / 65535)
    bright = apply_variant("exposure-x4", obj)
    assert bright.image.max() == 1.0
    unsaturated = 4.0 * obj.image < 1.0
    np.testing.assert_allclose(bright.image[unsaturated], 4.0 * obj.image[unsaturated], atol=1e-4)
    assert bright.reflectance is obj.reflectance and bright.shading is obj.shading


def test_white_balance_changes_the_channels_not_the_truth() -> None:
    obj = _object()
    warm = apply_variant("white-balance", obj)
    ratio = warm.image.reshape(-1, 3) / obj.image.reshape(-1, 3)
    np.testing.assert_allclose(np.median(ratio, axis=0), (1.25, 1.0, 0.75), atol=1e-3)


def test_noise_is_seeded_and_of_the_stated_size() -> None:
    obj = _object()
    a, b = apply_variant("noise", obj), apply_variant("noise", obj)
    np.testing.assert_array_equal(a.image, b.image)
    z = (a.image - obj.image) / np.sqrt(1e-4 * obj.image + 0.002**2)
    assert 0.8 < z.std() < 1.2 and abs(z.mean()) < 0.2


def test_half_resolution_averages_image_and_truth_and_shrinks_the_mask() -> None:
    obj = _object()
    half = apply_variant("downscale-0.5", obj)
    assert half.image.shape == (5, 6, 3) and half.shading.shape == (5, 6)
    np.testing.assert_allclose(half.shading[1, 2], obj.shading[2:4, 4:6].mean())
    assert not half.mask[0, 0] and half.mask[1:, 1:].all()


def test_every_variant_keeps_the_input_in_unit_range_and_unknown_names_are_refused() -> None:
    obj = _object()
    for name in VARIANTS:
        image = apply_variant(name, obj).image
        assert image.min() >= 0.0 and image.max() <= 1.0
    with pytest.raises(KeyError, match="expected one of original"):
        apply_variant("sepia", obj)
