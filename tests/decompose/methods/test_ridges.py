"""The colour-shade descriptor (thesis sec. 3.2.2): RAD's ridges on distributions of known shape.

Under white light and Lambertian shading the log colours of one surface lie on a line along the
grey diagonal (log rho + log s (1, 1, 1)); RAD should find one ridge per surface, running along
that diagonal, and the MRF (sec. 3.3.2) should weigh a step across a cast shadow as Case C.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.decompose.methods.names_shades import NamesAndShades, grid_edges
from spectrinsic.decompose.methods.ridges import colour_shades
from spectrinsic.errors import SpectrinsicError

pytestmark = pytest.mark.filterwarnings("ignore::FutureWarning")  # gco's numpy aliases

ALBEDOS = np.array([[0.8, 0.2, 0.1], [0.2, 0.3, 0.8], [0.85, 0.85, 0.8]])
DIAGONAL = np.full(3, 1.0 / np.sqrt(3.0))


def _shaded_surfaces(n: int = 20000, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Log colours of three surfaces, each under shading from 0.05 to 1, with 3 % noise."""
    rng = np.random.default_rng(seed)
    which = rng.integers(0, ALBEDOS.shape[0], n)
    rgb = ALBEDOS[which] * rng.uniform(0.05, 1.0, n)[:, None] * np.exp(rng.normal(0, 0.03, (n, 3)))
    return np.log(np.clip(rgb, 1 / 255, 1)), which


def test_rad_finds_one_ridge_per_surface_along_the_shading_direction():
    colours, which = _shaded_surfaces()
    shades = colour_shades(colours, detector="rad", creaseness=1.0, sigma=1.0)
    assert shades.n_ridges == 3
    # each ridge holds exactly one surface's colours (Eq. 3.3)
    for r in range(3):
        assert np.unique(which[shades.ridge == r]).size == 1
    cosine = np.abs(shades.tangent @ DIAGONAL)
    assert np.median(cosine) > 0.99 and np.mean(cosine > 0.9) > 0.95
    # pi(p) is the foot of the perpendicular on the tangent line
    offset = ((colours - shades.projection) * shades.tangent).sum(axis=1)
    np.testing.assert_allclose(offset, 0.0, atol=1e-9)
    assert np.median(np.linalg.norm(colours - shades.projection, axis=1)) < 2 * shades.bin_width


def test_the_hessian_detector_splits_the_same_surfaces_into_many_ridges():
    # the round-1 detector, kept for the ablation: why RAD was needed
    colours, _ = _shaded_surfaces()
    assert colour_shades(colours, detector="hessian").n_ridges > 10


def test_rad_prunes_ridges_of_a_negligible_share_of_the_colours():
    colours, _ = _shaded_surfaces(seed=1)
    rng = np.random.default_rng(2)
    speck = np.log([0.1, 0.9, 0.1]) + rng.normal(0, 0.02, (30, 3))  # 0.15 % of the pixels
    shades = colour_shades(np.vstack([colours, speck]), min_share=0.005)
    assert shades.n_ridges == 3
    kept = colour_shades(np.vstack([colours, speck]), min_share=0.0)
    assert kept.n_ridges >= 4


def test_unknown_ridge_detector_is_refused():
    with pytest.raises(ValueError, match="detector"):
        colour_shades(np.zeros((5, 3)), detector="watershed")
    with pytest.raises(SpectrinsicError, match="ridge_detector"):
        NamesAndShades(ridge_detector="watershed").labelling(np.ones((8, 8, 3)))


def test_a_cast_shadow_is_case_c_and_a_paint_edge_case_a():
    """Two paints side by side, each shaded from 1 to 0.4 across it, a shadow (x 0.5) over the
    lower half: with RAD ridges the MRF weighs steps across the shadow's edge gamma (same ridge,
    parallel) and steps across the paint edge alpha (different ridges)."""
    rng = np.random.default_rng(3)
    h, w = 60, 80
    yy, xx = np.mgrid[0:h, 0:w]
    albedo = np.where((xx < w // 2)[..., None], [0.8, 0.25, 0.15], [0.2, 0.35, 0.8])
    shading = (1.0 - 0.6 * (xx % (w // 2)) / (w // 2)) * np.where(yy >= h // 2, 0.5, 1.0)
    image = albedo * shading[..., None] * np.exp(rng.normal(0, 0.01, (h, w, 3)))
    method = NamesAndShades(ridge_detector="rad", creaseness=1.0, sigma=1.0)
    stages = method.labelling(image)
    edges, _ = grid_edges(stages.mask)
    i, j = edges[:, 0], edges[:, 1]
    y, x = np.divmod(np.arange(h * w), w)
    across_shadow = (y[i] == h // 2 - 1) & (y[j] == h // 2)
    across_paint = (x[i] == w // 2 - 1) & (x[j] == w // 2)
    assert np.mean(stages.weights[across_shadow] == method.gamma) > 0.9
    alpha = method.gamma / method.gamma_over_alpha
    assert np.mean(stages.weights[across_paint] == alpha) > 0.9


def _bridged_surfaces(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Log colours of two paints (each shaded from 0.05 to 1, 3 % noise) and 10 % of pixels on
    their shared edge: linear mixtures of the two under one shading (0.5), a crest across the
    grey diagonal that bridges the two ridges."""
    rng = np.random.default_rng(seed)
    paints = np.array([[0.7, 0.35, 0.2], [0.35, 0.4, 0.5]])
    n = 20000
    which = rng.integers(0, 2, n)
    mixed = rng.random(n) < 0.1
    t = np.where(mixed, rng.random(n), which.astype(float))
    albedo = paints[0] * (1.0 - t)[:, None] + paints[1] * t[:, None]
    shading = np.where(mixed, 0.5, rng.uniform(0.05, 1.0, n))
    rgb = albedo * shading[:, None] * np.exp(rng.normal(0, 0.03, (n, 3)))
    return np.log(np.clip(rgb, 1 / 255, 1)), which, ~mixed


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_cutting_crests_across_the_diagonal_separates_bridged_surfaces(seed):
    colours, which, pure = _bridged_surfaces(seed)
    joined = colour_shades(colours, creaseness=1.5, sigma=2.0)
    assert joined.n_ridges == 1  # threshold-and-thin follows the bridge
    cut = colour_shades(colours, creaseness=1.5, sigma=2.0, max_axis_angle=60.0)
    # no ridge holds pixels of both paints; the pieces of one paint's ridge that the cut
    # leaves apart (where the ridge bends) are few, the largest holds most of its pixels
    for r in range(cut.n_ridges):
        assert np.unique(which[pure & (cut.ridge == r)]).size <= 1
    for paint in (0, 1):
        _, counts = np.unique(cut.ridge[pure & (which == paint)], return_counts=True)
        assert counts.size <= 3 and counts.max() > 0.6 * counts.sum()


def test_principal_axes_do_not_depend_on_how_lapack_breaks_a_tie():
    """A tie between the two largest eigenvalues leaves eigh free to return any vector of the
    tied plane (OPENBLAS_CORETYPE changed it, and with it a grey checker's regions); the axis is
    then the grey diagonal projected onto that plane, whatever eigh returned."""
    from spectrinsic.decompose.methods.ridges import principal_axes

    diagonal = np.ones(3) / np.sqrt(3.0)
    rotation = np.linalg.qr(np.array([[1.0, 2.0, 0.5], [0.3, -1.0, 2.0], [2.0, 0.1, -0.7]]))[0]
    tied = np.diag([1.0, 2.0, 2.0])
    matrices = np.stack([tied, rotation @ tied @ rotation.T, np.diag([3.0, 1.0, 0.5])])
    axes = principal_axes(matrices, diagonal)
    np.testing.assert_allclose(axes[0], [0.0, 1.0, 1.0] / np.sqrt(2.0), atol=1e-12)
    # the tied plane turned: the projection of the diagonal onto the turned plane
    plane = rotation[:, 1:]
    expected = plane @ (plane.T @ diagonal)
    np.testing.assert_allclose(axes[1], expected / np.linalg.norm(expected), atol=1e-9)
    # no tie: eigh's own axis, signed along the diagonal
    np.testing.assert_allclose(axes[2], [1.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(axes, axis=1), 1.0, atol=1e-12)
