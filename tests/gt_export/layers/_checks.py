"""A check every computed ground truth passes, shared by the layer tests of rendered rooms.

A helper module, not a conftest: its function takes the ground truth, and
tests/test_test_layout.py checks only ``test_*.py`` files.
"""

from __future__ import annotations

import numpy as np

from spectrinsic.gt_export.layers import GroundTruth

__all__ = ["LIGHT_LAYERS", "assert_finite_and_light_nonnegative"]

#: Layers that are light (a shading, the illuminant, a light's share): never negative.
LIGHT_LAYERS = (
    "shading",
    "shading_raw",
    "shading_camera",
    "shading_grey",
    "illuminant",
    "light_share",
)


def assert_finite_and_light_nonnegative(gt: GroundTruth) -> None:
    """Every layer of *gt* finite, and every one of :data:`LIGHT_LAYERS` (in any colour space
    or camera: ``shading/camera:...``) ≥ 0."""
    for name, layer in gt.layers.items():
        assert np.isfinite(layer.data).all(), name
        if name.split("/")[0] in LIGHT_LAYERS:
            assert (layer.data >= 0).all(), name
