"""Issue 36, cause 9: a mesh too large to validate in bounded memory is refused from its header.

A 10^6-face PLY took 7 GB and 41 s inside ``load_scene`` (the camera-visibility check's ray
index costs about 5.3 KiB per face). The documented limit (250,000 faces and vertices,
:data:`spectrinsic.scenes.meshes.MAX_FACES`) is checked from the file's header before trimesh
builds anything, for a mesh given directly and for one named by a scene file, and over the
whole scene file.
"""

from __future__ import annotations

import resource
import time
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.cli import main
from spectrinsic.errors import SceneError
from spectrinsic.scenes.sources import load_scene_file

#: One face over the documented limit (the number FORMAT.md and the message state).
OVER = 250_001


def _ply(path: Path, n_faces: int, *, declared: int | None = None) -> Path:
    """A binary PLY of a unit triangle repeated *n_faces* times (its header may declare more)."""
    header = (
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\n"
        f"element face {declared or n_faces}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    faces = np.zeros(n_faces, dtype=[("n", "u1"), ("i", "<i4", (3,))])
    faces["n"], faces["i"] = 3, (0, 1, 2)
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype="<f4")
    path.write_bytes(header.encode("ascii") + vertices.tobytes() + faces.tobytes())
    return path


def test_a_mesh_over_the_face_limit_is_refused_before_loading(tmp_path):
    ply = _ply(tmp_path / "big.ply", OVER)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.perf_counter()
    with pytest.raises(SceneError, match=r"big\.ply.*250,001 faces.*250,000 faces"):
        load_scene_file(ply, default_spectrum="flat:0.5")
    assert time.perf_counter() - start < 5  # refused from the header, nothing built
    growth_mib = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - peak) / 1024
    assert growth_mib < 200, growth_mib


def test_a_million_face_header_is_one_line_on_the_command_line(tmp_path, capsys):
    ply = _ply(tmp_path / "million.ply", 1, declared=1_000_000)
    assert main(["render", str(ply), "--out", str(tmp_path / "o"), "-q"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "1,000,000 faces" in err and "million.ply" in err, err
    assert not (tmp_path / "o").exists()


def test_a_scene_file_naming_a_mesh_over_the_limit_is_refused(tmp_path):
    _ply(tmp_path / "big.ply", 1, declared=OVER)
    scene = tmp_path / "s.yaml"
    scene.write_text(
        "name: s\nmaterials: {grey: 'flat:0.5'}\n"
        "meshes:\n  - {name: m, file: big.ply, material: grey}\n"
        "lights:\n  - {kind: point, spectrum: 'cie:D65', power: 4, position: [0, 0, 2]}\n"
        "camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 16, height: 16}\n"
    )
    with pytest.raises(SceneError, match=r"big\.ply.*250,000 faces"):
        load_scene_file(scene)


def test_a_scene_file_whose_meshes_together_pass_the_limit_is_refused(tmp_path):
    _ply(tmp_path / "half.ply", OVER // 2 + 1)
    scene = tmp_path / "s.yaml"
    scene.write_text(
        "name: s\nmaterials: {grey: 'flat:0.5'}\nmeshes:\n"
        "  - {name: a, file: half.ply, material: grey}\n"
        "  - {name: b, file: half.ply, material: grey}\n"
        "lights:\n  - {kind: point, spectrum: 'cie:D65', power: 4, position: [0, 0, 2]}\n"
        "camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 16, height: 16}\n"
    )
    with pytest.raises(SceneError, match=r"half\.ply.*250,002 faces.*at most 250,000"):
        load_scene_file(scene)
