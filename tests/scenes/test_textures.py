"""Spectral textures in scenes: patterns, texture coordinates, scene files (issue 22, item 2)."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml

from spectrinsic.errors import SceneError
from spectrinsic.scenes.model import scene_hash, scene_to_dict
from spectrinsic.scenes.scene_reader import load_scene
from spectrinsic.scenes.scene_writer import save_scene
from spectrinsic.scenes.textures import (
    PATTERNS,
    TEXTURE_MAX,
    box_uv,
    pattern_weights,
    texel_index,
    texture_from_record,
)

from .test_io import BASE, render_refusal, write

WOOD = {
    "kind": "textured",
    "basis": ["munsell:10YR 6/6", "munsell:5YR 5/4", "munsell:5R 4/14"],
    "pattern": "rings",
    "size": 16,
    "seed": 3,
}


def _doc(wood: object = WOOD) -> dict:
    """BASE with its ground textured by *wood*."""
    doc = copy.deepcopy(BASE)
    doc["materials"]["wood"] = wood
    doc["meshes"][1]["material"] = "wood"
    return doc


@pytest.mark.parametrize("pattern", PATTERNS)
def test_patterns_are_convex_varied_and_seeded(pattern):
    w = pattern_weights(pattern, 32, 3, seed=4)
    assert w.shape == (32, 32, 3) and w.min() >= 0.0
    assert np.abs(w.sum(axis=2) - 1.0).max() < 1e-12
    assert w.std(axis=(0, 1)).max() > 0.05  # a pattern, not a flat colour
    assert np.array_equal(w, pattern_weights(pattern, 32, 3, seed=4))
    assert not np.array_equal(w, pattern_weights(pattern, 32, 3, seed=5))


def test_box_uv_projects_each_face_along_its_normal_into_the_unit_square():
    import trimesh

    box = trimesh.creation.box((2.0, 1.0, 0.5))
    uv = box_uv(box.vertices, box.faces)
    assert uv.shape == (12, 3, 2) and uv.min() == 0.0 and uv.max() == 1.0
    # the top face (+z) takes (x, y) scaled by the box's extents
    top = np.flatnonzero(box.face_normals[:, 2] > 0.9)
    xy = box.vertices[box.faces[top]][..., :2]
    np.testing.assert_allclose(uv[top], (xy - [-1.0, -0.5]) / [2.0, 1.0])
    rows, cols = texel_index(np.array([[0.999, 0.0], [1.0, 1.0], [-0.1, 0.5]]), (4, 8))
    assert rows.tolist() == [0, 3, 2] and cols.tolist() == [7, 7, 0]


def test_textured_yaml_loads_validates_and_round_trips(tmp_path):
    scene = load_scene(write(tmp_path, _doc()))
    ground = scene.meshes[1]
    assert ground.texture is not None and ground.texture.weights.shape == (16, 16, 3)
    basis = [scene.materials[b] for b in ground.texture.basis]
    assert [m.name for m in basis] == ["wood[0]", "wood[1]", "wood[2]"]
    assert [m.spectrum for m in basis] == WOOD["basis"]
    assert set(ground.face_materials.tolist()) == {ground.texture.basis[0]}
    saved = save_scene(scene, tmp_path / "saved.yaml")
    doc = yaml.safe_load(saved.read_text())
    assert doc["materials"]["wood"] == WOOD and doc["meshes"][1]["material"] == "wood"
    again = load_scene(saved)
    assert again == scene and scene_hash(again) == scene_hash(scene)
    # a procedural texture's record is its recipe, not its 16 x 16 x 3 weights
    record = scene_to_dict(scene)["meshes"][1]["texture"]
    assert "weights" not in record and record["pattern"] == "rings"
    assert texture_from_record(record) == ground.texture  # as relight reads scene.json
    assert "texture" not in scene_to_dict(scene)["meshes"][0]


def test_explicit_weights_round_trip(tmp_path):
    wood = {
        "kind": "textured",
        "basis": ["flat:0.2", "flat:0.9"],
        "weights": [[[1, 0], [0.25, 0.75]]],
    }
    scene = load_scene(write(tmp_path, _doc(wood)))
    np.testing.assert_array_equal(scene.meshes[1].texture.weights, [[[1, 0], [0.25, 0.75]]])
    assert load_scene(save_scene(scene, tmp_path / "saved.yaml")) == scene
    record = scene_to_dict(scene)["meshes"][1]["texture"]
    assert texture_from_record(record) == scene.meshes[1].texture


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        ({"weights": [[[0.5, 0.6]]], "pattern": None}, "not convex: a texel's weights sum"),
        ({"weights": [[[1.5, -0.5]]], "pattern": None}, "not convex: a weight is negative"),
        (
            {"size": TEXTURE_MAX + 1},
            f"expected a whole number of texels per side, 1 to {TEXTURE_MAX}",
        ),
        ({"pattern": "ring"}, "did you mean 'rings'"),
        ({"basis": ["flat:0.5"]}, "expected a list of 2 to 4 spectrum names"),
        ({"colour": "red"}, "unknown key 'colour'"),
    ],
)
def test_bad_textures_give_one_line_naming_the_field(tmp_path, change, expected):
    wood = {k: v for k, v in (WOOD | change).items() if v is not None}
    if "weights" in wood:
        wood = {k: v for k, v in wood.items() if k not in ("size", "seed")}
        wood["basis"] = wood["basis"][:2]
    path = write(tmp_path, _doc(wood))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{path}: materials.wood: ")
    assert expected in message


def test_an_unknown_basis_spectrum_is_named(tmp_path):
    wood = WOOD | {"basis": ["munsell:10YR 6/6", "munsell:5YR 3/44"]}
    with pytest.raises(
        SceneError, match=r"materials\[3\] \('wood\[1\]'\)\.spectrum: unknown Munsell"
    ):
        load_scene(write(tmp_path, _doc(wood)))


def test_a_textured_material_covers_whole_meshes(tmp_path):
    doc = _doc()
    doc["meshes"][0]["face_materials"] = [["red", 6], ["wood", 6]]
    with pytest.raises(SceneError, match="a textured material covers a whole mesh"):
        load_scene(write(tmp_path, doc))


def test_cli_rejects_a_bad_texture_before_any_work(tmp_path):
    path = write(tmp_path, _doc(WOOD | {"size": 100000}))
    assert "size 100000" in render_refusal(path, tmp_path / "out")


@pytest.mark.parametrize("generator", ["objects-on-ground", "rooms"])
def test_generated_objects_take_per_pixel_textures_on_request(tmp_path, generator):
    from spectrinsic.scenes.generators import GeneratorOptions, generate
    from spectrinsic.scenes.generators.materials import (
        PIXEL_TEXTURE,
        MaterialDistribution,
        munsell_chips,
    )
    from spectrinsic.scenes.validate import validate_scene

    def scene(fraction: float):
        dist = MaterialDistribution(chroma_range=(2.0, 4.0), texture_fraction=fraction)
        options = GeneratorOptions(width=16, height=16, materials=dist)
        return generate(generator, root_seed=5, index=0, view=0, options=options)

    chips = {n: (v, c) for n, v, c in munsell_chips()}
    plain, textured = scene(0.0), scene(1.0)
    assert all(m.texture is None for m in plain.meshes)
    meshes = [m for m in textured.meshes if m.texture is not None]
    assert meshes and textured.metadata["patterns"].count(PIXEL_TEXTURE) == len(meshes)
    validate_scene(textured)
    for mesh in meshes:
        basis = [textured.materials[b] for b in mesh.texture.basis]
        assert 2 <= len(basis) <= 3 and mesh.texture.weights.shape == (64, 64, len(basis))
        assert len({m.spectrum for m in basis}) == len(basis)  # distinct chips ...
        assert all(2.0 <= chips[m.spectrum][1] <= 4.0 for m in basis)  # ... from the range
    assert load_scene(save_scene(textured, tmp_path / "scene.yaml")) == textured


def test_texture_fraction_is_checked_and_textured_parts_do_not_merge():
    from spectrinsic.errors import DatasetError
    from spectrinsic.pipeline.source_plan import generator_source
    from spectrinsic.scenes.generators.materials import MaterialDistribution
    from spectrinsic.scenes.parts import merge
    from spectrinsic.scenes.primitives import box

    with pytest.raises(SceneError, match="texture_fraction=1.5"):
        MaterialDistribution(texture_fraction=1.5)
    with pytest.raises(DatasetError, match="--texture-fraction 1.5"):
        generator_source("rooms", 2, texture_fraction=1.5)
    assert "texture_fraction" not in generator_source("rooms", 2)  # older configs keep their hash
    part = box((1, 1, 1), "flat:0.5")
    textured = type(part)(
        part.vertices, part.faces, part.labels, ("flat:0.2", "flat:0.8"), ("noise", 4, 0)
    )
    with pytest.raises(SceneError, match="textured part"):
        merge(part, textured)
