"""Eq. 3.10's bounded least squares: the active-set solver against scipy's bounded LSMR."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import lsq_linear

import spectrinsic.decompose.methods.coherence as coherence
from spectrinsic.decompose.methods.coherence import bounded_minimum, global_coherence, grid_edges


@pytest.fixture(autouse=True)
def _no_fallback(monkeypatch):
    """The active set must settle by itself on these problems, not hand over to LSMR."""

    def refuse(a):
        raise AssertionError("bounded_minimum fell back to LSMR")

    monkeypatch.setattr(coherence, "_bounded_lsmr", refuse)


def _ratio_rows(rng, n: int, n_pairs: int) -> sp.csr_matrix:
    """Rows ``s (a_i x_i - a_j x_j)`` with positive ``a``, as global_coherence builds them."""
    i = rng.integers(0, n, n_pairs)
    j = (i + rng.integers(1, n, n_pairs)) % n
    a_i, a_j, s = rng.uniform(0.05, 1.0, (3, n_pairs))
    rows = np.repeat(np.arange(n_pairs), 2)
    cols = np.stack([i, j], axis=1).ravel()
    vals = np.stack([s * a_i, -s * a_j], axis=1).ravel()
    return sp.csr_matrix((vals, (rows, cols)), shape=(n_pairs, n))


@pytest.mark.parametrize("seed", range(6))
def test_active_set_reaches_the_bounded_least_squares_minimum(seed):
    rng = np.random.default_rng(seed)
    a = _ratio_rows(rng, n=60, n_pairs=150)
    ours = bounded_minimum(a)
    ref = lsq_linear(
        a.toarray(),
        np.zeros(a.shape[0]),
        bounds=(1.0, np.inf),
        method="bvls",
        tol=1e-14,
        max_iter=10000,
    ).x
    assert ours.min() >= 1.0 - 1e-12
    assert np.sum((a @ ours) ** 2) <= np.sum((a @ ref) ** 2) * (1 + 1e-9) + 1e-15
    np.testing.assert_allclose(ours, ref, rtol=1e-6)


def test_a_region_without_neighbours_keeps_scale_one():
    rng = np.random.default_rng(3)
    a = sp.hstack([_ratio_rows(rng, n=10, n_pairs=30), sp.csr_matrix((30, 1))]).tocsr()
    assert bounded_minimum(a)[-1] == 1.0


def test_coherence_scales_a_two_region_image_to_the_image_ratio():
    regions = np.array([[1, 1, 2, 2]] * 3)
    image = np.where(regions == 1, 0.2, 0.8)
    lam = global_coherence(regions, np.array([0.0, 0.5, 0.5]), image)
    assert lam[2] / lam[1] == pytest.approx(4.0, rel=1e-9) and lam[1:].min() == 1.0


def _lens(profile: np.ndarray, side: float = 0.15) -> np.ndarray:
    """A symmetric 3-tap point spread ``(side, 1 - 2 side, side)`` along the row."""
    padded = np.concatenate([profile[:1], profile, profile[-1:]])
    return side * padded[:-2] + (1.0 - 2.0 * side) * padded[1:-1] + side * padded[2:]


def _two_regions(row: np.ndarray, step_at: int, blurred: bool) -> float:
    """Reflectance ratio left/right that global_coherence gives a 3-row image of *row* split
    into two regions at *step_at*, each region's ``L`` its mean image intensity (the
    names-and-shades default); every edge marked *blurred* or none."""
    image = np.repeat(row[None, :], 3, axis=0)
    regions = np.where(np.arange(row.size) < step_at, 1, 2)[None, :].repeat(3, axis=0)
    means = np.array([0.0, image[regions == 1].mean(), image[regions == 2].mean()])
    marks = np.ones(grid_edges(regions > 0)[1].shape[0], bool) if blurred else None
    lam = global_coherence(regions, means, image, marks)
    return float(lam[1] * means[1] / (lam[2] * means[2]))


def test_coherence_reads_a_blurred_step_past_its_mixed_pixels():
    # paper 0.8 beside print 0.05 (ratio 16) under uniform light, through a lens that mixes
    # 15 % into each neighbour: the boundary pixels hold 0.6875 and 0.1625 (ratio 4.2)
    row = _lens(np.where(np.arange(16) < 8, 0.8, 0.05))
    assert _two_regions(row, 8, blurred=False) == pytest.approx(4.23, abs=0.01)  # before
    assert _two_regions(row, 8, blurred=True) == pytest.approx(16.0, rel=1e-6)


def test_a_shading_gradient_at_a_sharp_step_is_not_taken_for_blur():
    # the same step, unblurred, under a light falling 10 % per pixel: reading inside would
    # add the gradient to the ratio; the extrapolated reads give the boundary pixels' values
    x = np.arange(16)
    row = np.where(x < 8, 0.8, 0.05) * 0.9**x
    assert _two_regions(row, 8, blurred=True) == pytest.approx(
        _two_regions(row, 8, blurred=False), rel=1e-9
    )
    assert _two_regions(row, 8, blurred=False) == pytest.approx(16 / 0.9, rel=1e-6)


def test_a_blurred_step_under_a_shading_gradient_reads_as_the_unblurred_boundary():
    # the blurred print of the first test under the falling light of the second (teabag1 at
    # half size: mixed pixels and a gradient together); the extrapolation from the two pixels
    # behind each boundary pixel gives what Eq. 3.8 reads on the unblurred image, 16 / 0.9
    # (round 6's reads past the blur went 2 px inside and read 21.9, the gradient over 4 px)
    x = np.arange(16)
    row = _lens(np.where(x < 8, 0.8, 0.05) * 0.9**x)
    assert _two_regions(row, 8, blurred=False) == pytest.approx(4.44, abs=0.01)  # mixed
    assert _two_regions(row, 8, blurred=True) == pytest.approx(16 / 0.9, rel=1e-6)


def test_a_side_without_two_pixels_behind_it_is_read_on_its_boundary():
    # a one-pixel-wide middle region cannot be extrapolated: both its edges read the
    # boundary pixels, so the marks change nothing on an unblurred image
    image = np.array([[0.8, 0.8, 0.8, 0.05, 0.8, 0.8, 0.8]] * 3)
    regions = np.array([[1, 1, 1, 2, 3, 3, 3]] * 3)
    means = np.array([0.0, 0.8, 0.05, 0.8])
    marks = np.ones(grid_edges(regions > 0)[1].shape[0], bool)
    lam = global_coherence(regions, means, image, marks)
    assert lam[1] * means[1] / (lam[2] * means[2]) == pytest.approx(16.0, rel=1e-9)
    assert lam[3] == pytest.approx(lam[1], rel=1e-9)
