"""One scene-wide budget of faces, vertices and texels (:mod:`spectrinsic.scenes.budget`),
charged from what each part declares before it is loaded.

A 327,000-face GLB was accepted because its accessors were not counted (only vertices were),
and ten references to one 200,000-face PLY loaded 5 GB before "out of memory". Now each is
refused in one line naming the file and the count, before trimesh builds anything.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.errors import SceneError
from spectrinsic.scenes.budget import MAX_FACES, MAX_TEXELS, SceneBudget
from spectrinsic.scenes.mesh_counts import mesh_counts
from spectrinsic.scenes.sources import load_scene_file

LIGHT = "lights:\n  - {kind: point, spectrum: 'cie:D65', power: 4, position: [0, 0, 2]}\n"
CAMERA = "camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 16, height: 16}\n"


def glb(path: Path, document: dict) -> Path:
    """A GLB holding only its JSON chunk (the counts live there; no geometry is needed)."""
    data = json.dumps(document).encode()
    data += b" " * (-len(data) % 4)
    chunk = struct.pack("<I4s", len(data), b"JSON") + data
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(chunk)) + chunk)
    return path


def _document(faces: int, vertices: int, nodes: int = 1) -> dict:
    return {
        "asset": {"version": "2.0"},
        "accessors": [
            {"count": vertices, "type": "VEC3", "componentType": 5126},
            {"count": 3 * faces, "type": "SCALAR", "componentType": 5125},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0} for _ in range(nodes)],
    }


def _ply_header(path: Path, faces: int, vertices: int = 3) -> Path:
    path.write_text(
        "ply\nformat ascii 1.0\n"
        f"element vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    return path


def test_glb_faces_are_counted_from_their_accessors_per_node(tmp_path):
    assert mesh_counts(glb(tmp_path / "a.glb", _document(100, 60))) == (60, 100)
    assert mesh_counts(glb(tmp_path / "b.glb", _document(100, 60, nodes=3))) == (180, 300)
    unindexed = _document(0, 90)
    del unindexed["meshes"][0]["primitives"][0]["indices"]
    assert mesh_counts(glb(tmp_path / "c.glb", unindexed)) == (90, 30)


@pytest.fixture
def no_loading(monkeypatch):
    """trimesh.load fails the test: a refusal must come before any mesh is built."""
    import trimesh

    def load(*args, **kwargs):
        raise AssertionError(f"trimesh.load{args} called: the budget was not charged first")

    monkeypatch.setattr(trimesh, "load", load)


def test_a_glb_over_the_face_budget_is_refused_before_loading(tmp_path, no_loading):
    path = glb(tmp_path / "big.glb", _document(327_000, 170_000))
    with pytest.raises(SceneError, match=r"big\.glb.*327,000 faces; a scene holds at most 250,000"):
        load_scene_file(path, default_spectrum="flat:0.5")


def test_ten_references_to_one_large_ply_are_refused_before_the_second_loads(tmp_path, monkeypatch):
    import trimesh

    _ply_header(tmp_path / "big.ply", 200_000)  # only the header: the body is never read
    loaded = []
    monkeypatch.setattr(
        trimesh,
        "load",
        lambda *a, **k: (
            loaded.append(a)
            or trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]])
        ),
    )
    meshes = "".join(f"  - {{name: m{i}, file: big.ply, material: grey}}\n" for i in range(10))
    scene = tmp_path / "s.yaml"
    scene.write_text(f"name: s\nmaterials: {{grey: 'flat:0.5'}}\nmeshes:\n{meshes}{LIGHT}{CAMERA}")
    with pytest.raises(SceneError) as caught:
        load_scene_file(scene)
    message = str(caught.value)
    assert "\n" not in message and "s.yaml" in message and "big.ply" in message
    assert "400,000 faces" in message and f"{MAX_FACES:,}" in message
    assert len(loaded) == 1  # the second reference was refused from the header


def test_textures_share_one_texel_budget(tmp_path):
    materials = "".join(
        f"  t{i}: {{kind: textured, pattern: noise, size: 256, seed: {i}, "
        "basis: ['flat:0.2', 'flat:0.8']}\n"
        for i in range(MAX_TEXELS // 256**2 + 1)
    )
    scene = tmp_path / "s.yaml"
    scene.write_text(
        "name: s\nmaterials:\n" + materials
        + "meshes:\n  - {name: q, vertices: [[0,0,0],[1,0,0],[0,1,0]], faces: [[0,1,2]], "
        "material: t0}\n" + LIGHT + CAMERA
    )  # fmt: skip
    with pytest.raises(SceneError, match=rf"texels; a scene holds at most {MAX_TEXELS:,} texels"):
        load_scene_file(scene)


def test_a_refused_charge_keeps_the_budget_spent():
    budget = SceneBudget("s.yaml")
    budget.charge("a", faces=MAX_FACES)
    with pytest.raises(SceneError, match="s.yaml: b brings the scene to 250,001 faces"):
        budget.charge("b", faces=1)
    with pytest.raises(SceneError):  # later parts, however small, are refused too
        budget.charge("c", faces=1)
    assert np.isclose(budget.faces, MAX_FACES + 2)
