""".blend colours: the file's working colour space checked wherever a colour is read, image
textures fed in ways that would be read wrong refused, and what ``--approximate`` left out
named when a scene is left without light. The files are built with bpy in one subprocess
(``make_colour_blends.py``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from ._builders import build_blend

#: The texture's texels (bottom row first once read: Blender's v = 0).
PIXELS = np.array([[[255, 128, 0], [64, 32, 16]], [[0, 0, 255], [200, 100, 50]]], np.uint8)


@pytest.fixture(scope="module")
def blends(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("colours")
    Image.fromarray(PIXELS).save(folder / "texel.png")
    return build_blend("make_colour_blends.py", folder)


def load(path: Path, **options):
    from spectrinsic.scenes.blender import load_blend

    return load_blend(path, **options)


def _rgb(spectrum: str) -> np.ndarray:
    return np.array([float(c) for c in spectrum.partition(":")[2].split(",")])


@pytest.mark.blender
@pytest.mark.parametrize("stem", ["paint", "paint_2020", "paint_aces"])
def test_a_base_colour_blender_converted_to_another_working_space_reads_back(blends, stem):
    """(0.2, 0.4, 0.6) set in Linear Rec.709 and converted by Blender itself (its OpenColorIO
    configuration: a 7-digit matrix, Bradford-adapted for ACEScg) to Rec.2020 or ACEScg reads
    back as (0.2, 0.4, 0.6) in Rec. 709 within 1e-5 (Blender's matrix digits, there and back);
    the Rec.709 file as Blender's float32 in 9 digits."""
    (paint,) = load(blends / f"{stem}.blend").materials
    tol = 1e-8 if stem == "paint" else 1e-5
    np.testing.assert_allclose(_rgb(paint.spectrum), np.float32([0.2, 0.4, 0.6]), atol=tol)


@pytest.mark.blender
def test_a_glass_tint_and_a_world_colour_converted_by_blender_read_back(blends):
    """The glass tint (0.9, 0.8, 0.7) converted to ACEScg is read back, its transmittance the
    square roots; the World (0.8, 0.4, 0.2) x 2.5 converted to Rec.2020 is a sky of
    ``rgblight:`` (1, 0.5, 0.25); a material named after a spectrum in ACEScg reads no colour."""
    (glass,) = load(blends / "glass_aces.blend").materials
    np.testing.assert_allclose(_rgb(glass.transmittance), np.sqrt([0.9, 0.8, 0.7]), atol=1e-5)
    scene = load(blends / "world_2020.blend")
    (sky,) = [light for light in scene.lights if light.kind == "sky"]
    np.testing.assert_allclose(_rgb(sky.spectrum), [1.0, 0.5, 0.25], atol=1e-5)
    (named,) = load(blends / "named_wide.blend").materials
    assert named.spectrum == "flat:0.8"


@pytest.mark.blender
def test_an_srgb_texture_reads_alike_in_every_working_space(blends):
    """An image's colour is its own colour space's: the sRGB texels are decoded alike in a
    Linear Rec.2020 file (colour-science's sRGB decoding, bottom row first)."""
    import colour

    (plane,) = load(blends / "texture_2020.blend").meshes
    assert plane.texture is not None and plane.texture.image is not None
    expected = colour.cctf_decoding(PIXELS / 255.0, function="sRGB")[::-1]
    np.testing.assert_allclose(plane.texture.image.texels, expected, atol=1e-12)


@pytest.mark.blender
@pytest.mark.parametrize(
    ("stem", "says"),
    [
        ("saturated", "material 'Paint'"),
        ("noncolor_2020", "Non-Color values in a file whose working colour space is 'Linear Rec"),
        ("alpha", "feeds the Base Color from its Alpha output; expected its Color output"),
        ("muted", "or its link to the Base Color is muted"),
        ("xyz", "in colour space 'Linear CIE-XYZ D65'; expected sRGB or Linear Rec.709"),
        ("dropped", "at least one light (--approximate: world 'Mixed': its Surface comes from "),
    ],
)
def test_each_colour_read_wrong_is_refused_by_the_command_line_in_one_line(
    blends, tmp_path, capsys, stem, says
):
    from spectrinsic.cli import main

    path = blends / f"{stem}.blend"
    out = tmp_path / "o"
    args = ["-q", "render", str(path), "--modes", "rgb3", "--out", str(out), "--approximate"]
    rc = main(args)
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert str(path) in err and says in err, err
    assert "Traceback" not in err and not out.exists()


@pytest.mark.blender
def test_a_non_color_texture_is_read_as_its_values_unencoded(blends):
    """Non-Color texels are the 8-bit values / 255, not sRGB-decoded (which would make 128
    0.2158 instead of 0.5020), bottom row first."""
    (plane,) = load(blends / "noncolor.blend").meshes
    assert plane.texture is not None and plane.texture.image is not None
    np.testing.assert_allclose(plane.texture.image.texels, PIXELS[::-1] / 255.0, atol=1e-12)
    assert plane.texture.image.texels[1, 0, 1] == pytest.approx(128 / 255)


@pytest.mark.blender
def test_a_world_left_out_is_named_in_the_scene_without_light(blends):
    """``--approximate`` drops the Mix Shader World; validation's refusal says so, and the note
    names the file once, then the World (not the reader or the file's full path)."""
    from spectrinsic.errors import SceneError
    from spectrinsic.scenes.reading_notes import reading_notes

    with pytest.raises(SceneError, match="needs at least one light") as info:
        load(blends / "dropped.blend", approximate=True)
    assert "Mix Shader" in str(info.value)
    scene = load(blends / "dropped.blend", approximate=True, validate=False)
    (note,) = reading_notes(scene)
    assert note.startswith("dropped.blend: approximated: world 'Mixed': its Surface comes from")
    assert note.endswith(": left out") and str(blends) not in note
