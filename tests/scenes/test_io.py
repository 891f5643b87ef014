"""YAML scene files: round trips, mesh files, and a one-line error for every bad input."""

from __future__ import annotations

import copy
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml

from spectrinsic.errors import SceneError
from spectrinsic.scenes import library
from spectrinsic.scenes.model import Light, scene_hash
from spectrinsic.scenes.scene_reader import load_scene
from spectrinsic.scenes.scene_writer import save_scene

SEED = 7

# a unit cube (closed, outward) resting on a ground quad, lit from above, seen from the front
CUBE = trimesh.creation.box((1.0, 1.0, 1.0))
BASE: dict = {
    "format": 1,
    "name": "cube",
    "materials": {"red": "munsell:5R 4/14", "ground": "flat:0.5"},
    "meshes": [
        {
            "name": "cube",
            "vertices": (CUBE.vertices + [0, 0, 0.5]).tolist(),
            "faces": CUBE.faces.tolist(),
            "face_materials": [["red", 6], ["ground", 6]],
        },
        {
            "name": "ground",
            "vertices": [[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]],
            "faces": [[0, 1, 2], [0, 2, 3]],
            "material": "ground",
        },
    ],
    "lights": [
        {"kind": "point", "spectrum": "cie:D65", "power": 5.0, "position": [1.0, -1.0, 3.0]}
    ],
    "camera": {"origin": [0.0, -4.0, 1.5], "target": [0.0, 0.0, 0.5], "width": 32, "height": 24},
}


def write(folder: Path, doc: dict, name: str = "scene.yaml") -> Path:
    path = folder / name
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


def render_refusal(path: Path, out: Path) -> str:
    """The one-line stderr of ``spectrinsic render PATH --out OUT`` refusing the scene before
    any work: rc 2, no traceback, nothing written."""
    run = subprocess.run(
        [sys.executable, "-P", "-m", "spectrinsic", "render", str(path), "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1
    assert not out.exists()
    return run.stderr


def load_error(folder: Path, doc: dict) -> str:
    path = write(folder, doc)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    assert "\n" not in message, "errors must be one line"
    assert message.startswith(f"{path}: "), "errors must name the file"
    return message


def edited(**changes) -> dict:
    """BASE with ``changes`` applied at dotted paths (``"lights.0.power"``)."""
    doc = copy.deepcopy(BASE)
    for dotted, value in changes.items():
        keys = dotted.split("__")
        node = doc
        for k in keys[:-1]:
            node = node[int(k)] if isinstance(node, list) else node[k]
        last = keys[-1]
        if value is KeyError:
            del node[last]
        elif isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
    return doc


# --- round trips ----------------------------------------------------------------------------


def test_inline_scene_loads_with_runs_and_defaults(tmp_path):
    scene = load_scene(write(tmp_path, BASE))
    assert [m.name for m in scene.meshes] == ["cube", "ground"]
    assert [m.object_id for m in scene.meshes] == [0, 1]
    np.testing.assert_array_equal(scene.meshes[0].face_materials, [0] * 6 + [1] * 6)
    assert scene.camera.up == (0.0, 0.0, 1.0) and scene.camera.fov_deg == 40.0
    assert scene.lights[0].power == 5.0


@pytest.mark.parametrize(
    ("name", "view"), [("obj-turtle", 0), ("obj-paper", 0), ("room-corner", 2)]
)
def test_library_scene_round_trips_exactly(tmp_path, name, view):
    scene = library.build(name, view=view, condition="two-colour-b", seed=SEED, width=40, height=30)
    path = save_scene(scene, tmp_path / "saved.yaml")
    again = load_scene(path)
    assert again == scene
    assert scene_hash(again) == scene_hash(scene)
    assert again.metadata == scene.metadata
    # large meshes went to PLY files next to the YAML
    text = path.read_text()
    assert "saved_meshes/" in text
    assert yaml.safe_load(text)["lights"][0]["spectrum"] == scene.lights[0].spectrum


def test_saving_twice_gives_identical_yaml(tmp_path):
    scene = load_scene(write(tmp_path, BASE))
    a = save_scene(scene, tmp_path / "a.yaml").read_text()
    b = save_scene(load_scene(tmp_path / "a.yaml"), tmp_path / "b.yaml").read_text()
    assert a == b
    assert "vertices:" in a and not (tmp_path / "a_meshes").exists()  # small meshes stay inline


def test_mesh_file_with_transform(tmp_path):
    (tmp_path / "meshes").mkdir()
    CUBE.export(tmp_path / "meshes" / "cube.obj")
    doc = edited(
        meshes__0={
            "name": "cube",
            "file": "meshes/cube.obj",
            "material": "red",
            "transform": {"scale": [2, 1, 1], "rotate_deg": [0, 0, 90], "translate": [0, 0, 0.5]},
        }
    )
    scene = load_scene(write(tmp_path, doc))
    v = scene.meshes[0].vertices
    # the x-extent 2 turns into y by the quarter turn about z
    np.testing.assert_allclose(v.min(axis=0), [-0.5, -1.0, 0.0], atol=1e-7)
    np.testing.assert_allclose(v.max(axis=0), [0.5, 1.0, 1.0], atol=1e-7)
    assert len(scene.meshes[0].faces) == 12


# --- bad input: every error names the file and the field ------------------------------------


def test_unknown_spectrum_names_material_and_suggests(tmp_path):
    msg = load_error(tmp_path, edited(materials__red="munsell:5R 4/15"))
    assert "materials[0] ('red').spectrum" in msg and "'5R 4/14'" in msg


def test_unknown_light_spectrum(tmp_path):
    msg = load_error(tmp_path, edited(lights__0__spectrum="cie:D66"))
    assert "lights[0].spectrum" in msg


def test_illuminant_used_as_material_is_rejected(tmp_path):
    msg = load_error(tmp_path, edited(materials__red="cie:D65"))
    assert "materials[0] ('red').spectrum" in msg and "expected a reflectance" in msg


@pytest.mark.parametrize("power", [0, 0.0, -1.5])
def test_zero_or_negative_power(tmp_path, power):
    msg = load_error(tmp_path, edited(lights__0__power=power))
    assert "lights[0].power" in msg and "> 0" in msg


@pytest.mark.parametrize("kind", ["point", "spot", "area"])
def test_light_inside_geometry(tmp_path, kind):
    light = {"kind": kind, "spectrum": "cie:D65", "power": 1.0, "position": [0.1, 0.2, 0.5]}
    if kind != "point":
        light["direction"] = [0, 0, -1]
    if kind == "area":
        light["size"] = [0.1, 0.1]
    msg = load_error(tmp_path, edited(lights__0=light))
    assert f"lights[0].position ({kind} light)" in msg and "inside the closed mesh 'cube'" in msg


@pytest.mark.parametrize(
    "light",
    [
        {"kind": "directional", "spectrum": "cie:D65", "power": 3.0, "direction": [0, 0, -1]},
        {
            "kind": "area",
            "spectrum": "cie:D65",
            "power": 3.0,
            "position": [0, 0, 3],
            "direction": [0, 0, -1],
            "size": [1, 1],
        },
        {
            "kind": "spot",
            "spectrum": "cie:D65",
            "power": 3.0,
            "position": [0, 0, 3],
            "direction": [0, 0, -1],
        },
    ],
    ids=lambda light: light["kind"],
)
def test_lights_at_default_placement_round_trip(tmp_path, light):
    """A light whose required fields equal the record's defaults (a sun straight down) is saved
    with those fields, so the saved file loads again (it was refused: ``direction`` missing)."""
    scene = load_scene(write(tmp_path, edited(lights__0=light)))
    assert scene.lights[0].direction == (0.0, 0.0, -1.0)
    path = save_scene(scene, tmp_path / "saved.yaml")
    assert yaml.safe_load(path.read_text())["lights"][0]["direction"] == [0.0, 0.0, -1.0]
    assert load_scene(path) == scene


def test_light_just_outside_geometry_is_fine(tmp_path):
    """1 cm above the cube's top face (z = 1) loads, and the light is where the file put it."""
    scene = load_scene(write(tmp_path, edited(lights__0__position=[0.0, 0.0, 1.01])))
    assert scene.lights[0].position == (0.0, 0.0, 1.01)


def test_directional_light_has_no_position_to_check(tmp_path):
    sun = {"kind": "directional", "spectrum": "cie:D65", "power": 3.0, "direction": [0, 0.5, -1]}
    scene = load_scene(write(tmp_path, edited(lights__0=sun)))
    assert scene.lights[0].kind == "directional"


def test_camera_inside_geometry(tmp_path):
    msg = load_error(tmp_path, edited(camera__origin=[0.1, 0.0, 0.6]))
    assert "camera.origin" in msg and "inside the closed mesh 'cube'" in msg


def test_camera_looking_at_nothing(tmp_path):
    msg = load_error(tmp_path, edited(camera__target=[0.0, -8.0, 1.5]))
    assert "camera: looks at nothing" in msg


def test_camera_looking_up_at_the_sky(tmp_path):
    msg = load_error(tmp_path, edited(camera__target=[0.0, -3.0, 9.0]))
    assert "camera: looks at nothing" in msg


def test_inline_mesh_with_nan(tmp_path):
    doc = edited()
    doc["meshes"][1]["vertices"][2] = [3.0, float("nan"), 0.0]  # written as .nan by YAML
    msg = load_error(tmp_path, doc)
    assert "meshes[1] ('ground').vertices" in msg and "NaN" in msg and "vertex 2" in msg


def test_mesh_file_with_nan(tmp_path):
    (tmp_path / "nan.obj").write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    doc = edited(meshes__1={"name": "ground", "file": "nan.obj", "material": "ground"})
    msg = load_error(tmp_path, doc)
    assert "meshes[1] ('ground').vertices" in msg and "NaN" in msg


@pytest.mark.parametrize("rel", ["../outside.obj", "meshes/../../outside.obj"])
def test_path_outside_scene_folder(tmp_path, rel):
    folder = tmp_path / "scene"
    (folder / "meshes").mkdir(parents=True)
    CUBE.export(tmp_path / "outside.obj")
    msg = load_error(folder, edited(meshes__0={"name": "cube", "file": rel, "material": "red"}))
    assert "meshes[0].file" in msg and "outside the scene's folder" in msg


def test_absolute_path_rejected(tmp_path):
    CUBE.export(tmp_path / "cube.obj")
    msg = load_error(
        tmp_path,
        edited(meshes__0={"name": "cube", "file": str(tmp_path / "cube.obj"), "material": "red"}),
    )
    assert "meshes[0].file" in msg and "absolute path" in msg


@pytest.mark.skipif(not hasattr(os, "symlink"), reason="platform without symbolic links")
def test_symlink_leading_outside_rejected(tmp_path):
    folder = tmp_path / "scene"
    folder.mkdir()
    CUBE.export(tmp_path / "secret.obj")
    (folder / "link.obj").symlink_to(tmp_path / "secret.obj")
    msg = load_error(
        folder, edited(meshes__0={"name": "cube", "file": "link.obj", "material": "red"})
    )
    assert "outside the scene's folder" in msg


def test_missing_and_unsupported_mesh_files(tmp_path):
    msg = load_error(
        tmp_path, edited(meshes__0={"name": "cube", "file": "nope.ply", "material": "red"})
    )
    assert "meshes[0].file" in msg and "not found" in msg
    (tmp_path / "cube.blend").write_bytes(b"BLENDER")
    msg = load_error(
        tmp_path, edited(meshes__0={"name": "cube", "file": "cube.blend", "material": "red"})
    )
    assert "unsupported mesh file type" in msg


def test_corrupt_mesh_file(tmp_path):
    (tmp_path / "bad.ply").write_bytes(b"ply\nformat gibberish\n")
    msg = load_error(
        tmp_path, edited(meshes__0={"name": "cube", "file": "bad.ply", "material": "red"})
    )
    assert "meshes[0].file" in msg and "bad.ply" in msg


@pytest.mark.parametrize(
    ("changes", "field", "expected"),
    [
        ({"lights__0__power": "bright"}, "lights[0].power", "expected a number"),
        ({"lights__0__power": True}, "lights[0].power", "expected a number"),
        ({"lights__0__position": [1, 2]}, "lights[0].position", "3 numbers"),
        ({"lights__0__kind": "pont"}, "lights[0].kind", "did you mean 'point'"),
        ({"lights__0__positon": [0, 0, 3]}, "lights[0].positon", "did you mean 'position'"),
        ({"camera__width": "wide"}, "camera.width", "integer >= 1"),
        ({"camera__height": 0}, "camera.height", "integer >= 1"),
        ({"camera__fov_deg": 180}, "camera.fov_deg", "(0, 180)"),
        ({"camera__up": [0, 4, -1]}, "camera.up", "parallel"),
        ({"camera__target": [0.0, -4.0, 1.5]}, "camera.target", "equals camera.origin"),
        ({"camera__origin": KeyError}, "camera.origin", "missing required key"),
        ({"meshes__1__faces": [[0, 1, 7]]}, "meshes[1] ('ground').faces", "out of range"),
        ({"meshes__1__faces": [[0, 1, 2.5]]}, "meshes[1].faces[0][2]", "expected an integer"),
        ({"meshes__1__vertices": "none"}, "meshes[1].vertices", "non-empty list"),
        ({"meshes__1__material": "blue"}, "meshes[1].material", "unknown material 'blue'"),
        ({"meshes__0__face_materials": [["red", 5]]}, "meshes[0].face_materials", "covers 5 faces"),
        ({"meshes__1__name": "cube"}, "meshes[1] ('cube').name", "duplicate"),
        ({"meshes__1__object_id": -1}, "meshes[1].object_id", "integer >= 0"),
        ({"materials": ["red"]}, "materials", "mapping"),
        ({"lights": []}, "lights", "non-empty list"),
        ({"format": 2}, "format", "unsupported format version"),
        ({"colour": "red"}, "colour", "unknown key"),
    ],
)
def test_bad_types_and_values(tmp_path, changes, field, expected):
    msg = load_error(tmp_path, edited(**changes))
    assert f": {field}: " in msg
    assert expected in msg


def test_spot_and_area_need_their_fields(tmp_path):
    msg = load_error(tmp_path, edited(lights__0__kind="area"))
    assert "lights[0].direction" in msg and "missing" in msg


def test_invalid_yaml_names_the_line(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("name: x\nmaterials: {red: 'munsell:5R 4/14'\nmeshes: []\n")
    with pytest.raises(SceneError, match=r"broken\.yaml: line \d+: invalid YAML"):
        load_scene(path)


def test_unsafe_yaml_tags_are_not_constructed(tmp_path):
    path = tmp_path / "evil.yaml"
    path.write_text("name: !!python/object/apply:os.system ['echo hacked']\n")
    with pytest.raises(SceneError, match="invalid YAML"):
        load_scene(path)


def test_missing_scene_file(tmp_path):
    with pytest.raises(SceneError, match="cannot read scene file"):
        load_scene(tmp_path / "absent.yaml")


def test_format_documentation_example_loads(tmp_path):
    import re

    import spectrinsic.scenes
    from spectrinsic.scenes.objects import cup

    doc = (Path(spectrinsic.scenes.__file__).with_name("FORMAT.md")).read_text()
    example = re.search(r"```yaml\n(.*?)```", doc, re.S).group(1)
    (tmp_path / "meshes").mkdir()
    part = cup()
    trimesh.Trimesh(part.vertices, part.faces, process=False).export(
        tmp_path / "meshes" / "cup.ply"
    )
    (tmp_path / "scene.yaml").write_text(example)
    scene = load_scene(tmp_path / "scene.yaml")
    assert [m.name for m in scene.meshes] == ["cup", "ground"]
    assert len(scene.meshes[0].faces) == len(part.faces)
    # scale 0.5 then lift by 0.1: the cup's foot sits at z = 0.1
    assert scene.meshes[0].vertices[:, 2].min() == pytest.approx(0.1, abs=1e-6)


def test_light_kind_table_is_the_one_list_of_kinds():
    """LightKind, LIGHT_KINDS and LIGHT_FIELDS agree; make_light keeps only a kind's fields."""
    import typing

    from spectrinsic.scenes.model import (
        LIGHT_FIELDS,
        LIGHT_KINDS,
        LIGHT_PLACEMENT,
        LightKind,
        make_light,
    )

    assert typing.get_args(LightKind) == LIGHT_KINDS == tuple(LIGHT_FIELDS)
    assert set(LIGHT_PLACEMENT) == {"position", "direction", "size", "cutoff_deg", "radius"}
    placement = {
        "position": (1.0, 2.0, 3.0),
        "direction": (0.0, 1.0, 0.0),
        "size": (2.0, 3.0),
        "cutoff_deg": 45.0,
        "radius": 0.25,
    }
    for kind in LIGHT_KINDS:
        light = make_light(kind, "cie:D65", 1.0, **placement)
        default = Light(kind, "cie:D65", 1.0)
        for f in LIGHT_PLACEMENT:
            expected = placement[f] if f in LIGHT_FIELDS[kind] else getattr(default, f)
            assert getattr(light, f) == expected, (kind, f)
