"""Scene files the reader tests build: .blend files by the bpy builder scripts beside this
module (``make_*.py``, each in its own subprocess, as bpy's state is global to the process), and
a glTF whose one material carries given extensions.

A helper module, not a conftest: its functions take arguments (script, target, options; a
mesh, extensions), and tests/test_test_layout.py checks only ``test_*.py`` files.
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path

import pytest
import trimesh

__all__ = ["build_blend", "gltf_with_material"]

HERE = Path(__file__).resolve().parent
#: A builder writes at most 14 small files; bpy's start-up is most of it (about 2 s idle).
TIMEOUT_S = 180


def build_blend(script: str, target: Path, *options: str) -> Path:
    """*target* (a ``.blend`` or a folder of them) written by ``tests/scenes/<script>`` run as
    ``python -P SCRIPT -- TARGET OPTIONS...``; skipped, saying why, where bpy is missing."""
    pytest.importorskip("bpy", reason="the optional 'blender' extra (bpy) is not installed")
    proc = subprocess.run(
        [sys.executable, "-P", str(HERE / script), "--", str(target), *options],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
    )
    assert proc.returncode == 0 and target.exists(), proc.stderr[-2000:]
    return target


def gltf_with_material(
    folder: Path, mesh: trimesh.Trimesh, extensions: Mapping[str, object], pbr: Mapping[str, object]
) -> Path:
    """``glass.gltf`` in *folder* (trimesh's export of *mesh* as node "pane", its buffers and
    images beside it) whose one material carries *extensions*, *pbr* merged into its
    ``pbrMetallicRoughness`` (the reader's input is the JSON, written here as glTF says)."""
    scene = trimesh.Scene()
    scene.add_geometry(mesh, "pane")
    files = scene.export(file_type="gltf")
    doc = json.loads(files.pop("model.gltf"))
    for name, data in files.items():
        (folder / name).write_bytes(data)
    (material,) = doc["materials"]
    material["extensions"] = dict(extensions)
    material["pbrMetallicRoughness"] = material.get("pbrMetallicRoughness", {}) | dict(pbr)
    path = folder / "glass.gltf"
    path.write_text(json.dumps(doc))
    return path
