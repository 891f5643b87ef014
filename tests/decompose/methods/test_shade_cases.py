"""Issue 33's structural changes to names-and-shades, each on a synthetic image built to need it.

* A cast shadow over one paint: the MRF keeps a wide shadow as a label of its own when its area
  outweighs its boundary (``(1 - mu) gamma P < mu A``, as on the MIT raccoon); every edge of
  the shadow's boundary is Case C (one ridge, step along it), so the regions of uniform
  reflectance (sec. 3.4) must join it to the lit paint, and the reflectance must be one.
* RAD's flooding step: a thin, dense surface beside a second one whose ridge bends near it;
  each colour must take the ridge whose density it lies under (the flooded domain), not the
  one that happens to be nearest.
* A faint print on white paper: darker, slightly purple 2-pixel lines whose log colours lie on
  the paper's ridge along its direction (Case C, as paper1's print on the MIT set); the names
  call the print purple and the paper white or grey, which a white light's shading cannot do,
  so the print must keep its own reflectance.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spectrinsic.decompose.methods.names_shades import NamesAndShades
from spectrinsic.decompose.methods.ridges import colour_shades
from spectrinsic.decompose.methods.shade_cases import CASE_A, CASE_C, merge_shading_boundaries

pytestmark = pytest.mark.filterwarnings("ignore::FutureWarning")  # gco's numpy aliases


def _white_paint_with_cast_shadow(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A white paint shaded from 1 to 0.15 across it, a cast shadow (x 0.3) over its lower
    half, and a blue paint beside it; 1 % noise. Returns image, shadow mask, blue mask."""
    rng = np.random.default_rng(seed)
    h, w = 64, 96
    yy, xx = np.mgrid[0:h, 0:w]
    blue = xx >= 72
    albedo = np.where(blue[..., None], [0.2, 0.3, 0.75], [0.85, 0.85, 0.8])
    shadow = (yy >= h // 2) & ~blue
    shading = np.where(
        blue, 1.0 - 0.5 * (xx - 72) / 24, (1.0 - 0.85 * xx / 72) * np.where(shadow, 0.3, 1.0)
    )
    image = albedo * shading[..., None] * np.exp(rng.normal(0, 0.01, (h, w, 3)))
    return image, shadow, blue


@pytest.mark.parametrize("seed", [0, 1])
def test_a_cast_shadow_over_one_paint_is_one_reflectance_region(seed):
    image, shadow, blue = _white_paint_with_cast_shadow(seed)
    method = NamesAndShades()
    stages = method.labelling(image)
    in_shadow, on_blue = shadow[stages.mask], blue[stages.mask]
    # The MRF's output as on the raccoon: the lit paint one label, its shadow another.
    labels = stages.labels.copy()
    lit = int(np.bincount(labels[~in_shadow & ~on_blue]).argmax())
    labels[~on_blue] = lit
    labels[in_shadow] = (lit + 1) % stages.candidates.size
    kept_shadow = dataclasses.replace(stages, labels=labels)
    grey = method.reflectance(kept_shadow).reflectance.mean(axis=2)
    lit_paint = ~shadow & ~blue
    # one region: the shadow's reflectance is the lit paint's (the image's ratio there is 0.3)
    assert grey[shadow].mean() / grey[lit_paint].mean() == pytest.approx(1.0, abs=0.05)
    assert grey[shadow].std() / grey[shadow].mean() < 0.02
    # the paint edge stays: the blue paint is darker in reflectance (its grey level 0.42
    # against the white's 0.83 at equal shading along the edge)
    assert grey[blue].mean() / grey[lit_paint].mean() != pytest.approx(1.0, abs=0.2)
    thesis_regions = dataclasses.replace(method, merge_shading=False).reflectance(kept_shadow)
    shadowed = thesis_regions.reflectance.mean(axis=2)
    assert shadowed[shadow].mean() / shadowed[lit_paint].mean() < 0.5


def test_regions_join_only_across_boundaries_that_are_mostly_case_c():
    regions = np.array([[1, 1, 2, 2, 3, 3]])
    edges = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5]])
    cases = np.array([CASE_A, CASE_C, CASE_A, CASE_A, CASE_C])
    merged = merge_shading_boundaries(regions, edges, cases == CASE_C)
    assert merged.tolist() == [[1, 1, 1, 1, 2, 2]]
    # a boundary of two edges, one Case C: not a majority, the regions stay apart
    regions = np.array([[1, 2], [1, 2]])
    edges = np.array([[0, 1], [2, 3], [0, 2], [1, 3]])
    parallel = np.array([True, False, True, True])
    assert merge_shading_boundaries(regions, edges, parallel).tolist() == [[1, 2], [1, 2]]


def _thin_and_wide_surfaces(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Log colours of two surfaces under shading: A grey, shaded over a wide range (log -5 to
    0); B coloured, mostly bright (log -1.5 to 0) with 6 % of its pixels in a dark tail; 3 %
    noise. Returns colours and surface index."""
    rng = np.random.default_rng(seed)
    n = 30000
    a = rng.uniform(-5.0, 0.0, n)[:, None] + rng.normal(0, 0.03, (n, 3))
    tail = rng.random(n) < 0.06
    s_b = np.where(tail, rng.uniform(-5.0, -1.5, n), rng.uniform(-1.5, 0.0, n))
    b = s_b[:, None] + np.array([0.5, -0.25, -0.25]) + rng.normal(0, 0.03, (n, 3))
    return np.vstack([a, b]), np.repeat([0, 1], n)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_flooding_gives_each_colour_the_ridge_whose_density_it_lies_under(seed):
    colours, which = _thin_and_wide_surfaces(seed)

    def misplaced_share_of_a(flooding: bool) -> float:
        shades = colour_shades(
            colours, sigma=2.0, creaseness=1.5, max_axis_angle=45.0, flooding=flooding
        )
        owner = np.array(
            [
                np.bincount(which[shades.ridge == r], minlength=2).argmax()
                for r in range(shades.n_ridges)
            ]
        )
        return float(np.mean(owner[shades.ridge[which == 0]] != 0))

    assert misplaced_share_of_a(True) < 0.01
    assert misplaced_share_of_a(False) > 0.1  # nearest ridge (Eq. 3.3): a fifth of A on B's


def _paper_with_faint_print(seed: int) -> tuple[np.ndarray, np.ndarray, float]:
    """White paper (albedo 0.85) with a grid of 2-pixel lines of a faint purple-grey ink
    (albedo x (0.63, 0.56, 0.63), paper1's print over its paper on the MIT set), under smooth
    shading from 1 to about 0.4; 1 % noise. Returns image, print mask, true grey ratio."""
    rng = np.random.default_rng(seed)
    h, w = 80, 96
    yy, xx = np.mgrid[0:h, 0:w]
    ink = np.array([0.63, 0.56, 0.63])
    lines = np.zeros((h, w), bool)
    for r in range(10, h - 10, 12):
        lines[r : r + 2, 8 : w - 8] = True
    for c in range(14, w - 10, 20):
        lines[8 : h - 8, c : c + 2] = True
    albedo = 0.85 * np.where(lines[..., None], ink, 1.0)
    shading = 0.35 + 0.65 * np.exp(-(((xx - 20) / 70.0) ** 2 + ((yy - 15) / 60.0) ** 2))
    image = albedo * shading[..., None] * np.exp(rng.normal(0, 0.01, (h, w, 3)))
    return image, lines, float(ink.mean())


@pytest.mark.parametrize("seed", [0, 1])
def test_a_faint_print_on_white_paper_keeps_its_own_reflectance(seed):
    image, lines, ratio = _paper_with_faint_print(seed)
    method = NamesAndShades()
    stages = method.labelling(image)
    grey = method.reflectance(stages).reflectance.mean(axis=2)
    # the print's reflectance over the paper's is the ink's (0.607; within 10 %, the grey-world
    # step divides each channel apart), not 1 or 0.8 (print erased in all or part)
    assert grey[lines].mean() / grey[~lines].mean() == pytest.approx(ratio, rel=0.1)
    # and the paper stays nearly one reflectance under its shading: its cells between the
    # lines are regions of their own now, tied through the print (std 3.7-4.0 %), against the
    # image's own spread there (the shading, std 22 %)
    assert grey[~lines].std() / grey[~lines].mean() < 0.05
    shaded = image.mean(axis=2)[~lines]
    assert shaded.std() / shaded.mean() > 0.15
    # the print is named chromatic: its edges to the paper are Case A with the change
    pale_print = dataclasses.replace(method, pale_vs_chromatic=False).labelling(image)
    assert np.count_nonzero(pale_print.cases == CASE_A) < np.count_nonzero(stages.cases == CASE_A)
