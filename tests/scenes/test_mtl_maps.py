"""OBJ/MTL ``d``, ``Tr`` and ``map_d`` as a mesh's opacity mask (issue 42, item 1): the quad
is cut where the ``map_d`` image (its grey level, no alpha) says, by the OBJ's ``vt`` (v up:
the image's bottom row at v = 0)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from PIL import Image

from spectrinsic.errors import SpectrinsicWarning
from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.scenes.meshes import load_mesh_scene
from spectrinsic.scenes.model import Camera, Light

SIZE, FOV, DISTANCE, TEXELS = 32, 30.0, 3.0, 4


def _checker() -> np.ndarray:
    index = np.add.outer(np.arange(TEXELS), np.arange(TEXELS)) % 2
    index[0, 0] = 1 - index[0, 0]
    return (index * 255).astype(np.uint8)


def _obj(folder, mtl: str) -> str:
    Image.fromarray(_checker(), "L").save(folder / "leaf_d.png")
    (folder / "leaf.mtl").write_text("newmtl leafy\nKd 0.2 0.6 0.1\n" + mtl)
    lines = ["mtllib leaf.mtl", "usemtl leafy", "v -1 -1 0", "v 1 -1 0", "v 1 1 0", "v -1 1 0"]
    lines += ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1", "f 1/1 2/2 3/3", "f 1/1 3/3 4/4"]
    (folder / "leaf.obj").write_text("\n".join(lines) + "\n")
    return str(folder / "leaf.obj")


def test_map_d_cuts_the_quad_where_the_image_says(tmp_path):
    scene = load_mesh_scene(_obj(tmp_path, "map_d leaf_d.png\n"), materials={}, width=8, height=8)
    scene = replace(
        scene,
        camera=Camera((0, 0, DISTANCE), (0, 0, 0), (0, 1, 0), FOV, SIZE, SIZE),
        lights=(Light("directional", "cie:D65", 1.0, direction=(0.0, 0.0, -1.0)),),
    )
    result = render_scene(scene, RenderSettings(4, max_depth=2, modes=("bands31",)), seed=1)
    half = DISTANCE * math.tan(math.radians(FOV / 2))
    edges = np.linspace(-half, half, SIZE + 1)
    texel = np.floor((edges + 1.0) / 2.0 * TEXELS).astype(int)
    inside = (texel[:-1] == texel[1:])[:, None] & (texel[:-1] == texel[1:])[None, :]
    rows = np.broadcast_to((TEXELS - 1 - texel[::-1][1:])[:, None], (SIZE, SIZE))  # from the top
    cols = np.broadcast_to(texel[:-1][None, :], (SIZE, SIZE))
    expected = (_checker()[rows, cols] == 255).astype(float)
    cover = result.aovs["mask"].reshape(SIZE, SIZE)
    assert inside.sum() > 600
    np.testing.assert_array_equal(cover[inside], expected[inside])


def test_dissolve_and_transparency_are_constant_opacities(tmp_path):
    maps = load_mesh_scene(_obj(tmp_path, "d 0.25\n"), materials={}, width=8, height=8)
    assert maps.meshes[0].maps.opacity == 0.25
    maps = load_mesh_scene(_obj(tmp_path, "Tr 0.25\n"), materials={}, width=8, height=8)
    assert maps.meshes[0].maps.opacity == 0.75
    assert (
        load_mesh_scene(_obj(tmp_path, "d 1\n"), materials={}, width=8, height=8).meshes[0].maps
        is None
    )


def test_bump_maps_are_said_not_read(tmp_path):
    with pytest.warns(SpectrinsicWarning, match="bump maps of 1 materials .* are not read"):
        scene = load_mesh_scene(
            _obj(tmp_path, "map_bump leaf_d.png\n"), materials={}, width=8, height=8
        )
    assert scene.meshes[0].maps is None
