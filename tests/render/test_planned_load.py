"""The counts a library dataset is sized by before its scenes exist (``PLANNED_LOAD``, the
render-size check of ``spectrinsic dataset``, :mod:`spectrinsic.render.budget`) are at least those of every library scene."""

from __future__ import annotations

import dataclasses

from spectrinsic.render.budget import PLANNED_LOAD, RenderLoad
from spectrinsic.scenes import library


def test_every_library_scene_fits_the_planned_load():
    """Every library scene (and its glossy twin), first view, under the two-light condition:
    each of its counts is at most the planned one."""
    names = library.scene_names() + library.scene_names("glossy")
    loads = [
        RenderLoad.of_scene(
            library.build(name, condition="two-colour-a", seed=0, width=8, height=8)
        )
        for name in names
    ]
    assert max(load.n_lights for load in loads) == 2
    for field in dataclasses.fields(RenderLoad):
        most = max(getattr(load, field.name) for load in loads)
        assert most <= getattr(PLANNED_LOAD, field.name), (field.name, most)
