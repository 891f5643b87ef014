"""Mitsuba XML ``mask``, ``bumpmap`` and ``normalmap`` read exactly (issue 42, item 1).

The maps' values are the bytes written into the test's images (a bitmap's luminance, sRGB
decoded unless ``raw``, as Mitsuba reads it); the checker mask's orientation is checked against
Mitsuba's own render of the same file: the pixels it shows the red quad on are the ones our
first-hit coverage gives the quad.
"""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from spectrinsic.cli import main
from spectrinsic.errors import SceneError
from spectrinsic.render.base.variants import choose_variant, import_mitsuba
from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml
from spectrinsic.scenes.model import scene_from_dict, scene_to_dict

SIZE = 32
_XML = """<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="30"/>
    <transform name="to_world"><lookat origin="0,0,3" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="{size}"/>
      <integer name="height" value="{size}"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="rectangle" id="leaf">
    {bsdf}
  </shape>
  <shape type="rectangle" id="wall">
    <transform name="to_world"><scale value="3"/><translate z="-1"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.05,0.1,0.6"/></bsdf>
  </shape>
</scene>
"""
_MASK = """<bsdf type="mask" id="leafy">
      <texture type="bitmap" name="opacity"><string name="filename" value="{file}"/>
        <string name="filter_type" value="nearest"/></texture>
      <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.1,0.1"/></bsdf></bsdf>
    </bsdf>"""
_BUMP = """<bsdf type="twosided"><bsdf type="bumpmap">
      <texture type="bitmap"><string name="filename" value="{file}"/><boolean name="raw" value="true"/></texture>
      <float name="scale" value="0.25"/>
      <bsdf type="diffuse"/>
    </bsdf></bsdf>"""
_NORMAL = """<bsdf type="normalmap">
      <texture type="bitmap" name="normalmap"><string name="filename" value="{file}"/>
        <boolean name="raw" value="true"/></texture>
      <bsdf type="twosided"><bsdf type="diffuse"/></bsdf>
    </bsdf>"""


def _checker() -> np.ndarray:
    """A 4 × 4 checker of 0/255 (row 0 the image's top), symmetry broken at one corner."""
    index = np.add.outer(np.arange(4), np.arange(4)) % 2
    index[0, 0] = 1 - index[0, 0]
    return (index * 255).astype(np.uint8)


def _write(folder, bsdf: str, image: np.ndarray, name: str = "map.png") -> str:
    Image.fromarray(image).save(folder / name)
    (folder / "scene.xml").write_text(_XML.format(size=SIZE, bsdf=bsdf.format(file=name)))
    return str(folder / "scene.xml")


def _load(path: str):
    import_mitsuba()  # the reader imports Mitsuba as found: set it up first, as the CLI does
    return load_mitsuba_xml(path)


def test_mask_bitmap_is_read_as_the_leaf_opacity(tmp_path):
    scene = _load(_write(tmp_path, _MASK, _checker()))
    leaf, wall = scene.meshes
    assert wall.maps is None and leaf.maps is not None
    assert leaf.maps.opacity == 1.0 and leaf.maps.normal_image is None
    texels = leaf.maps.opacity_image.texels  # row 0 at v = 0: the image's bottom row
    np.testing.assert_array_equal(texels[..., 0], _checker()[::-1] / 255.0)
    assert leaf.maps.uv.shape == (len(leaf.faces), 3, 2)
    # the material is the wrapped BSDF's, named by the wrapper
    assert scene.materials[int(leaf.face_materials[0])].name == "leafy"
    assert scene_from_dict(scene_to_dict(scene)) == scene  # the record keeps the maps


def test_constant_opacity_mask(tmp_path):
    bsdf = '<bsdf type="mask"><float name="opacity" value="0.25"/><bsdf type="diffuse"/></bsdf>'
    scene = _load(_write(tmp_path, bsdf, _checker()))
    assert scene.meshes[0].maps.opacity == 0.25 and scene.meshes[0].maps.opacity_image is None


def test_bump_and_normal_maps_are_read_raw(tmp_path):
    ramp = np.tile(np.arange(0, 256, 32, dtype=np.uint8), (8, 1))
    maps = _load(_write(tmp_path, _BUMP, ramp)).meshes[0].maps
    assert maps.bump_scale == 0.25 and not maps.masked
    np.testing.assert_array_equal(maps.bump_image.texels[..., 1], ramp[::-1] / 255.0)
    tilt = np.broadcast_to(np.array([160, 100, 230], np.uint8), (2, 2, 3))
    maps = _load(_write(tmp_path, _NORMAL, np.ascontiguousarray(tilt))).meshes[0].maps
    np.testing.assert_array_equal(maps.normal_image.texels[0, 0], [160 / 255, 100 / 255, 230 / 255])
    assert maps.bump_image is None


@pytest.mark.parametrize(
    ("bsdf", "expected"),
    [
        (_BUMP.replace("{file}", "../outside.png"), "expected a path inside the scene's folder"),
        (
            '<bsdf type="mask"><float name="opacity" value="1.5"/><bsdf type="diffuse"/></bsdf>',
            "opacity 1.5; expected a number in [0, 1]",
        ),
        (
            '<bsdf type="mask"><texture type="checkerboard" name="opacity"/><bsdf type="diffuse"/></bsdf>',
            "expected a <texture type='bitmap'>",
        ),
        (
            '<bsdf type="bumpmap"><bsdf type="diffuse"/></bsdf>',
            "expected one <texture type='bitmap'>, found 0",
        ),
    ],
)
def test_bad_wrappers_are_refused_in_one_line_with_rc_2(tmp_path, capsys, bsdf, expected):
    (tmp_path / "outside.png").write_bytes(b"")
    folder = tmp_path / "scene"
    folder.mkdir()
    Image.fromarray(_checker()).save(tmp_path / "outside.png")
    path = _write(folder, bsdf.replace("{file}", "map.png"), _checker())
    with pytest.raises(SceneError, match=expected.replace("[", r"\[").replace("]", r"\]")):
        _load(path)
    assert main(["render", path, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and expected in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_mask_lands_where_mitsuba_renders_it(tmp_path):
    """Mitsuba's own render of the file (its ``mask``, its rectangle's uv, its bitmap lookup)
    shows the red leaf on the pixels our first-hit coverage gives the leaf."""
    from spectrinsic.render import RenderSettings, render_scene

    path = _write(tmp_path, _MASK, _checker())
    scene = _load(path)  # sets Mitsuba up (its libLLVM) before anything imports it
    result = render_scene(scene, RenderSettings(4, max_depth=3, modes=("rgb3",)), seed=1)
    leaf = result.aovs["coverage"][..., 0]
    mi = import_mitsuba()
    mi.set_variant(choose_variant("rgb"))
    path_tracer = mi.load_dict({"type": "path", "max_depth": 3})
    image = np.asarray(mi.render(mi.load_file(path), integrator=path_tracer, spp=16, seed=1))
    image = image[..., :3]
    red = image[..., 0] > image[..., 2]  # the leaf (0.7, 0.1, 0.1) against the wall's blue
    sure = (leaf == 0.0) | (leaf == 1.0)  # pixels inside one texel
    assert sure.sum() > 600 and 0.3 < red.mean() < 0.7
    np.testing.assert_array_equal(red[sure], leaf[sure] == 1.0)
