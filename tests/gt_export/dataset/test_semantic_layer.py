"""The ``semantic`` layer (issue 41): each pixel's class is its object's, written with the class
table, loaded, checked, listed in the manifest and the card (synthetic renders, no Mitsuba)."""

from __future__ import annotations

import dataclasses
import json

import numpy as np

from spectrinsic.gt_export import (
    check_dataset,
    export_sample,
    load_sample,
    write_dataset_card,
    write_manifest,
)
from spectrinsic.gt_export.dataset.check import _semantic_problems
from spectrinsic.scenes.semantic import class_id, class_table


def _two_objects(synth):
    """The synthetic scene with a table (object 0, its class from its name) and a mesh named
    ``Mesh.3`` given the class ``lamp`` (object 5), splitting the covered pixels in two."""
    scene = synth.make_scene(("planck:2800K",))
    table = dataclasses.replace(scene.meshes[0], name="table-0", semantic="")  # its name's class
    lamp = dataclasses.replace(scene.meshes[0], name="Mesh.3", object_id=5, semantic="lamp")
    scene = dataclasses.replace(scene, meshes=(table, lamp))
    result = synth.make_result(scene)
    covered = result.aovs["material_id"] >= 0
    left = np.arange(synth.W)[None, :] < synth.W // 2
    object_id = np.where(covered, np.where(left, 0, 5), -1).astype(np.int32)
    return scene, dataclasses.replace(result, aovs={**result.aovs, "object_id": object_id})


def test_the_semantic_layer_is_each_objects_class_and_round_trips(tmp_path, synth, config):
    scene, result = _two_objects(synth)
    export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=1)
    sample = load_sample(tmp_path / "s")
    object_id = result.aovs["object_id"]
    expected = np.select(
        [object_id == 0, object_id == 5], [class_id("table"), class_id("lamp")], default=-1
    )
    assert sample["semantic"].dtype == np.int32
    np.testing.assert_array_equal(sample["semantic"], expected)
    np.testing.assert_array_equal(sample["ids"]["semantic"], expected)
    assert {-1, class_id("table"), class_id("lamp")} == set(np.unique(sample["semantic"]))
    assert sample["meta"]["semantic_classes"] == class_table()
    assert "semantic" in sample["meta"]["layers"]
    write_manifest(tmp_path, config)
    write_dataset_card(tmp_path, config)
    manifest = json.loads((tmp_path / "manifest.json").read_text())
    assert manifest["semantic_classes"] == class_table()
    assert "`semantic`" in (tmp_path / "DATASET.md").read_text()
    assert check_dataset(tmp_path) == []


def test_check_names_unknown_ids_and_objects_of_two_classes():
    table = {"0": "wall", "1": "floor"}
    objects = np.array([[0, 0, 1, -1]])
    assert (
        _semantic_problems({"semantic_classes": table}, {"semantic": np.array([[0, 0, 1, -1]])})
        == []
    )
    unknown = _semantic_problems(
        {"semantic_classes": table}, {"semantic": np.array([[0, 0, 7, -1]]), "object_id": objects}
    )
    assert unknown == ["layer 'semantic' holds ids [7] not in semantic_classes"]
    mixed = _semantic_problems(
        {"semantic_classes": table}, {"semantic": np.array([[0, 1, 1, -1]]), "object_id": objects}
    )
    assert mixed == ["layer 'semantic': objects [0] have more than one class"]
    assert _semantic_problems({}, {"semantic": objects}) == [
        "layer 'semantic' has no class table (semantic_classes) in meta.json"
    ]
