"""Layers where no light arrives are exactly 0 (issue 36, cause 13).

The only light of the scene, a spot above a card on a floor, points up, away from everything:
no path reaches a surface, so the image and the raw shading are 0 at every pixel. The denoiser
must not invent light there (its output is masked by the raw white-surface radiance of every
batch), and the unit-luminance ``illuminant``, which divides by the luminance, is documented
as 0 where none arrives.
"""

from __future__ import annotations

import numpy as np

from spectrinsic.gt_export.layers import compute_ground_truth
from spectrinsic.render import RenderSettings, render_batches
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene
from tests.conftest import quad


def _dark_scene() -> Scene:
    floor_v, floor_f = quad((-2, -2, 0), (4, 0, 0), (0, 4, 0))
    card_v, card_f = quad((-0.5, -0.5, 0.5), (1, 0, 0), (0, 1, 0))
    return Scene(
        name="dark",
        meshes=(
            Mesh("floor", floor_v, floor_f, np.zeros(2, np.int64), object_id=0),
            Mesh("card", card_v, card_f, np.ones(2, np.int64), object_id=1),
        ),
        materials=(Material("grey", "flat:0.5"), Material("red", "flat:0.8")),
        lights=(
            Light("spot", "cie:D65", 5.0, position=(0.0, 0.0, 2.0), direction=(0.0, 0.0, 1.0)),
        ),
        camera=Camera(
            origin=(0.0, 0.3, 4.0),
            target=(0, 0, 0),
            up=(0, 0, 1),
            fov_deg=50.0,
            width=24,
            height=24,
        ),
    )


def test_a_light_pointing_away_leaves_denoised_shading_and_illuminant_exactly_zero():
    scene = _dark_scene()
    result = render_batches(scene, RenderSettings(4, batches=2, modes=("rgb3",)), seed=3)
    gt = compute_ground_truth(scene, result, denoise=True)
    # the raw passes: nothing arrives anywhere (what makes the rest a test of the masking)
    assert not np.any(gt.layers["image"].data)
    assert not np.any(gt.layers["shading_raw"].data)
    for name in ("shading", "illuminant", "shading_grey", "image_denoised"):
        data = gt.layers[name].data
        assert not np.any(data), (
            f"{name}: {np.count_nonzero(data)} non-zero values, max {data.max()}"
        )
