"""Mitsuba XML ``bitmap`` reflectances read as exact image textures (issue 41): decoding as
Mitsuba does, the shapes that carry texture coordinates, and the refusals, each one line.
The rendered per-texel check against colour-science and Mitsuba's own render is in
tests/render/base/test_image_textures.py. Reading the XML imports mitsuba (its parser and mesh
loader), so these tests are marked render."""

from __future__ import annotations

import colour
import numpy as np
import pytest
from PIL import Image

from spectrinsic.errors import SceneError
from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml

CAMERA = (
    '<sensor type="perspective"><transform name="to_world"><lookat origin="0,0,3" '
    'target="0,0,0" up="0,1,0"/></transform><film type="hdrfilm"><integer name="width" '
    'value="8"/><integer name="height" value="8"/></film></sensor>'
    '<emitter type="constant"><rgb name="radiance" value="1"/></emitter>'
)
TEXELS = np.array([[[10, 200, 30], [255, 0, 128]]], np.uint8)  # 1 row, 2 columns


def _scene(tmp_path, shape: str = '<shape type="rectangle">', bitmap: str = "") -> str:
    Image.fromarray(TEXELS).save(tmp_path / "tex.png")
    text = (
        f'<scene version="3.0.0">{CAMERA}{shape}<bsdf type="diffuse">'
        '<texture type="bitmap" name="reflectance"><string name="filename" value="tex.png"/>'
        f'<string name="filter_type" value="nearest"/>{bitmap}</texture></bsdf></shape></scene>'
    )
    (tmp_path / "scene.xml").write_text(text)
    return str(tmp_path / "scene.xml")


@pytest.mark.parametrize("raw", [False, True])
def test_texels_are_decoded_as_mitsuba_does(tmp_path, raw):
    """8-bit sRGB decoded by default (colour-science's transfer function), linear with raw."""
    extra = '<boolean name="raw" value="true"/>' if raw else ""
    (mesh,) = load_mitsuba_xml(_scene(tmp_path, bitmap=extra)).meshes
    image = mesh.texture.image
    want = TEXELS / 255.0 if raw else colour.cctf_decoding(TEXELS / 255.0, function="sRGB")
    np.testing.assert_allclose(image.texels, want, atol=1e-12)
    assert image.source == "tex.png" and image.wrap == "repeat" and image.srgb is not raw


def test_rectangle_corners_take_mitsubas_uv_in_our_convention(tmp_path):
    """Mitsuba's rectangle has uv ((x + 1) / 2, (y + 1) / 2) with v = 0 the image's top row:
    ours (v up) is ((x + 1) / 2, (1 - y) / 2)."""
    (mesh,) = load_mitsuba_xml(_scene(tmp_path)).meshes
    corners = mesh.vertices[mesh.faces][..., :2]
    want = np.stack([(corners[..., 0] + 1) / 2, (1 - corners[..., 1]) / 2], axis=-1)
    np.testing.assert_allclose(mesh.texture.uv, want, atol=1e-12)


@pytest.mark.parametrize(
    "shape, bitmap, message",
    [
        ('<shape type="sphere">', "", "needs texture coordinates"),
        ('<shape type="obj"><string name="filename" value="bare.obj"/>', "", "needs texture"),
        ('<shape type="rectangle">', '<transform name="to_uv"><scale x="2"/></transform>', "to_uv"),
        ('<shape type="rectangle">', '<string name="wrap_mode" value="border"/>', "wrap_mode"),
        ('<shape type="rectangle">', '<float name="gain" value="2"/>', "'gain'"),
    ],
)
def test_what_has_no_exact_texture_is_refused_in_one_line(tmp_path, shape, bitmap, message):
    (tmp_path / "bare.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
    with pytest.raises(SceneError, match=message) as info:
        load_mitsuba_xml(_scene(tmp_path, shape, bitmap))
    assert "\n" not in str(info.value)


def test_a_bitmap_outside_the_scene_folder_is_refused(tmp_path):
    inner = tmp_path / "scene"
    inner.mkdir()
    path = _scene(inner)
    Image.fromarray(TEXELS).save(tmp_path / "out.png")
    text = (inner / "scene.xml").read_text().replace("tex.png", "../out.png")
    (inner / "scene.xml").write_text(text)
    with pytest.raises(SceneError, match="inside the scene's folder"):
        load_mitsuba_xml(path)


def test_a_bitmap_on_a_plastic_stays_refused(tmp_path):
    text = (
        open(_scene(tmp_path))
        .read()
        .replace('<bsdf type="diffuse">', '<bsdf type="plastic">')
        .replace('name="reflectance"', 'name="diffuse_reflectance"')
    )
    (tmp_path / "scene.xml").write_text(text)
    with pytest.raises(SceneError, match="has no exact ground truth"):
        load_mitsuba_xml(tmp_path / "scene.xml")
