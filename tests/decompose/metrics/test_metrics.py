"""Metrics against independent values: identities, hand-computed cases, scikit-image."""

from __future__ import annotations

import math

import numpy as np
import pytest
from skimage.metrics import structural_similarity

from spectrinsic.decompose import metrics as M
from spectrinsic.decompose._validation import ImageShapeError
from spectrinsic.decompose.metrics import colour as MC
from spectrinsic.decompose.metrics import scale as MS
from spectrinsic.decompose.metrics.judgements import (
    DARKER_1,
    DARKER_2,
    EQUAL,
    Judgements,
    sample_judgements,
)
from spectrinsic.errors import SpectrinsicError

#: Float64 round-off on sums of a few thousand terms.
EXACT = 1e-12
#: Round-off after multiplying by a scale that is not a power of two.
SCALED = 1e-9
#: acos near 1 turns a 1e-16 cosine error into ~1e-6 degrees.
ANGLE_ROUNDOFF_DEG = 1e-5


@pytest.fixture()
def pair():
    rng = np.random.default_rng(7)
    truth = rng.uniform(0.05, 1.0, (48, 52, 3))
    estimate = truth * rng.uniform(0.5, 1.5, truth.shape)
    return truth, estimate


@pytest.mark.parametrize("grey", [False, True])
def test_identical_images_score_perfectly(pair, grey):
    truth = pair[0].mean(axis=2) if grey else pair[0]
    names = [
        n
        for n in M.METRICS
        if not (
            grey
            and "reflectance" in M.METRICS[n].layers
            and n.startswith(("angular", "chromaticity"))
        )
    ]
    scores = M.compute_metrics(truth, truth.copy(), names)
    for name, value in scores.items():
        expected = 1.0 if M.METRICS[name].better == "higher" else 0.0
        tol = (
            ANGLE_ROUNDOFF_DEG
            if "angular" in M.METRICS[name].equation or "4.31" in M.METRICS[name].equation
            else EXACT
        )
        assert value == pytest.approx(expected, abs=tol), name


def test_scaled_estimate_scores_zero_on_scale_invariant_metrics(pair):
    truth = pair[0]
    mask = np.zeros(truth.shape[:2], bool)
    mask[5:40, 3:50] = True
    for name, metric in M.METRICS.items():
        assert metric.scale_invariant
        value = metric.func(truth, 3.7 * truth, mask=mask)
        expected = 1.0 if metric.better == "higher" else 0.0
        tol = (
            ANGLE_ROUNDOFF_DEG
            if "angular" in M.METRICS[name].equation or "4.31" in M.METRICS[name].equation
            else SCALED
        )
        assert value == pytest.approx(expected, abs=tol), name
    judgements = sample_judgements(truth, seed=1, n_pairs=300, mask=mask)
    assert M.whdr(3.7 * truth, judgements) == 0.0


def test_lmse_hand_computed_two_windows():
    # truth 1 everywhere; estimate 1 left of column 15, 2 from it. Windows (20x20, step 10) on a
    # 20x30 image: columns 0-19 and 10-29. Per window alpha = sum(TE)/sum(E^2):
    # w1: alpha = 500/700, residual 300(1-5/7)^2 + 100(1-10/7)^2 = 300/7, energy 400;
    # w2: alpha = 700/1300, residual 100(6/13)^2 + 300(1/13)^2 = 300/13, energy 400.
    truth = np.ones((20, 30))
    estimate = np.where(np.arange(30) < 15, 1.0, 2.0)[None, :].repeat(20, axis=0)
    expected = (300 / 7 + 300 / 13) / 800  # = 15/182
    assert MS.lmse(truth, estimate) == pytest.approx(expected, rel=EXACT)
    # colour copies of the same grey image give the same value with one alpha per window
    colour = np.repeat(estimate[:, :, None], 3, axis=2)
    assert MS.lmse(np.ones((20, 30, 3)), colour) == pytest.approx(expected, rel=EXACT)


def test_lmse_window_straddling_the_mask():
    # As above, but pixels from column 25 on are masked out (and hold garbage): window 2 keeps
    # columns 10-24: 100 px of E=1, 200 px of E=2; alpha = 500/900, residual = 1600/81 + 200/81
    # = 200/9, energy 300. Window 1 is unchanged (300/7 over 400).
    truth = np.ones((20, 30))
    estimate = np.where(np.arange(30) < 15, 1.0, 2.0)[None, :].repeat(20, axis=0)
    mask = np.broadcast_to(np.arange(30) < 25, (20, 30))
    truth[:, 25:] = 123.0
    estimate[:, 25:] = -7.0
    expected = (300 / 7 + 200 / 9) / (400 + 300)
    assert MS.lmse(truth, estimate, mask=mask) == pytest.approx(expected, rel=EXACT)


def test_mit_score_averages_shading_and_reflectance(pair):
    truth, estimate = pair
    s, r = truth[..., 0], truth
    es, er = estimate[..., 0], estimate
    assert MS.mit_score(s, r, es, er) == pytest.approx(
        0.5 * MS.lmse(s, es) + 0.5 * MS.lmse(r, er), rel=EXACT
    )


def test_si_mse_closed_form():
    # truth (1, 2), estimate (1, 1): alpha = 3/2, residual (1-1.5)^2 + (2-1.5)^2 = 0.5 over 2.
    assert MS.si_mse(np.array([[1.0, 2.0]]), np.array([[1.0, 1.0]])) == pytest.approx(0.25)


def test_correlation_matches_numpy(pair):
    truth, estimate = pair
    assert MS.correlation(truth, estimate) == pytest.approx(
        np.corrcoef(truth.ravel(), estimate.ravel())[0, 1], rel=1e-12
    )


def test_dssim_equals_scikit_image(pair):
    truth, estimate = pair
    ssim = structural_similarity(truth, estimate, data_range=1.0, channel_axis=-1)
    value = MS.dssim(truth, estimate, data_range=1.0, fit_scale=False)
    assert value == pytest.approx((1.0 - ssim) / 2.0, rel=EXACT)
    grey = structural_similarity(truth[..., 1], estimate[..., 1], data_range=1.0)
    assert MS.dssim(truth[..., 1], estimate[..., 1], data_range=1.0, fit_scale=False) == (
        pytest.approx((1.0 - grey) / 2.0, rel=EXACT)
    )


def test_whdr_hand_computed():
    reflectance = np.array([[1.0, 1.05, 2.0, 0.5]])
    p = lambda *cols: np.array([[0, c] for c in cols])  # noqa: E731
    # predictions (delta 0.1): (0,1) E; (0,2) 1 [2/1 > 1.1]; (0,3) 2; (1,0) E [1.05 < 1.1]
    judgements = Judgements(
        points1=p(0, 0, 0, 1),
        points2=p(1, 2, 3, 0),
        labels=np.array([EQUAL, DARKER_1, EQUAL, DARKER_2]),
        weights=np.array([1.0, 1.0, 2.0, 0.5]),
        within=np.zeros(4, bool),
    )
    # disagreements: the third (weight 2) and the fourth (weight 0.5) -> 2.5 / 4.5
    assert M.whdr(reflectance, judgements) == pytest.approx(2.5 / 4.5)


def test_sample_judgements_is_seeded_and_mixes_materials():
    rng = np.random.default_rng(0)
    ids = np.repeat(np.arange(4), 100).reshape(20, 20)
    refl = np.array([0.2, 0.4, 0.41, 0.8])[ids][:, :, None] * np.ones(3)
    a = sample_judgements(refl, seed=5, n_pairs=200, material_ids=ids)
    b = sample_judgements(refl, seed=5, n_pairs=200, material_ids=ids)
    np.testing.assert_array_equal(a.points1, b.points1)
    i1 = ids[a.points1[:, 0], a.points1[:, 1]]
    i2 = ids[a.points2[:, 0], a.points2[:, 1]]
    assert np.all(i1[a.within] == i2[a.within]) and np.all(i1[~a.within] != i2[~a.within])
    assert np.all(a.labels[a.within] == EQUAL)  # flat materials: equal reflectance
    assert {DARKER_1, DARKER_2} <= set(a.labels[~a.within].tolist())
    assert (
        M.whdr(refl, a) == 0.0 and M.whdr(refl[..., ::-1] * 0 + rng.uniform(size=refl.shape), a) > 0
    )


def test_angular_error_stats():
    truth = np.ones((2, 2, 3))
    estimate = np.ones((2, 2, 3))
    estimate[0, 0] = [1.0, 0.0, 0.0]  # angle to (1,1,1): acos(1/sqrt(3)) = 54.7356 deg
    angle = np.degrees(np.arccos(1 / np.sqrt(3)))
    assert MC.angular_error_mean(truth, estimate) == pytest.approx(angle / 4)
    assert MC.angular_error_median(truth, estimate) == pytest.approx(0.0)


def test_shape_checks_and_registry():
    with pytest.raises(ImageShapeError, match="differs"):
        MS.lmse(np.ones((30, 30)), np.ones((30, 31)))
    with pytest.raises(ImageShapeError, match="mask must have shape"):
        MS.lmse(np.ones((30, 30)), np.ones((30, 30)), mask=np.ones((3, 3), bool))
    with pytest.raises(ImageShapeError, match="smaller than"):
        MS.lmse(np.ones((10, 10)), np.ones((10, 10)))
    with pytest.raises(ImageShapeError, match="NaN"):
        MS.si_mse(np.full((4, 4), np.nan), np.ones((4, 4)))
    with pytest.raises(SpectrinsicError, match="did you mean 'lmse'"):
        M.get_metric("lmsee")
    assert M.get_metric("lmse").equation == "Eq. 2.5"


# --- coloured-shading metrics and the MAW-style split of reflectance error -----------------

#: acos(1/sqrt(3)): the angle between a primary and the achromatic axis, degrees.
PRIMARY_TO_GREY_DEG = math.degrees(math.acos(1.0 / math.sqrt(3.0)))


def _shading_case():
    truth = np.ones((2, 3, 3))
    estimate = np.ones((2, 3, 3))
    estimate[0, 0] = (1.0, 0.0, 0.0)  # 54.7356 degrees
    estimate[0, 1] = (2.0, 2.0, 2.0)  # same colour, other intensity: 0
    estimate[0, 2] = (0.0, 0.0, 0.0)  # zero estimate under light: 90 degrees
    estimate[1, 0] = (0.0, 1.0, 0.0)  # masked out below
    truth[1, 1] = 0.0  # no light arrives: not scored
    mask = np.ones((2, 3), bool)
    mask[1, 0] = False
    return truth, estimate, mask


def test_shading_chromaticity_error_hand_computed():
    truth, estimate, mask = _shading_case()
    # scored pixels: (0,0) 54.74, (0,1) 0, (0,2) 90, (1,2) 0
    expected_mean = (PRIMARY_TO_GREY_DEG + 0.0 + 90.0 + 0.0) / 4.0
    value = MC.shading_chromaticity_error(truth, estimate, mask=mask)
    assert value == pytest.approx(expected_mean, abs=ANGLE_ROUNDOFF_DEG)
    median = MC.shading_chromaticity_error(truth, estimate, mask=mask, statistic="median")
    assert median == pytest.approx(PRIMARY_TO_GREY_DEG / 2.0, abs=ANGLE_ROUNDOFF_DEG)


def test_shading_chromaticity_error_scores_grey_shading_as_white_light():
    truth = np.zeros((4, 4, 3))
    truth[..., 0] = 2.0  # red light everywhere
    grey = np.full((4, 4), 0.3)
    value = MC.shading_chromaticity_error(truth, grey)
    assert value == pytest.approx(PRIMARY_TO_GREY_DEG, abs=ANGLE_ROUNDOFF_DEG)
    assert MC.shading_chromaticity_error(truth, 5.0 * truth) == pytest.approx(0.0, abs=1e-6)


def test_shading_chromaticity_error_rejects_bad_input():
    with pytest.raises(ImageShapeError, match="differs from truth shape"):
        MC.shading_chromaticity_error(np.ones((4, 4, 3)), np.ones((4, 5, 3)))
    with pytest.raises(ImageShapeError, match="colour or"):
        MC.shading_chromaticity_error(np.ones((4, 4, 2)), np.ones((4, 4, 2)))
    with pytest.raises(SpectrinsicError, match="statistic"):
        MC.shading_chromaticity_error(np.ones((4, 4, 3)), np.ones((4, 4, 3)), statistic="max")


def test_reflectance_intensity_error_hand_computed():
    # grey truth intensities 1, 2, 3 against a flat estimate: alpha = 6 / 3 = 2,
    # residual (1-2)^2 + 0 + (3-2)^2 = 2, energy 1 + 4 + 9 = 14.
    truth = np.array([1.0, 2.0, 3.0])[None, :, None] * np.ones((1, 3, 3))
    flat = np.full((1, 3, 3), 0.4)
    assert MC.reflectance_intensity_error(truth, flat) == pytest.approx(2.0 / 14.0, abs=EXACT)
    mask = np.array([[True, False, True]])  # intensities 1 and 3: alpha 2, residual 2, energy 10
    assert MC.reflectance_intensity_error(truth, flat, mask=mask) == pytest.approx(0.2, abs=EXACT)
    with pytest.raises(ImageShapeError, match="masked truth is zero"):
        MC.reflectance_intensity_error(np.zeros((2, 2, 3)), np.ones((2, 2, 3)))


def test_maw_split_separates_colour_from_lightness():
    truth = np.ones((3, 3, 3))
    recoloured = np.broadcast_to(np.array([1.5, 0.5, 1.0]), (3, 3, 3))  # same channel mean
    # (1,1,1).(1.5,0.5,1) = 3; |.| = sqrt(3) sqrt(3.5)
    angle = math.degrees(math.acos(3.0 / math.sqrt(3.0 * 3.5)))
    assert MC.reflectance_intensity_error(truth, recoloured) == pytest.approx(0.0, abs=EXACT)
    assert MC.reflectance_chromaticity_error(truth, recoloured) == pytest.approx(
        angle, abs=ANGLE_ROUNDOFF_DEG
    )
    darker = truth.copy()
    darker[0] *= 0.5  # lightness change, colour kept
    assert MC.reflectance_chromaticity_error(truth, darker) == pytest.approx(
        0.0, abs=ANGLE_ROUNDOFF_DEG
    )
    # intensities 1 (6 px) and 0.5 (3 px) against 1: alpha = 7.5/9, see the formula above
    t = np.array([1.0] * 6 + [1.0] * 3)
    e = np.array([1.0] * 6 + [0.5] * 3)
    alpha = (t * e).sum() / (e * e).sum()
    expected = ((t - alpha * e) ** 2).sum() / (t * t).sum()
    assert MC.reflectance_intensity_error(darker, truth) > 0.0
    assert MC.reflectance_intensity_error(truth, darker) == pytest.approx(expected, abs=EXACT)
    with pytest.raises(ImageShapeError, match="needs .H, W, 3. images"):
        MC.reflectance_chromaticity_error(np.ones((3, 3)), np.ones((3, 3)))
