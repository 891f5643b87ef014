"""Semantic classes (issue 41): the class table, the name map and its user extension, the
generators' classes, scene files labelled by name, and the records kept as before."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spectrinsic.errors import SceneError
from spectrinsic.gt_export.layers.geometry import semantic_ids
from spectrinsic.scenes.generators import GENERATORS, GeneratorOptions, generated_scene_seed
from spectrinsic.scenes.generators.base import scene_rngs
from spectrinsic.scenes.generators.camera import first_hits
from spectrinsic.scenes.geometry import camera_rays
from spectrinsic.scenes.model import Camera, Material, Mesh, Scene, scene_from_dict, scene_to_dict
from spectrinsic.scenes.parts import to_meshes
from spectrinsic.scenes.semantic import (
    SEMANTIC_CLASSES,
    SemanticRules,
    class_id,
    class_table,
    classify,
    read_semantic_map,
)
from spectrinsic.scenes.sources import labelled, load_scene_file
from tests.conftest import QUAD_YAML

#: The classes the rooms generator gives (no window: a room's window is an opening).
GENERATED = {"wall", "floor", "ceiling", "table", "chair", "shelf", "sofa", "lamp", "cabinet"}
#: Root seed 0, rooms scene 649: a layout holding every kind of furniture (found by a search
#: over layouts; any layout with all kinds would do).
ALL_KINDS_ROOM = 649


def test_the_class_table_is_the_issue_list_with_stable_ids():
    assert SEMANTIC_CLASSES[:11] == (
        "wall",
        "floor",
        "ceiling",
        "table",
        "chair",
        "shelf",
        "sofa",
        "lamp",
        "cabinet",
        "object",
        "window",
    )
    assert class_table() == {str(i): c for i, c in enumerate(SEMANTIC_CLASSES)}
    with pytest.raises(SceneError, match="did you mean 'table'"):
        class_id("tabel")


def _cube_map(meshes: tuple[Mesh, ...], centre: np.ndarray, n: int) -> np.ndarray:
    """Object ids of the first hits of six 90° views from *centre* (``(6 n², )``, -1 none)."""
    ids = np.array([m.object_id for m in meshes])
    faces = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    out = []
    for axis in faces:
        up = (0, 1, 0) if axis[2] else (0, 0, 1)
        origins, dirs = camera_rays(centre, centre + np.array(axis), up, 90.0, n, n, n=n)
        hit = first_hits(meshes, origins, dirs)
        out.append(np.where(hit >= 0, ids[np.maximum(hit, 0)], -1))
    return np.concatenate(out)


def test_every_generated_class_is_seen_in_a_test_room():
    seed = generated_scene_seed(0, "rooms", ALL_KINDS_ROOM)
    layout = GENERATORS["rooms"](scene_rngs(seed)["layout"], GeneratorOptions(16, 16))
    meshes, materials = to_meshes(layout.parts)
    assert {m.semantic for m in meshes} == GENERATED | {"object"}
    for mesh in meshes:  # furniture by kind, objects by shape name: the generator's own class
        kind = mesh.name.rsplit("-", 1)[0]
        expected = {"round-table": "table", "wall": "wall"}.get(kind, kind)
        assert mesh.semantic == (expected if expected in GENERATED else "object"), mesh.name
    # the first-hit id map of a cube of views from the room's centre, through the layer's lookup
    w, d, h = layout.info["room_size"]
    object_id = _cube_map(meshes, np.array([w / 2, d / 2, h / 2]), n=12)
    scene = Scene("room", meshes, materials, (), Camera((0, 0, 1), (0, 1, 1)))
    semantic = semantic_ids(scene, object_id)
    assert {SEMANTIC_CLASSES[i] for i in np.unique(semantic) if i >= 0} == GENERATED | {"object"}
    by_object = {m.object_id: class_id(m.semantic) for m in meshes}
    by_object[-1] = -1  # no hit (a window or a missing wall): background
    assert all(semantic[k] == by_object[int(o)] for k, o in enumerate(object_id))


def test_generated_classes_leave_the_scene_record_as_before():
    """The generators' classes are those their names map to, so no mesh record carries one and
    the scene hash is that of before classes existed (checked against main by hand)."""
    seed = generated_scene_seed(0, "objects-on-ground", 0)
    layout = GENERATORS["objects-on-ground"](scene_rngs(seed)["layout"], GeneratorOptions(16, 16))
    meshes, _ = to_meshes(layout.parts)
    assert {m.semantic for m in meshes} == {"floor", "object"}
    assert all(m.semantic == classify([m.name]) for m in meshes)


@pytest.mark.parametrize(
    "names, expected",
    [
        (["wall-left"], "wall"),
        (["Floor_Lamp.001"], "lamp"),  # compound names: the more specific class first
        (["wall cabinet"], "cabinet"),
        (["BookShelves"], "shelf"),
        (["round-table-3"], "table"),
        (["Armchair"], "chair"),
        (["couch"], "sofa"),
        (["Window_frame"], "window"),
        (["Ceiling"], "ceiling"),
        (["ground"], "floor"),
        (["Mesh.012"], "object"),  # no rule: the fallback
        (["Cube.001", "Oak Table Top"], "table"),  # the name says nothing: its material does
        (["chair-2", "floor paint"], "chair"),  # the name decides before the materials
    ],
)
def test_the_default_map_maps_names_as_documented(names, expected):
    assert classify(names) == expected


def test_a_user_map_is_tried_first_and_extends_the_default(tmp_path):
    path = tmp_path / "map.yaml"
    path.write_text(
        'format: 1\nfallback: unlabelled\nrules:\n  "counter|worktop": table\n  "^lamp_post": object\n'
    )
    rules = read_semantic_map(path)
    chosen = rules.compiled()
    assert classify(["Kitchen Counter"], chosen) == "table"
    assert classify(["lamp_post_3"], chosen) == "object"  # before the default's lamp rule
    assert classify(["floor_lamp"], chosen) == "lamp"  # the default rules still apply
    assert classify(["Mesh.7"], chosen) == "unlabelled"  # its fallback replaces the default's
    assert classify(["Mesh.7"]) == "object"


@pytest.mark.parametrize(
    "text, expected",
    [
        ('rules: {"desk": tabel}\n', "unknown semantic class 'tabel'"),
        ('rules: {"(desk": table}\n', "rule '(desk'"),
        ("fallback: nothing\n", "fallback: unknown semantic class"),
        ("colours: {}\n", "expected a mapping with keys"),
    ],
)
def test_a_bad_user_map_is_refused_naming_the_file(tmp_path, text, expected):
    path = tmp_path / "map.yaml"
    path.write_text(text)
    with pytest.raises(SceneError) as info:
        read_semantic_map(path)
    assert str(path) in str(info.value) and expected in str(info.value)
    assert len(str(info.value).splitlines()) == 1


def test_scene_files_are_labelled_by_object_then_material_name(tmp_path):
    text = QUAD_YAML.replace("{grey: ", "{carpet: ").replace("material: grey", "material: carpet")
    text = text.replace("name: ground", "name: Plane")
    path = tmp_path / "scene.yaml"
    path.write_text(text)
    scene = load_scene_file(path)
    assert scene.meshes[0].semantic == "floor"  # "Plane" says nothing; material "carpet" does
    # the class differs from the name's, so the record keeps it and reads it back
    record = scene_to_dict(scene)
    assert record["meshes"][0]["semantic"] == "floor"
    assert scene_from_dict(record) == scene
    user = tmp_path / "map.yaml"
    user.write_text('rules: {"^plane$": unlabelled}\n')
    relabelled = load_scene_file(path, semantic=read_semantic_map(user))
    assert relabelled.meshes[0].semantic == "unlabelled"


def test_meshes_sharing_an_object_id_must_share_a_class(tmp_path):
    extra = """  - name: chair
    object_id: 0
    vertices: [[0, 0, 0.5], [1, 0, 0.5], [0, 1, 0.5]]
    faces: [[0, 1, 2]]
    material: grey
lights:"""
    path = tmp_path / "scene.yaml"
    path.write_text(QUAD_YAML.replace("lights:", extra))
    with pytest.raises(SceneError, match="meshes sharing an object id share a class"):
        load_scene_file(path)


def test_a_mesh_record_without_a_class_takes_its_names():
    mesh = Mesh("sofa-2", np.eye(3), np.array([[0, 1, 2]]), np.array([0]), 0)
    assert mesh.semantic == "sofa"
    assert mesh != dataclasses.replace(mesh, semantic="object")


def test_a_saved_generated_scene_reads_back_with_the_generators_classes():
    """Generated materials are named after their spectra; one that a rule would match
    (``sfu:sfu_lab_wall/1``) does not make the vase it paints a wall."""
    vase = Mesh("vessel-3", np.eye(3), np.array([[0, 1, 2]]), np.array([0]), 0)
    wall = Material("sfu:sfu_lab_wall/1", "sfu:sfu_lab_wall/1")
    named = Material("Wall paint", "munsell:5Y 8/2")
    scene = Scene("s", (vase,), (wall,), (), Camera((0, 0, 1), (0, 1, 1)))
    assert labelled(scene, SemanticRules(), "s").meshes[0].semantic == "object"
    scene = dataclasses.replace(scene, materials=(named,))
    assert labelled(scene, SemanticRules(), "s").meshes[0].semantic == "wall"


def test_an_obj_mesh_takes_its_class_from_its_material_name(tmp_path):
    obj = tmp_path / "thing.obj"
    (tmp_path / "thing.mtl").write_text("newmtl Oak_Desk_top\nKd 0.5 0.3 0.1\n")
    obj.write_text("mtllib thing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl Oak_Desk_top\nf 1 2 3\n")
    scene = load_scene_file(obj, materials={"Oak_Desk_top": "munsell:10YR 6/6"})
    assert [m.semantic for m in scene.meshes] == ["table"]  # "desk" in its material's name
