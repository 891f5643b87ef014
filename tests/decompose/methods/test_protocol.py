"""Hold-one-out parameter choice and global colour constancy, against hand-worked cases."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.decompose.methods.constancy import discount_illuminant, illuminant_colour
from spectrinsic.decompose.methods.protocol import grid_points, hold_one_out, scene_group
from spectrinsic.errors import SpectrinsicError

A, B = (("t", 1),), (("t", 2),)


def test_hold_one_out_by_hand():
    groups = {"x1": "x", "x2": "x", "y1": "y", "z1": "z"}
    # group means: A: x 1.0, y 1.0, z 4.0 ; B: x 2.0, y 2.0, z 1.0
    table = {
        A: {"x1": 0.5, "x2": 1.5, "y1": 1.0, "z1": 4.0},
        B: {"x1": 2.0, "x2": 2.0, "y1": 2.0, "z1": 1.0},
    }
    res = hold_one_out(table, groups)
    # all groups: A 2.0, B 5/3 -> B
    assert res.chosen == B and res.chosen_score == pytest.approx(5.0 / 3.0)
    folds = {f.held_out: f for f in res.folds}
    # without x: A (1+4)/2 = 2.5, B (2+1)/2 = 1.5 -> B, scored on x: 2.0
    assert folds["x"].chosen == B and folds["x"].score == 2.0
    # without y: same -> B, y scores 2.0
    assert folds["y"].chosen == B and folds["y"].score == 2.0
    # without z: A 1.0, B 2.0 -> A, z scores 4.0
    assert folds["z"].chosen == A and folds["z"].score == 4.0
    assert res.held_out_score == pytest.approx((2.0 + 2.0 + 4.0) / 3.0)


def test_hold_one_out_with_a_constraint_by_hand():
    """The table of the test above with B ineligible wherever the groups it is chosen on
    include z (say B loses to a baseline there): A everywhere except the fold without z."""
    groups = {"x1": "x", "x2": "x", "y1": "y", "z1": "z"}
    table = {
        A: {"x1": 0.5, "x2": 1.5, "y1": 1.0, "z1": 4.0},
        B: {"x1": 2.0, "x2": 2.0, "y1": 2.0, "z1": 1.0},
    }
    res = hold_one_out(table, groups, eligible=lambda p, keep: p == A or "z" not in keep)
    assert res.chosen == A and res.chosen_score == pytest.approx(2.0)
    folds = {f.held_out: f for f in res.folds}
    assert folds["x"].chosen == A and folds["x"].score == 1.0
    assert folds["y"].chosen == A and folds["y"].score == 1.0
    assert folds["z"].chosen == A and folds["z"].score == 4.0
    assert res.held_out_score == pytest.approx(2.0)


def test_hold_one_out_needs_two_groups_and_treats_nan_as_worst():
    with pytest.raises(SpectrinsicError, match="at least 2 scene groups"):
        hold_one_out({A: {"a": 1.0}}, {"a": "g"})
    res = hold_one_out({A: {"a": np.nan, "b": 0.0}, B: {"a": 1.0, "b": 1.0}}, {"a": "g", "b": "h"})
    assert res.chosen == B


def test_grid_points_and_groups():
    assert grid_points({"b": [1, 2], "a": ["u"]}) == [
        (("a", "u"), ("b", 1)),
        (("a", "u"), ("b", 2)),
    ]
    assert scene_group("obj-apple__v0__two-colour-a") == "obj-apple"


def test_colour_constancy_estimates_by_hand():
    mask = np.ones((1, 2), bool)
    image = np.array([[[1.0, 2.0, 3.0], [3.0, 2.0, 1.0]]])
    np.testing.assert_allclose(illuminant_colour(image, mask, "grey-world"), [1.0, 1.0, 1.0])
    # p = 6: (mean(1^6, 3^6))^(1/6) = 365^(1/6) for R and B, 2 for G; normalised to mean 1
    r = 365.0 ** (1.0 / 6.0)
    expected = np.array([r, 2.0, r]) / ((2 * r + 2.0) / 3.0)
    np.testing.assert_allclose(illuminant_colour(image, mask, "shades-of-grey"), expected)
    np.testing.assert_allclose(illuminant_colour(image, mask, "none"), [1.0, 1.0, 1.0])
    tinted = np.ones((3, 3, 3)) * np.array([2.0, 1.0, 0.5])
    refl, light = discount_illuminant(tinted, tinted, np.ones((3, 3), bool), "max-rgb")
    np.testing.assert_allclose(light, np.array([2.0, 1.0, 0.5]) / (3.5 / 3.0), rtol=1e-6)
    np.testing.assert_allclose(refl, 3.5 / 3.0)  # the tint is gone, the mean kept
    with pytest.raises(SpectrinsicError, match="colour constancy"):
        illuminant_colour(image, mask, "gray-world")


@pytest.mark.parametrize("method", ["colour-retinex", "names-shades"])
def test_post_hoc_constancy_equals_the_decomposer_option(method):
    """score_grid applies colour constancy after the decomposition; it must be what the
    decomposer's own option gives (up to float32 storage)."""
    from spectrinsic.decompose.methods.constancy import with_constancy
    from spectrinsic.decompose.methods.registry import get_decomposer
    from spectrinsic.decompose.synthetic import mondrian

    scene = mondrian(40, 40, seed=4, light=(1.0, 0.8, 0.5))
    mask = np.ones((40, 40), bool)
    direct = get_decomposer(method, colour_constancy="shades-of-grey")(scene.image, mask)
    plain = get_decomposer(method, colour_constancy="none")(scene.image, mask)
    post = with_constancy(plain, scene.image, mask, colour_constancy="shades-of-grey")
    np.testing.assert_allclose(post.reflectance, direct.reflectance, rtol=1e-5)
    np.testing.assert_allclose(post.shading, direct.shading, rtol=1e-5)
    assert not np.allclose(plain.reflectance, direct.reflectance, rtol=1e-3)
