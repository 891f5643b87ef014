"""A sample's lighting measured from its light records (spectrinsic/scenes/lighting.py)."""

from __future__ import annotations

import pytest

from spectrinsic.scenes.lighting import WHITE_XY, describe_lighting

D65 = {"spectrum": "cie:D65", "xy": list(WHITE_XY), "share": 1.0}
A = {"spectrum": "cie:A", "xy": [0.44757, 0.40745], "share": 0.5}
LED = {"spectrum": "led:blue", "xy": [0.15, 0.06], "share": 0.5}


def test_groups_follow_the_light_colours_not_the_names():
    assert describe_lighting([D65]).group == "WL"
    assert describe_lighting([D65, dict(D65, spectrum="other-name-same-white")]).group == "WL"
    assert describe_lighting([A, dict(A, share=0.3)]).group == "1L"  # generator's one-colour
    two = describe_lighting([A, LED])
    assert (two.group, two.n_lights, two.n_colours, two.spectra) == (
        "2L",
        2,
        2,
        ("cie:A", "led:blue"),
    )
    # the spread is the xy distance between the two colours
    assert two.xy_spread == pytest.approx(((0.44757 - 0.15) ** 2 + (0.40745 - 0.06) ** 2) ** 0.5)


def test_a_light_that_does_not_reach_the_image_does_not_count():
    d = describe_lighting([A, dict(LED, share=0.0)])
    assert (d.group, d.n_lights) == ("1L", 1)


def test_white_plus_a_coloured_light_is_two_colours():
    assert describe_lighting([D65, LED]).group == "2L"


@pytest.mark.parametrize("lights", [[], [{"spectrum": "x"}], [{"xy": [0.3]}]])
def test_lights_without_chromaticity_are_refused(lights):
    with pytest.raises(ValueError, match="light|xy"):
        describe_lighting(lights)
