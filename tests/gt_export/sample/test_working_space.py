"""The RGB working space (issue 30): ACEScg with unclipped shading by default, linear sRGB
(shading clipped, the layers of before) on request, recorded in meta.json, and the sRGB view
that previews, the card and evaluation use."""

from __future__ import annotations

import json

import numpy as np
import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import export_sample, load_sample
from spectrinsic.gt_export.layers import compute_ground_truth, identities
from spectrinsic.spectra import xyz_to_linear_srgb
from spectrinsic.spectra.working_space import working_space

#: float32 storage of each layer, a few roundings.
F32 = 4 * float(np.finfo(np.float32).eps)
#: Saturated light the sRGB gamut cannot hold after a bounce off a saturated surface.
NARROW = "led:540/31"


def _close(a, b, scale):
    np.testing.assert_allclose(a, b, rtol=F32 * 4, atol=F32 * 4 * scale)


def test_colourspace_record_is_colour_sciences():
    import colour

    for name, cs_name in (("acescg", "ACEScg"), ("srgb", "sRGB")):
        ws = working_space(name)
        cs = colour.RGB_COLOURSPACES[cs_name]
        np.testing.assert_allclose(ws.from_xyz, cs.matrix_XYZ_to_RGB, rtol=1e-12)
        # colour-science's RGB -> XYZ is rounded (the product is the identity to 4e-5)
        np.testing.assert_allclose(ws.to_xyz, cs.matrix_RGB_to_XYZ, atol=1e-4)
        # to sRGB: XYZ -> sRGB after the space's RGB -> XYZ
        expected = colour.RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB @ cs.matrix_RGB_to_XYZ
        np.testing.assert_allclose(ws.to_srgb, expected, atol=2e-4)
        assert ws.clip_shading is (name == "srgb")
    np.testing.assert_allclose(
        working_space("acescg").from_xyz @ working_space("acescg").to_xyz, np.eye(3), atol=1e-12
    )
    np.testing.assert_array_equal(working_space("srgb").to_srgb, np.eye(3))
    with pytest.raises(ValueError, match="expected one of"):
        working_space("prophoto")


def test_srgb_space_is_the_layers_of_before_and_acescg_the_same_light(synth):
    """Both spaces are the same XYZ through their matrices; srgb is linear sRGB of the
    render's XYZ, its shading clipped; the sRGB view of the ACEScg layers is the srgb layers."""
    scene = synth.make_scene((NARROW, "planck:2800K"))
    result = synth.make_result(scene)
    srgb = compute_ground_truth(scene, result, cameras=(), working_space="srgb")
    aces = compute_ground_truth(scene, result, cameras=())
    assert aces.working_space.name == "acescg" and srgb.working_space.name == "srgb"
    xyz = np.asarray(result.images["bands31"], np.float64)
    scale = np.abs(srgb.layers["image"].data).max()
    _close(srgb.layers["image"].data, xyz_to_linear_srgb(xyz), scale)
    to_xyz = aces.working_space.to_xyz
    _close(aces.layers["image"].data @ to_xyz.T, xyz, np.abs(xyz).max())
    # reflectance: both the surface's XYZ under D65
    r_s, r_a = srgb.layers["reflectance"].data, aces.layers["reflectance"].data
    _close(aces.working_space.srgb(r_a), r_s, 1.0)
    # shading: the same light relative to each space's D65 white; sRGB clips, ACEScg does not
    s_s, s_a = srgb.layers["shading"].data, aces.layers["shading"].data
    view = aces.working_space.srgb(s_a * aces.working_space.white) / srgb.working_space.white
    np.testing.assert_allclose(np.clip(view, 0, None), s_s, atol=1e-5 * np.abs(s_s).max())
    assert (s_s >= 0).all() and srgb.layers["shading"].nonnegative
    assert not aces.layers["shading"].nonnegative
    # the identity holds in both, per pixel, to float32 rounding
    for gt in (srgb, aces):
        for ident in identities(gt):
            img, refl, sh, res = (
                gt.layers[ident[k]].data.astype(np.float64)
                for k in ("image", "reflectance", "shading", "residual")
            )
            _close(refl * sh + res, img, np.abs(img).max())


def test_acescg_keeps_out_of_gamut_light_that_srgb_clips_into_the_residual(synth):
    """Under a 540 nm LED the green bounce light is out of sRGB's gamut: the srgb shading is
    clipped on lit pixels and its residual grows; ACEScg holds the light (nothing clipped)
    and its residual share is smaller."""
    scene = synth.make_scene((NARROW,))
    result = synth.make_result(scene)
    srgb = compute_ground_truth(scene, result, cameras=(), working_space="srgb")
    aces = compute_ground_truth(scene, result, cameras=())
    assert srgb.clipping["pixels"] > 0.5
    assert aces.clipping["pixels"] == 0.0
    assert aces.residual_share["image"] < srgb.residual_share["image"]


def test_meta_records_the_space_and_the_loader_gives_the_srgb_view(tmp_path, synth, config):
    scene = synth.make_scene((NARROW, "cie:D65"))
    result = synth.make_result(scene)
    folder = export_sample(tmp_path, scene, result, sample_id="a", config=config, seed=1)
    old = export_sample(
        tmp_path, scene, result, sample_id="s", config=config, seed=1, working_space="srgb"
    )
    record = json.loads((folder / "meta.json").read_text())["working_space"]
    assert record["name"] == "acescg" and record["shading_clipped"] is False
    np.testing.assert_allclose(record["rgb_to_xyz"], working_space("acescg").to_xyz)
    stored, view = load_sample(folder), load_sample(folder, space="srgb")
    reference = load_sample(old)
    assert reference["meta"]["working_space"]["name"] == "srgb"
    scale = np.abs(reference["image"]).max()
    for key in ("image", "reflectance", "image_spectral"):
        _close(view[key], reference[key], max(scale, 1.0))
    assert np.abs(stored["image"] - view["image"]).max() > 0.01 * scale  # a real change
    # the residual recomputed in the view closes the identity there
    rebuilt = view["reflectance"].astype(np.float64) * view["shading"] + view["residual"]
    _close(rebuilt, view["image"], scale)
    # a layer subset still gets the recomputed residual
    part = load_sample(folder, layers=["residual"], space="srgb")
    assert set(part) == {"residual", "meta"}
    np.testing.assert_array_equal(part["residual"], view["residual"])
    # the srgb sample's view is itself
    same = load_sample(old, space="srgb")
    np.testing.assert_array_equal(same["shading"], reference["shading"])
    with pytest.raises(DatasetError, match="space="):
        load_sample(folder, space="acescg")


def test_working_space_is_a_hashed_dataset_setting():
    from spectrinsic.pipeline.presets import DatasetConfig

    base = DatasetConfig.from_settings("tiny", width=8, height=8, spp=2)
    assert base.working_space == "acescg"
    srgb = base.with_options(working_space="srgb")
    assert "working_space" not in srgb.settings()  # srgb: the hash of before
    assert base.settings()["working_space"] == "acescg"
    assert base.config_hash() != srgb.config_hash()
    with pytest.raises(DatasetError, match="--working-space 'xyz'; expected one of"):
        base.with_options(working_space="xyz")


def test_dataset_card_shows_the_residual_figure_by_light_family(built):
    """DATASET.md links residual.png, a real PNG written beside it, and names the space; the
    figure's data are the samples' recorded shares by family."""
    from spectrinsic.gt_export.dataset.card_residual import residual_by_family
    from spectrinsic.gt_export.sample import sample_dirs

    card = (built / "DATASET.md").read_text()
    assert "![Residual share by light family](residual.png)" in card
    assert "working space: ACEScg" in card
    png = (built / "residual.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 2000
    metas = [json.loads((d / "meta.json").read_text()) for d in sample_dirs(built)]
    by_family = residual_by_family(metas)
    assert sum(len(v["rgb"]) for v in by_family.values()) == len(metas) == 2
    shares = sorted(m["residual_share"]["image"] for m in metas)
    assert sorted(x for v in by_family.values() for x in v["rgb"]) == shares
