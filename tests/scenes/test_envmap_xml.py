"""Mitsuba XML ``envmap`` emitters (issue 42): read exactly, files checked in one line."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.cli import main
from spectrinsic.errors import SceneError
from spectrinsic.mitsuba_import import import_mitsuba
from spectrinsic.scenes.envmaps import portable_map_files
from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml
from spectrinsic.scenes.model import scene_to_dict
from spectrinsic.spectra.user_spectra import rgb_light_power

ENVMAP = """<emitter type="envmap">
    <string name="filename" value="{file}"/>
    <float name="scale" value="2.5"/>
    <transform name="to_world"><rotate x="1" angle="90"/></transform>
  </emitter>"""
SCENE = """<scene version="3.0.0">
  {emitters}
  <shape type="rectangle"><transform name="to_world"><scale value="5"/></transform>
    <bsdf type="diffuse"/></shape>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,2" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
  </sensor>
</scene>"""


def write_scene(folder, emitters: str) -> str:
    mi = import_mitsuba()
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    mi.Bitmap(np.full((4, 8, 3), 0.5, np.float32)).write(str(folder / "sky.exr"))
    path = folder / "scene.xml"
    path.write_text(SCENE.format(emitters=emitters))
    return str(path)


def test_an_envmap_is_read_with_its_file_scale_and_rotation(tmp_path):
    scene = load_mitsuba_xml(write_scene(tmp_path, ENVMAP.format(file="sky.exr")))
    assert [li.kind for li in scene.lights] == ["envmap"] * 3
    assert [li.channel for li in scene.lights] == [0, 1, 2]
    unit = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    assert [li.power for li in scene.lights] == [2.5 * rgb_light_power(e) for e in unit]
    rotation = np.reshape(scene.lights[0].rotation, (3, 3))
    assert np.allclose(rotation, [[1, 0, 0], [0, 0, -1], [0, 1, 0]], atol=1e-12)
    assert scene.lights[0].file == str((tmp_path / "sky.exr").resolve())
    (record,) = scene.metadata["files"]
    assert record["path"] == "sky.exr" and record["sha256"] == scene.lights[0].sha256


@pytest.mark.parametrize(
    ("emitters", "expected"),
    [
        (ENVMAP.format(file="../sky.exr"), "expected a path inside the scene's folder"),
        (ENVMAP.format(file="notes.txt"), "is not an OpenEXR or Radiance HDR file"),
        (
            ENVMAP.format(file="sky.exr")
            + '<emitter type="constant"><rgb name="radiance" value="1,1,1"/></emitter>',
            "an environment map and a sky",
        ),
        (
            ENVMAP.format(file="sky.exr").replace(
                "<float", '<boolean name="mis" value="true"/><float'
            ),
            "unsupported parameter 'mis'",
        ),
    ],
)
def test_a_bad_envmap_is_refused_in_one_line(tmp_path, capsys, emitters, expected):
    (tmp_path / "notes.txt").write_text("#?not a map\n")
    (tmp_path.parent / "sky.exr").write_bytes(b"\x76\x2f\x31\x01")  # outside the folder
    path = write_scene(tmp_path, emitters)
    with pytest.raises(SceneError, match=expected):
        load_mitsuba_xml(path)
    assert main(["render", path, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err
    assert not (tmp_path / "out").exists()


def test_two_envmaps_add_as_two_maps_of_three_lights_each(tmp_path):
    two = ENVMAP.format(file="sky.exr") + ENVMAP.format(file="sky.exr").replace("2.5", "1")
    scene = load_mitsuba_xml(write_scene(tmp_path, two))
    names = [li.name for li in scene.lights]
    assert names == ["envmap.r", "envmap.g", "envmap.b", "envmap_2.r", "envmap_2.g", "envmap_2.b"]
    assert scene.lights[3].power == pytest.approx(scene.lights[0].power / 2.5, rel=1e-12)


def test_the_scene_record_names_the_map_relative_to_the_scene_folder(tmp_path):
    scene = load_mitsuba_xml(write_scene(tmp_path, ENVMAP.format(file="sky.exr")))
    record = portable_map_files(scene_to_dict(scene), tmp_path)
    assert [li["file"] for li in record["lights"]] == ["sky.exr"] * 3
    elsewhere = portable_map_files(scene_to_dict(scene), tmp_path / "other")
    assert [li["file"] for li in elsewhere["lights"]] == ["sky.exr"] * 3  # the name alone
    assert str(tmp_path) not in repr(record)
