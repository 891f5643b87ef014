"""The scene record: ``scene_from_dict`` is the inverse of ``scene_to_dict`` through JSON, and a
sample's ``scene.json`` is that record (issue 35: the writer once kept texel weights the scene
hash leaves out, and a pattern texture of seed 0 could not be read back)."""

from __future__ import annotations

import ast
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.errors import SceneError
from spectrinsic.gt_export.sample import plain_data
from spectrinsic.scenes import library
from spectrinsic.scenes.model import (
    Camera,
    Light,
    Material,
    Mesh,
    Scene,
    scene_from_dict,
    scene_hash,
    scene_to_dict,
)
from spectrinsic.scenes.textures import Texture, make_texture


def _through_json(scene: Scene) -> Scene:
    return scene_from_dict(json.loads(json.dumps(scene_to_dict(scene))))


def _textured(texture: Texture) -> Scene:
    quad = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    return Scene(
        "textured",
        (Mesh("ground", quad, faces, np.zeros(2, np.int64), 0, texture=texture),),
        (Material("a", "flat:0.2"), Material("b", "munsell:5R 4/14")),
        (Light("spot", "cie:D65", 2.0, position=(0, 0, 2), cutoff_deg=20.0),),
        Camera((0.5, -2, 1), (0.5, 0.5, 0), fov_deg=35.0, width=16, height=12),
        {"kind": "test", "views": [1, 2]},
    )


@pytest.mark.parametrize("name", ["obj-apple", "room-living"])
def test_library_scenes_round_trip_with_their_hash(name):
    scene = library.build(name, condition="two-colour-a", seed=3, width=8, height=8)
    again = _through_json(scene)
    assert again == scene and scene_hash(again) == scene_hash(scene)
    assert again.metadata == json.loads(json.dumps(plain_data(scene.metadata)))


def test_defaults_left_out_come_back_as_defaults():
    """Glossy fields at their defaults are not in the record and read back as the defaults;
    a glossy material keeps every field."""
    scene = _textured(make_texture("wood", (0, 1), "rings", 8, 5))
    gold = Material("gold", "flat:0", kind="conductor", roughness=0.1, metal="Au")
    scene = replace(scene, materials=(*scene.materials, gold))
    record = scene_to_dict(scene)
    assert record["materials"][0] == {"name": "a", "spectrum": "flat:0.2"}
    assert record["materials"][2]["metal"] == "Au"
    again = _through_json(scene)
    assert again == scene and again.materials[0].kind == "diffuse"
    assert again.lights[0].cutoff_deg == 20.0 and again.camera.fov_deg == 35.0


@pytest.mark.parametrize("seed", [0, 4])
def test_a_pattern_texture_reads_back_from_its_recipe(seed):
    """Seed 0 is the field's default, so the record leaves it out; it reads back all the same
    (it raised KeyError 'seed' before), weights regenerated bit for bit."""
    texture = make_texture("wood", (0, 1), "noise", 8, seed)
    record = scene_to_dict(_textured(texture))["meshes"][0]["texture"]
    assert "weights" not in record and ("seed" in record) == (seed != 0)
    again = _through_json(_textured(texture))
    np.testing.assert_array_equal(again.meshes[0].texture.weights, texture.weights)
    assert again == _textured(texture)


def test_explicit_weights_stay_in_the_record():
    weights = np.array([[[1.0, 0.0], [0.25, 0.75]]])
    scene = _textured(Texture("paint", (0, 1), weights))
    assert scene_to_dict(scene)["meshes"][0]["texture"]["weights"] == weights.tolist()
    assert _through_json(scene) == scene


@pytest.mark.parametrize(
    "broken", [{}, {"name": "s", "meshes": [], "materials": [{"nam": "x"}], "lights": []}]
)
def test_a_broken_record_is_one_scene_error(broken):
    with pytest.raises(SceneError, match="^scene record: unexpected structure"):
        scene_from_dict(broken)


def test_plain_data_keeps_what_scene_to_dict_keeps():
    """The sample files' JSON follows the record's rule (the weights of a pattern texture out)."""
    scene = _textured(make_texture("wood", (0, 1), "rings", 8, 0))
    assert plain_data(scene) == scene_to_dict(scene)


def test_one_public_scene_from_dict():
    """Issue 46: one name, one meaning. The YAML reader's builder is private; the package
    defines ``scene_from_dict`` once, the inverse of ``scene_to_dict``."""
    package = Path(__file__).resolve().parents[2] / "spectrinsic"
    defined = [
        str(path.relative_to(package))
        for path in sorted(package.rglob("*.py"))
        for node in ast.parse(path.read_text(encoding="utf-8")).body
        if isinstance(node, ast.FunctionDef) and node.name == "scene_from_dict"
    ]
    assert defined == [str(Path("scenes", "model.py"))]
