"""The one slug: camera layer files, evaluation scenarios and contact sheets agree."""

from __future__ import annotations

import pytest

from spectrinsic.gt_export.formats.names import camera_slug, slug


@pytest.mark.parametrize(
    "text, expected",
    [
        ("Nikon 5100 (NPL)", "nikon-5100-npl"),
        ("Sigma SDMerill (NPL)", "sigma-sdmerill-npl"),
        ("two-colour-a", "two-colour-a"),
        ("  A__b..c  ", "a-b-c"),
        ("", ""),
    ],
)
def test_slug(text, expected):
    assert slug(text) == expected


def test_fallback_only_when_nothing_is_left():
    assert slug("()", fallback="none") == "none"
    assert slug("white", fallback="none") == "white"


def test_camera_slug_of_the_sensor_set_and_of_its_layer_key_agree():
    # the ground truth names the layer file from "camera:<key>", the evaluation its scenario
    # from the layer key "<key>": the same slug, so SC4_<slug> matches camera-<slug>
    assert (
        camera_slug("camera:Nikon 5100 (NPL)")
        == camera_slug("Nikon 5100 (NPL)")
        == "nikon-5100-npl"
    )
    assert camera_slug("camera:") == "camera"
