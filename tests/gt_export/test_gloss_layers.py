"""Ground truth of glossy scenes (gt_export/layers/gloss.py): the identity with the specular term,
raw and denoised, in every sensor space; the material maps; the sample's check reads it back."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from spectrinsic.gt_export import check_dataset, export_sample, write_manifest
from spectrinsic.gt_export.layers import compute_ground_truth, identities
from spectrinsic.render import RenderSettings, render_batches
from spectrinsic.scenes.model import Material

#: float32 round-off of the stored layers (as test_ground_truth_physics).
FLOAT32_RTOL = 1e-5
CAMERA = "camera:Nikon 5100 (NPL)"


@pytest.fixture(scope="module")
def glossy_room(make_room):
    """The test room with a silver mirror wall, a glossy floor and a rough coated cube."""
    scene = make_room(size=16)
    mats = list(scene.materials)
    mats[3] = Material("mirror", "flat:0", kind="conductor", metal="Ag")
    mats[4] = Material("floor", "munsell:5Y 8/2", kind="plastic", ior=1.5)
    mats[6] = Material("cube", "munsell:5P 5/10", kind="plastic", ior=1.5, roughness=0.15)
    scene = replace(scene, materials=tuple(mats))
    result = render_batches(
        scene,
        RenderSettings(8, batches=2, modes=("bands31", "rgb3"), per_light=True, share_mode="rgb3"),
        seed=5,
    )
    return scene, result


def test_d_identity_with_the_specular_term_raw_denoised_and_per_camera(glossy_room):
    """(d) image = reflectance ∘ shading + specular + residual to float precision, raw and
    denoised, in sRGB and camera RGB; every layer finite; shading ≥ 0."""
    scene, result = glossy_room
    gt = compute_ground_truth(scene, result, cameras=(CAMERA,), denoise=True)
    checked = identities(gt)
    assert len(checked) == 3 and all("specular" in i for i in checked)
    for ident in checked:
        image, refl, shading, res, spec = (
            gt.layers[ident[k]].data.astype(np.float64)
            for k in ("image", "reflectance", "shading", "residual", "specular")
        )
        assert np.abs(spec).max() > 0.1 * np.abs(image).max()  # the specular term matters here
        np.testing.assert_allclose(
            refl * shading + spec + res,
            image,
            rtol=FLOAT32_RTOL,
            atol=FLOAT32_RTOL * np.abs(image).max(),
        )
    for name, layer in gt.layers.items():
        assert np.isfinite(layer.data).all(), name
        if name.split("/")[0] in (
            "shading",
            "shading_raw",
            "shading_camera",
            "shading_grey",
            "illuminant",
        ):
            assert (layer.data >= 0).all(), name


def test_material_maps_and_metal_pixels(glossy_room):
    """``metallic`` marks the mirror, whose reflectance is 0 and whose light is all specular;
    ``roughness`` is the cube's α on the cube and 1 on the matte walls."""
    scene, result = glossy_room
    gt = compute_ground_truth(scene, result)
    cov = result.aovs["coverage"]
    metal, cube, matte = cov[..., 3] == 1, cov[..., 6] == 1, cov[..., :3].sum(-1) == 1
    assert metal.any() and cube.any() and matte.any()
    assert np.all(gt.layers["metallic"].data[metal] == 1) and np.all(
        gt.layers["metallic"].data[matte] == 0
    )
    assert np.all(gt.layers["reflectance"].data[metal] == 0)
    assert np.all(gt.layers["shading"].data[metal] == 0)  # no diffuse lobe: nothing to divide
    np.testing.assert_allclose(
        gt.layers["specular"].data[metal], gt.layers["image"].data[metal], rtol=1e-5, atol=1e-6
    )
    np.testing.assert_allclose(gt.layers["roughness"].data[cube], 0.15, rtol=1e-6)
    assert np.all(gt.layers["roughness"].data[matte] == 1) and np.all(
        gt.layers["non_diffuse"].data[matte] == 0
    )


def test_a_glossy_sample_passes_the_check_and_a_broken_specular_does_not(glossy_room, tmp_path):
    from spectrinsic.gt_export.exr import read_exr, read_exr_attributes, write_exr

    scene, result = glossy_room
    config = {"preset": "test", "width": 16, "height": 16, "spp": 16, "seed": 5}
    export_sample(tmp_path, scene, result, sample_id="g", config=config, seed=5)
    write_manifest(tmp_path, config)
    assert check_dataset(tmp_path) == []
    path = tmp_path / "g" / "intrinsics.exr"
    import json

    order = json.loads(read_exr_attributes(path)["spectrinsic.channels"])
    arrays = read_exr(path)
    arrays["specular"] = arrays["specular"] * 2.0
    write_exr(path, arrays, channel_names=order)
    problems = " ".join(check_dataset(tmp_path))
    assert "specular" in problems
