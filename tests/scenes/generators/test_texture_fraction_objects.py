"""``--texture-fraction`` applies to ``objects-on-ground`` too: it draws mostly library objects,
which kept their own colours, so a fraction of 1 gave no texture at all."""

from __future__ import annotations

import json

from spectrinsic.pipeline.presets import get_preset
from spectrinsic.pipeline.source_plan import _generator_options, generator_source
from spectrinsic.scenes.generators import generate


def _textured_objects(fraction: float) -> list[tuple[int, int]]:
    source = generator_source("objects-on-ground", 6, texture_fraction=fraction)
    config = get_preset("preview", seed=0).with_options(source=source)
    options = _generator_options(json.loads(source), config, None)
    counts = []
    for index in range(6):
        scene = generate("objects-on-ground", root_seed=0, index=index, view=0, options=options)
        objects = [m for m in scene.meshes if m.name != "ground"]
        counts.append((sum(m.texture is not None for m in objects), len(objects)))
    return counts


def test_a_texture_fraction_of_one_textures_every_object_on_the_ground():
    assert all(textured == n for textured, n in _textured_objects(1.0))


def test_no_texture_fraction_textures_no_object():
    assert all(textured == 0 for textured, _ in _textured_objects(0.0))
