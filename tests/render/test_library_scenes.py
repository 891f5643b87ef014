"""Every library scene renders in every mode.

Tiny images and one sample per pixel: this checks that each scene translates, loads and
renders in each mode with finite, non-negative-luminance output and light where the camera
looks, not image quality.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.render.algebra.modes import RENDER_MODES
from spectrinsic.scenes import library

#: Small enough to keep the whole library under a minute on 2 cores.
SIZE, SPP = 12, 1


@pytest.mark.parametrize("name", library.scene_names())
def test_library_scene_renders_in_every_mode(name):
    scene = library.build(
        name,
        view=library.n_views(name) - 1,
        condition="two-colour-b",
        seed=0,
        width=SIZE,
        height=SIZE,
    )
    result = render_scene(
        scene, RenderSettings(SPP, modes=tuple(RENDER_MODES), max_depth=4, aovs=True), seed=1
    )
    assert set(result.images) == set(RENDER_MODES)
    for mode, xyz in result.images.items():
        assert xyz.shape == (SIZE, SIZE, 3), mode
        assert np.all(np.isfinite(xyz)), mode
        assert xyz[..., 1].sum() > 0, f"{name}: {mode} image is black"
    assert result.aovs["mask"].any(), f"{name}: the camera sees nothing"
