"""The sRGB view's ``meta["working_space"]`` tells the truth: the view keeps out-of-gamut
light's negative components, so its record says ``shading_clipped: false`` (it said true,
copied from the sRGB space's own record, whose stored shading is clipped)."""

from __future__ import annotations

import numpy as np

from spectrinsic.gt_export import export_sample, load_sample

#: A narrow cyan LED: light outside the sRGB gamut (a negative red component there).
NARROW = "led:490/10"


def test_the_srgb_view_says_its_shading_is_not_clipped_and_holds_negative_light(
    tmp_path, synth, config
):
    scene = synth.make_scene((NARROW,))
    folder = export_sample(
        tmp_path, scene, synth.make_result(scene), sample_id="a", config=config, seed=1
    )
    view = load_sample(folder, space="srgb")
    record = view["meta"]["working_space"]
    assert record["view_of"] == "acescg" and record["shading_clipped"] is False
    assert (np.asarray(view["shading"]) < 0).any()  # what "not clipped" means, observed
