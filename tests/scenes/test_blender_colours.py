""".blend colours: the file's working colour space checked wherever a colour is read, image
textures fed in ways that would be read wrong refused, and what ``--approximate`` left out
named when a scene is left without light. The files are built with bpy in one subprocess
(``make_colour_blends.py``)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

MAKE = Path(__file__).with_name("make_colour_blends.py")
#: The texture's texels (bottom row first once read: Blender's v = 0).
PIXELS = np.array([[[255, 128, 0], [64, 32, 16]], [[0, 0, 255], [200, 100, 50]]], np.uint8)


@pytest.fixture(scope="module")
def blends(tmp_path_factory) -> Path:
    pytest.importorskip("bpy", reason="the optional 'blender' extra (bpy) is not installed")
    folder = tmp_path_factory.mktemp("colours")
    Image.fromarray(PIXELS).save(folder / "texel.png")
    proc = subprocess.run(
        [sys.executable, "-P", str(MAKE), "--", str(folder)],
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return folder


def load(path: Path, **options):
    from spectrinsic.scenes.blender import load_blend

    return load_blend(path, **options)


@pytest.mark.blender
def test_a_base_colour_is_read_in_linear_rec709_and_a_named_material_in_any_space(blends):
    """Control: the same Base Color in a Linear Rec.709 file is read as Blender's float32 of
    (0.2, 0.4, 0.6) to 9 digits; a file of another working space that reads no colour is read."""
    (paint,) = load(blends / "paint.blend").materials
    rgb = [float(c) for c in paint.spectrum.removeprefix("rgb:").split(",")]
    np.testing.assert_allclose(rgb, np.float32([0.2, 0.4, 0.6]), rtol=1e-8)  # 9 digits
    (named,) = load(blends / "named_wide.blend").materials
    assert named.spectrum == "flat:0.8"


@pytest.mark.blender
@pytest.mark.parametrize(
    ("stem", "says"),
    [
        ("paint_wide", "material 'Paint': Base Color: the file's working colour space is "),
        ("glass_wide", "material 'flat:0.5': glass Base Color: the file's working colour space "),
        ("texture_wide", "object 'Plane': 'Paint': image 'texel.png': the file's working "),
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
def test_the_working_space_refusal_names_the_space_and_the_expected_one(blends):
    from spectrinsic.errors import SceneError

    with pytest.raises(SceneError) as info:
        load(blends / "paint_wide.blend")
    assert "'Linear Rec.2020'; expected 'Linear Rec.709'" in str(info.value)


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
