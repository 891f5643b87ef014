"""A tiny trainable dataset: the synthetic samples of the gt_export tests (no rendering), four
scenes so every split holds one."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from tests.gt_export.conftest import make_result, make_scene

#: (scene name, light spectra) of the tiny set's samples, one scene each.
TINY_SCENES = (
    ("alpha", ("planck:2800K",)),
    ("beta", ("cie:D65",)),
    ("gamma", ("planck:2800K", "cie:FL11")),
    ("delta", ("cie:FL11",)),
    ("eps", ("cie:D65", "planck:4000K")),
)


@pytest.fixture(scope="session")
def tiny_set(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Five synthetic 12x16 samples (image, reflectance, shading, mask) with manifest."""
    from spectrinsic.gt_export import export_sample, write_dataset_card, write_manifest

    root = tmp_path_factory.mktemp("tiny_set")
    config = {"preset": "test", "width": 16, "height": 12, "spp": 1, "seed": 7}
    for i, (name, lights) in enumerate(TINY_SCENES):
        scene = replace(make_scene(lights), name=name)
        export_sample(
            root, scene, make_result(scene), sample_id=f"{name}__v0", config=config, seed=i
        )
    write_manifest(root, config)
    write_dataset_card(root, config)
    return root
