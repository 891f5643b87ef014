"""The glossy options of a generated dataset's source: recorded only when asked for, read back
into the generator's options."""

from __future__ import annotations

import json

from spectrinsic.pipeline.presets import get_preset
from spectrinsic.pipeline.source_plan import _generator_options, generator_source
from spectrinsic.scenes.generators import GlossDistribution


def test_matte_sources_are_unchanged_and_gloss_round_trips():
    matte = generator_source("rooms", 2)
    assert "gloss" not in json.loads(matte)
    assert matte == generator_source("rooms", 2, gloss=GlossDistribution())
    shiny = generator_source("rooms", 2, gloss=GlossDistribution(0.3, 0.1, (0.0, 0.5)))
    assert json.loads(shiny)["gloss"] == {
        "glossy": 0.3,
        "metallic": 0.1,
        "roughness_range": [0.0, 0.5],
    }
    options = _generator_options(json.loads(shiny), get_preset("preview"), None)
    assert options.gloss == GlossDistribution(0.3, 0.1, (0.0, 0.5))
    assert (
        _generator_options(json.loads(matte), get_preset("preview"), None).gloss
        == GlossDistribution()
    )
