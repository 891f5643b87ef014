"""Blender image-texture nodes read as exact spectral textures (issue 41): a small .blend
built with bpy in a subprocess, its image written here with PIL."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from spectrinsic.scenes.image_textures import corner_spectra

from ._builders import build_blend

#: Blender stores UVs in float32.
FLOAT32 = 1e-6
PIXELS = np.array([[[230, 40, 25], [20, 90, 200]], [[20, 90, 200], [200, 200, 30]]], np.uint8)


def _blend(folder: Path, pack: bool) -> Path:
    Image.fromarray(PIXELS).save(folder / "checker.png")
    png = str(folder / "checker.png")
    return build_blend("make_textured_blend.py", folder / "plane.blend", png, "1" if pack else "0")


@pytest.mark.blender
@pytest.mark.parametrize("pack", [False, True], ids=["file", "packed"])
def test_an_image_texture_node_becomes_an_exact_texture_on_the_uv_map(tmp_path, pack):
    import colour

    from spectrinsic.scenes.blender import load_blend

    path = _blend(tmp_path, pack)
    if pack:
        (tmp_path / "checker.png").unlink()  # the packed copy is read
    scene = load_blend(path)
    (plane,) = scene.meshes
    texture = plane.texture
    assert texture is not None and texture.image is not None
    assert texture.image.wrap == "repeat" and texture.image.filter == "nearest"
    assert texture.image.source == ("plane.blend#images/checker.png" if pack else "checker.png")
    # sRGB-decoded, bottom row first (Blender's and OpenGL's v = 0)
    expected = colour.cctf_decoding(PIXELS / 255.0, function="sRGB")[::-1]
    np.testing.assert_allclose(texture.image.texels, expected, atol=1e-12)
    # the corners' uv are the UV map's: (x + 1) / 2, (y + 1) / 2 of each face corner
    corners = plane.vertices[plane.faces]
    np.testing.assert_allclose(texture.uv, (corners[..., :2] + 1) / 2, atol=FLOAT32)
    assert [scene.materials[b].spectrum for b in texture.basis] == list(corner_spectra())
