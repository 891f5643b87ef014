"""Generated sets look like the world by default (issue 31): a share of glossy, metallic and
textured surfaces, recorded in the config's source; 0 everywhere gives the matte world and its
old config hash. The library layout stays the thesis' (matte)."""

from __future__ import annotations

import json

from spectrinsic.cli import build_parser
from spectrinsic.cli.dataset_source import source_from_args
from spectrinsic.pipeline.presets import DatasetConfig
from spectrinsic.pipeline.source_plan import _generator_options, generator_source
from spectrinsic.scenes.generators import generate
from spectrinsic.scenes.generators.world_defaults import (
    GLOSSY_FRACTION,
    METALLIC_FRACTION,
    TEXTURE_FRACTION,
)


def _source(*extra: str) -> str:
    args = build_parser().parse_args(["dataset", "--generator", "rooms", "--out", "x", *extra])
    source = source_from_args(args)
    assert source is not None
    return source


def test_the_default_generated_world_is_glossy_metallic_and_textured():
    spec = json.loads(_source())
    assert spec["gloss"]["glossy"] == GLOSSY_FRACTION == 0.25
    assert spec["gloss"]["metallic"] == METALLIC_FRACTION == 0.10
    assert spec["texture_fraction"] == TEXTURE_FRACTION == 0.20


def test_zero_fractions_give_the_matte_world_and_its_old_source():
    matte = _source("--glossy", "0", "--metallic", "0", "--texture-fraction", "0")
    assert matte == generator_source("rooms", 20)  # the python API's matte default, old hash
    assert "gloss" not in json.loads(matte) and "texture_fraction" not in json.loads(matte)


def test_default_scenes_hold_glossy_and_metal_materials():
    """Over 8 generated scenes the drawn material kinds come near the default shares."""
    spec = json.loads(_source())
    spec["generator"] = "objects-on-ground"
    config = DatasetConfig.from_settings("t", width=16, height=16, spp=1, max_depth=2)
    options = _generator_options(spec, config, None)
    kinds = [
        m.kind
        for i in range(8)
        for m in generate(
            "objects-on-ground", root_seed=0, index=i, view=0, options=options
        ).materials
    ]
    share = {k: kinds.count(k) / len(kinds) for k in ("plastic", "conductor")}
    assert 0.1 <= share["plastic"] <= 0.45 and 0.02 <= share["conductor"] <= 0.25, share
