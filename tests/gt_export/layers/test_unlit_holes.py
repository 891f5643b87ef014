"""Issue 47: the denoised shading keeps 0 where no light arrives (a shadow: the pixel and most
of its neighbours saw no light), but fills a sampling hole of a lit region (one pixel whose
few samples all missed the light), which left black specks in preview ``image_denoised``."""

from __future__ import annotations

import numpy as np

from spectrinsic.gt_export.layers.irradiance import WhiteRadiance, unlit_masked


def _radiance(bands):
    h, w, k = bands.shape
    return WhiteRadiance("rgb3", bands, np.ones_like(bands), np.ones((h, w), bool), np.eye(3, k))


def test_a_hole_in_a_lit_region_is_filled_and_a_shadow_stays_black():
    raw = np.ones((8, 8, 3))
    raw[2, 2] = 0.0  # a sampling hole: its 8 neighbours are lit
    raw[5:8, 5:8] = 0.0  # a shadow in the corner: its centre (6, 6) has no lit neighbour
    estimate = _radiance(np.full((8, 8, 3), 0.7))  # the denoiser's smooth estimate
    out = unlit_masked(estimate, _radiance(raw)).bands
    assert np.all(out[2, 2] == 0.7)
    assert np.all(out[6:8, 6:8] == 0.0)
    # a batch that saw light at a pixel makes it lit, whatever its neighbours
    batch = np.zeros((8, 8, 3))
    batch[7, 7] = 1.0
    assert np.all(unlit_masked(estimate, _radiance(raw), (batch,)).bands[7, 7] == 0.7)
