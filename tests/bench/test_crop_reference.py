"""The crop reference of ``make bench`` (issue 20, part 3): a film crop renders the full
image's pixels, and the error summaries count what they say."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.bench import crop_reference as cr
from spectrinsic.errors import SceneError
from spectrinsic.render.algebra.modes import channel_values, get_mode
from spectrinsic.render.band_path.traversal import render_traversal
from spectrinsic.render.base.plugins import hdr_film
from spectrinsic.render.settings import PassRequest
from spectrinsic.spectra import get_sensors

CROP = (5, 3, 7, 6)  # x, y, width, height: not square, not centred, odd sizes


def test_a_film_crop_renders_the_window_of_the_full_image(make_room):
    """Same scene, the window alone: its first-hit maps are the full image's there, and its
    31-band image agrees with the full image's window within the Monte Carlo error."""
    scene = make_room(size=16)
    values = [channel_values(scene, get_sensors(get_mode("bands31").sensors))]
    (full,), full_aovs, _, _ = render_traversal(scene, values, PassRequest(256, 1), aovs=True)
    (part,), part_aovs, _, _ = render_traversal(
        scene, values, PassRequest(256, 2), aovs=True, crop=CROP
    )
    x, y, w, h = CROP
    assert part.transport.shape[1:3] == (h, w)
    window = full.image()[y : y + h, x : x + w]
    np.testing.assert_array_equal(
        part_aovs["object_id"], full_aovs["object_id"][y : y + h, x : x + w]
    )
    depth = full_aovs["depth"][y : y + h, x : x + w]  # each a mean over its pixel's samples
    assert np.median(np.abs(part_aovs["depth"] - depth) / depth) < 0.01
    # mean over the window (256 spp per pixel, 42 pixels; spread 0.8 % over seeds): within 3 %
    assert part.image().mean() == pytest.approx(window.mean(), rel=0.03)
    with pytest.raises(SceneError, match="inside 16x16"):
        hdr_film(16, 16, (10, 0, 8, 8))


def test_edge_pixels_are_boundaries_and_shared_pixels():
    ids = np.zeros((5, 6), np.int32)
    ids[:, 3:] = 1
    coverage = np.ones((5, 6, 1))
    coverage[0, 0] = 0.5  # a pixel two surfaces share
    edges = cr.edge_pixels(ids, coverage)
    assert edges[:, 2:4].all() and not edges[1:, :2].any() and not edges[:, 5].any()
    assert edges[0, 0]


def test_shading_errors_summarise_the_relative_error_per_pixel():
    ref = np.ones((4, 4, 3))
    est = ref.copy()
    est[0, 0] *= 1.1  # 10 % error on one edge pixel, exact elsewhere
    edges = np.zeros((4, 4), bool)
    edges[0] = True
    out = cr.shading_errors(est, ref, np.ones((4, 4), bool), edges)
    assert out["median"] == 0 and out["pixels"] == 16
    assert out["edges"]["pixels"] == 4 and out["edges"]["p95"] == pytest.approx(
        0.085, rel=1e-6
    )  # 0.85 of the way
    assert out["interior"]["median"] == 0 and out["interior"]["pixels"] == 12
    assert out["rms"] == pytest.approx(np.sqrt(0.01 / 16), rel=1e-6)


def test_the_references_own_noise_is_removed_in_quadrature():
    ref = np.ones((2, 2, 3))
    est = ref * np.array([1.05, 1.05, 1.05])[None, None]  # 5 % everywhere
    se = np.full((2, 2), 0.03)
    out = cr.shading_errors(est, ref, np.ones((2, 2), bool), np.zeros((2, 2), bool), se)
    assert out["edges"]["pixels"] == 0 and out["edges"]["median"] is None
    assert out["median"] == pytest.approx(0.05, rel=1e-6)
    assert out["corrected"]["median"] == pytest.approx(0.04, rel=1e-6)  # sqrt(5² − 3²)
    assert out["corrected"]["rms"] == pytest.approx(0.04, rel=1e-6)
