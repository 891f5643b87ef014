"""``render --ground-truth`` honours ``--modes``, ``--max-depth`` and ``--integrator``: the
one-sample dataset recorded depth 6 and all four modes whatever was asked. The config handed
to the dataset builder (the same call as ``spectrinsic dataset``) is checked here, without
rendering; ``tests/pipeline`` proves that a config's modes and depth are what a sample records.
"""

from __future__ import annotations

import pytest

from spectrinsic.cli import dataset as cli_dataset
from spectrinsic.cli import main


@pytest.fixture
def handed(monkeypatch):
    """The config ``render --ground-truth`` hands to the builder (nothing is rendered)."""
    seen = {}
    monkeypatch.setattr(cli_dataset, "preflight", lambda out, config, **_: None)

    def build(out, config, **_):
        seen["config"] = config
        return 0

    monkeypatch.setattr(cli_dataset, "build", build)
    return seen


def test_modes_depth_and_integrator_reach_the_ground_truth_sample(tmp_path, handed):
    argv = ["-q", "render", "obj-box", "--ground-truth", "--out", str(tmp_path / "o")]
    assert main([*argv, "--modes", "rgb3", "--max-depth", "3", "--integrator", "passes"]) == 0
    render = handed["config"].render
    assert render.modes == ("rgb3",) and render.max_depth == 3 and render.integrator == "passes"


def test_without_them_the_preset_decides(tmp_path, handed):
    from spectrinsic.pipeline.presets import get_preset

    assert main(["-q", "render", "obj-box", "--ground-truth", "--out", str(tmp_path / "o")]) == 0
    preset = get_preset("default", seed=0).render
    render = handed["config"].render
    assert (render.modes, render.max_depth) == (preset.modes, preset.max_depth)
