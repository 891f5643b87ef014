"""Image textures as exact spectral textures (issue 41, item 2): the corner weights, decoding,
wrapping and the refusals, without rendering."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from spectrinsic.errors import SceneError, SpectrinsicWarning
from spectrinsic.scenes.image_textures import (
    CORNERS,
    IMAGE_TEXELS_MAX,
    ImageTexture,
    corner_spectra,
    corner_weights,
    image_texture_from_file,
)
from spectrinsic.scenes.model import Camera, Material, Mesh, Scene, scene_from_dict, scene_to_dict
from spectrinsic.scenes.textures import make_image_texture, texel_index
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as WL
from spectrinsic.spectra import get_spectrum

#: float64 round-off of a product of three numbers in [0, 1].
EXACT = 1e-12


def test_corner_weights_are_convex_and_reproduce_the_colour():
    rgb = np.random.default_rng(3).random((50, 3))
    w = corner_weights(rgb)
    assert w.shape == (50, 8) and np.all(w >= 0)
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=EXACT)
    np.testing.assert_allclose(w @ np.array(CORNERS), rgb, atol=EXACT)


def test_a_texel_spectrum_is_the_basis_matrix_times_its_rgb():
    """Σ_c w_c ρ_c (the corners' registry spectra) equals R b_R + G b_G + B b_B, the spectrum
    the registry gives ``rgb:R,G,B`` (Mallett & Yuksel 2019)."""
    rho = np.stack([get_spectrum(name).on(WL) for name in corner_spectra()])
    basis = rho[[1, 2, 4]]  # rgb:1,0,0, rgb:0,1,0, rgb:0,0,1
    assert np.all(rho >= 0) and np.all(rho <= 1)
    # flat on 400-700 nm: b_R + b_G + b_B = 1 (3.3e-8 measured; 1e-5 below 400 nm)
    visible = (WL >= 400) & (WL <= 700)
    np.testing.assert_allclose(basis.sum(axis=0)[visible], 1.0, atol=1e-7)
    for rgb in ([0.2, 0.7, 0.4], [1.0, 0.0, 0.5], [0.03, 0.03, 0.9]):
        mixed = corner_weights(np.array(rgb)) @ rho
        np.testing.assert_allclose(mixed, np.array(rgb) @ basis, atol=1e-9)
        reference = get_spectrum("rgb:" + ",".join(map(str, rgb))).on(WL)
        np.testing.assert_allclose(mixed, reference, atol=1e-9)


def _png(folder, pixels, name="t.png"):
    Image.fromarray(np.asarray(pixels, np.uint8)).save(folder / name)
    return folder / name


def test_srgb_images_are_decoded_times_the_factor_bottom_row_first(tmp_path):
    import colour

    pixels = np.array([[[255, 0, 0], [128, 128, 128]], [[0, 64, 255], [10, 20, 30]]])
    path = _png(tmp_path, pixels)
    image = image_texture_from_file(path, root=tmp_path, srgb=True, factor=(1.0, 0.5, 0.25))
    expected = colour.cctf_decoding(pixels / 255.0, function="sRGB") * [1.0, 0.5, 0.25]
    np.testing.assert_allclose(image.texels, expected[::-1], atol=EXACT)
    assert image.source == "t.png" and len(image.sha256) == 64
    linear = image_texture_from_file(path, root=tmp_path, srgb=False)
    np.testing.assert_allclose(linear.texels, pixels[::-1] / 255.0, atol=EXACT)


def test_texels_above_one_are_clipped_and_said(tmp_path):
    path = _png(tmp_path, np.full((2, 2, 3), 200))
    with pytest.warns(SpectrinsicWarning, match="4 texels outside"):
        image = image_texture_from_file(path, root=tmp_path, srgb=False, factor=(2.0, 1, 1))
    assert image.texels[..., 0].max() == 1.0


def test_bad_images_are_refused_in_one_line(tmp_path):
    inside = tmp_path / "scene"
    inside.mkdir()
    outside = _png(tmp_path, np.zeros((2, 2, 3)))
    cases = [
        (outside, "outside the scene's folder"),
        (inside / "missing.png", "no such file"),
    ]
    (inside / "junk.png").write_bytes(b"not an image")
    cases.append((inside / "junk.png", "cannot read it as an image"))
    big = Image.new("L", (IMAGE_TEXELS_MAX + 1, 1))
    big.save(inside / "big.png")
    cases.append((inside / "big.png", "expected at most"))
    for path, message in cases:
        with pytest.raises(SceneError, match=message) as info:
            image_texture_from_file(path, root=inside, srgb=True)
        assert "\n" not in str(info.value)


def _image(wrap="repeat", h=2, w=3) -> ImageTexture:
    texels = np.random.default_rng(1).random((h, w, 3))
    return ImageTexture("t.png", "0" * 64, texels, wrap=wrap, filter="nearest")


def _wrap(x: np.ndarray, wrap: str) -> np.ndarray:
    """Coordinates *x* wrapped into [0, 1) as the glTF sampler / Mitsuba define the mode."""
    if wrap == "repeat":
        return x % 1.0
    tile, frac = np.divmod(x, 1.0)
    return np.where(tile % 2 == 0, frac, 1.0 - frac)  # mirror: odd copies run backwards


@pytest.mark.parametrize("wrap", ["repeat", "mirror"])
def test_wrapping_is_exact_under_the_clamped_nearest_lookup(wrap):
    """Coordinates spanning [-1, 2] × [0, 2]: the image is copied 3 × 2 times and the
    coordinates rescaled; every point then finds the texel its wrap mode gives."""
    image = _image(wrap)
    uv = np.array([[[-1.0, 0.0], [2.0, 0.0], [2.0, 2.0]], [[-1.0, 0.0], [2.0, 2.0], [-1.0, 2.0]]])
    texture = make_image_texture("t", tuple(range(8)), image, uv)
    assert texture.image.tiles == (2, 3) and texture.image.first_tile == (0, -1)
    assert texture.weights.shape == (4, 9, 8)
    np.testing.assert_allclose(texture.uv[0, 1], (1.0, 0.0))
    points = np.random.default_rng(2).uniform((-1, 0), (2, 2), (400, 2))
    scaled = (points - (-1.0, 0.0)) / (3.0, 2.0)  # the same affine map as the face corners
    row, col = texel_index(scaled, texture.weights.shape[:2])
    wrapped_row, wrapped_col = texel_index(_wrap(points, wrap), image.texels.shape[:2])
    np.testing.assert_array_equal(
        texture.weights[row, col], corner_weights(image.texels[wrapped_row, wrapped_col])
    )


def test_clamped_coordinates_keep_the_image_once():
    uv = np.array([[[-0.5, 0.0], [1.5, 0.0], [1.5, 1.0]]])
    texture = make_image_texture("t", tuple(range(8)), _image("clamp"), uv)
    assert texture.image.tiles == (1, 1) and np.array_equal(texture.uv, uv)


def test_too_many_copies_are_refused():
    uv = np.array([[[0.0, 0.0], [600.0, 0.0], [600.0, 600.0]]])
    with pytest.raises(SceneError, match="copies of a 3x2 image"):
        make_image_texture("t", tuple(range(8)), _image(), uv)


def _scene_of(texture) -> Scene:
    return Scene(
        "s",
        (Mesh("m", np.eye(3), np.array([[0, 1, 2]]), np.zeros(1, np.int64), 0, texture),),
        tuple(Material(name, name) for name in corner_spectra()),
        (),
        Camera((0, 0, 3), (0, 0, 0), (0, 1, 0), 30.0, 8, 8),
    )


def test_an_image_texture_in_memory_survives_its_scene_record():
    texture = make_image_texture(
        "t", tuple(range(8)), _image("mirror"), np.array([[[-1, 0], [1, 0], [1, 1.0]]])
    )
    assert texture.image.tiles == (1, 2)
    record = scene_to_dict(_scene_of(texture))
    assert "weights" not in record["meshes"][0]["texture"]  # derived from the texels
    assert scene_from_dict(record) == _scene_of(texture)


def test_a_file_read_image_is_recorded_by_its_bytes_and_checked(tmp_path):
    """The scene record keeps the image file's bytes (not its texels) and decodes them again;
    bytes that do not match the recorded SHA-256 are refused."""
    import base64

    path = _png(tmp_path, np.random.default_rng(4).integers(0, 256, (16, 16, 3)))
    image = image_texture_from_file(path, root=tmp_path, srgb=True, factor=(0.5, 1.0, 1.0))
    uv = np.array([[[0, 0], [2, 0], [2, 1.0]]])  # two copies across u
    with pytest.warns(SpectrinsicWarning, match="bilinear filtering approximated"):
        texture = make_image_texture("t", tuple(range(8)), image, uv)
    record = scene_to_dict(_scene_of(texture))
    kept = record["meshes"][0]["texture"]["image"]
    assert "texels" not in kept and base64.b64decode(kept["data"]) == path.read_bytes()
    back = scene_from_dict(record)
    assert back == _scene_of(texture)
    np.testing.assert_array_equal(back.meshes[0].texture.weights, texture.weights)
    kept["data"] = base64.b64encode(b"\x89PNG tampered").decode()
    with pytest.raises(SceneError, match="do not match its SHA-256"):
        scene_from_dict(record)


def test_a_gltf_image_outside_its_folder_is_refused_in_one_line(tmp_path):
    """A ``.gltf`` whose image URI leads out of its folder: refused before any pixel is read."""
    import json

    from spectrinsic.scenes.gltf_colours import gltf_colours

    document = {
        "asset": {"version": "2.0"},
        "images": [{"uri": "../outside.png"}],
        "textures": [{"source": 0}],
        "materials": [{"name": "m", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
    }
    inside = tmp_path / "asset"
    inside.mkdir()
    _png(tmp_path, np.zeros((2, 2, 3)), "outside.png")
    (inside / "a.gltf").write_text(json.dumps(document))
    with pytest.raises(SceneError, match="'../outside.png' is not a file inside") as info:
        gltf_colours(inside / "a.gltf")
    assert "\n" not in str(info.value) and "SceneError(" not in str(info.value)


def test_mtl_colours_kd_alone_and_refusals(tmp_path):
    from spectrinsic.scenes.mtl_colours import mtl_colours

    obj = tmp_path / "a.obj"
    obj.write_text("mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    mtl = tmp_path / "a.mtl"
    mtl.write_text("newmtl paint\nKd 0.25 0.5 0.75\nnewmtl bare\n")
    colours = mtl_colours(obj)
    assert colours["paint"].spectrum == "rgb:0.25,0.5,0.75" and "bare" not in colours
    for body, message in (
        ("newmtl t\nmap_Kd -s 2 2 1 t.png\n", "map_Kd option '-s' is not supported"),
        ("newmtl t\nmap_Kd ../t.png\n", "'../t.png' is not a file inside"),
        ("newmtl t\nKd 1 x 1\n", "expected three numbers"),
    ):
        mtl.write_text(body)
        with pytest.raises(SceneError, match=message) as info:
            mtl_colours(obj)
        assert "\n" not in str(info.value)
