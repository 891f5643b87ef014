"""The view rule's rendered-light check (issue 47): a dark frame around one bright patch is
refused and the camera re-drawn; a frame lit across is kept."""

from __future__ import annotations

import numpy as np

from spectrinsic.scenes.generators import GeneratorOptions, generate
from spectrinsic.scenes.generators.view_rule import MIN_FRAME_MEDIAN, judge_frame


def _dark_frame_with_a_patch():
    """The measured failure's shape: a frame at 0.5 % of a bright 6 x 6 patch (3.5 % of it)."""
    y = np.full((32, 32), 0.005)
    y[10:16, 20:26] = 1.0
    return y


def _room_frame():
    """A lit room: a floor-to-ceiling gradient of 10:1 plus a lamp-lit spot 5x brighter."""
    y = np.repeat(np.linspace(0.1, 1.0, 32)[:, None], 32, axis=1)
    y[2:6, 2:6] = 5.0
    return y


def test_a_dark_frame_around_one_bright_patch_fails():
    j = judge_frame(_dark_frame_with_a_patch())
    assert j.median_share == 0.005
    assert not j.ok and "median" in j.reasons[0]


def test_a_frame_lit_across_passes():
    j = judge_frame(_room_frame())
    assert j.ok and j.median_share > 5 * MIN_FRAME_MEDIAN


def test_a_black_or_broken_frame_fails():
    assert not judge_frame(np.zeros((8, 8))).ok
    assert not judge_frame(np.full((8, 8), np.nan)).ok


def test_the_rule_is_independent_of_the_exposure():
    y = _room_frame()
    assert judge_frame(y).median_share == judge_frame(1e4 * y).median_share


def test_a_camera_whose_probe_is_dark_is_redrawn():
    """A probe that finds the first camera dark makes the generator draw the next one."""
    options = GeneratorOptions(width=32, height=32)
    seen = []

    def probe(scene):
        seen.append(scene.camera)
        return _dark_frame_with_a_patch() if len(seen) == 1 else _room_frame()

    plain = generate("rooms", root_seed=21, index=0, view=0, options=options)
    probed = generate("rooms", root_seed=21, index=0, view=0, options=options, probe=probe)
    assert seen[0] == plain.camera  # the first camera the estimate passes is the one probed
    assert probed.camera == seen[1] != plain.camera
    rule = probed.metadata["view_rule"]
    assert rule["passed"] == 1 and rule["judged"] > plain.metadata["view_rule"]["judged"]
