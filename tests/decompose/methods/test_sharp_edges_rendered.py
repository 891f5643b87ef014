"""Issue 48 on a render with exact ground truth: a black-and-white checker under a soft shadow.

A 2 x 2 plane textured with a 4 x 4 checker of spectrally flat 0.8 and 0.05 reflectances, seen
head-on (40 x 40 pixels, squares about 10 pixels wide), lit by a 1 x 1 area light at 45
degrees and a weak overhead directional light; a card outside the view casts a shadow over
the right part of the plane whose penumbra is several pixels wide (the area light's size).
Independent values: the reflectance and shading layers spectrinsic renders (exact), never the
decomposer's output. ``BEFORE`` (names-and-shades before issue 48) loses the checker: its
reflectance is one grey.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.decompose.methods.names_shades import NamesAndShades
from spectrinsic.gt_export.layers import compute_ground_truth
from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene
from spectrinsic.scenes.textures import Texture
from spectrinsic.scenes.validate import validate_scene

pytestmark = pytest.mark.filterwarnings("ignore::FutureWarning")  # gco's numpy aliases

BEFORE = NamesAndShades(
    sharp_edges="none", collapse_guard=False, blurred_steps=False, fine_detail=False
)
WHITE, BLACK = 0.8, 0.05


def _scene() -> Scene:
    mats = (
        Material("white", f"flat:{WHITE}"),
        Material("black", f"flat:{BLACK}"),
        Material("card", "flat:0.5"),
    )
    chk = np.add.outer(np.arange(4), np.arange(4)) % 2 == 0
    weights = np.stack([chk, ~chk], axis=2).astype(np.float64)
    quad = np.array([[0, 1, 2], [0, 2, 3]])
    plane = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0.0]])
    card = np.array([[1.0, -3, 1.0], [3, -3, 1.0], [3, 3, 1.0], [1.0, 3, 1.0]])
    return Scene(
        "checker_shadow",
        (
            Mesh(
                "plane", plane, quad, np.zeros(2, np.int64), 0, Texture("checker", (0, 1), weights)
            ),
            Mesh("card", card, quad, np.full(2, 2, np.int64), 1),
        ),
        mats,
        (
            Light("area", "cie:D65", 20.0, (3.0, 0.0, 3.0), (-0.7071, 0.0, -0.7071), (1.0, 1.0)),
            Light("directional", "cie:D65", 0.3, direction=(0.0, 0.0, -1.0)),
        ),
        Camera((0, 0, 3), (0, 0, 0), (0, 1, 0), 30.0, 40, 40),
    )


@pytest.fixture(scope="module")
def rendered() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Image, grey reflectance and grey shading of the scene (64 spp, direct light)."""
    scene = _scene()
    validate_scene(scene)
    settings = RenderSettings(64, max_depth=2, modes=("bands31",), per_light=True)
    layers = compute_ground_truth(scene, render_scene(scene, settings, seed=1)).layers
    image = np.asarray(layers["image"].data, np.float64)
    return image, layers["reflectance"].data.mean(axis=2), layers["shading"].data.mean(axis=2)


def test_a_soft_shadow_across_a_rendered_checker_stays_in_the_shading(rendered) -> None:
    image, refl, shade = rendered
    bright = np.median(shade[shade > np.median(shade)])
    lit, shadow = shade > 0.8 * bright, shade < 1.3 * np.percentile(shade, 10)
    white, black = refl > 0.5, refl < 0.1
    truth = np.median(shade[shadow]) / np.median(shade[lit])
    assert 0.2 < truth < 0.5 and (white & shadow).sum() > 50  # the shadow crosses white squares
    after = NamesAndShades()(image)
    r, s = after.reflectance.mean(axis=2), after.shading.mean(axis=2)
    # the shadow is not in the reflectance: white in and out of it within 10 %
    assert abs(np.log(np.median(r[white & shadow]) / np.median(r[white & lit]))) < np.log(1.1)
    # it is in the shading, within 15 % of the rendered shading's ratio
    assert abs(np.log(np.median(s[shadow]) / np.median(s[lit]) / truth)) < np.log(1.15)
    # the checker is in the reflectance (16 rendered; at least 10 here)
    assert np.median(r[white]) / np.median(r[black]) > 10.0
    before = BEFORE(image).reflectance.mean(axis=2)
    assert np.median(before[white]) / np.median(before[black]) < 2.0  # before: lost
