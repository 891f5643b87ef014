"""Writing :class:`~spectrinsic.scenes.model.Scene` records as YAML scene files
(:mod:`spectrinsic.scenes.scene_format`).

:func:`save_scene` writes inline geometry for small meshes and double-precision binary PLY
files (in ``<stem>_meshes/``) for larger ones, so ``load_scene(save_scene(s, p)) == s``
(:func:`spectrinsic.scenes.scene_reader.load_scene`).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import fields
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ..errors import SceneError
from ..file_writes import refuse_link, replacing, write_text_file
from .materials import material_entry, textured_entry
from .model import LIGHT_DEFAULTED, LIGHT_FIELDS, LIGHT_PLACEMENT, Light, Scene, scene_to_dict
from .scene_format import FORMAT_VERSION
from .textures import basis_name

__all__ = ["save_scene", "scene_to_yaml_dict"]


def _write_ply(path: Path, vertices: np.ndarray, faces: np.ndarray) -> None:
    """Binary little-endian PLY with float64 vertices (trimesh's writer rounds to float32)."""
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment written by spectrinsic\n"
        f"element vertex {len(vertices)}\nproperty double x\nproperty double y\nproperty double z\n"
        f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    packed = np.empty(len(faces), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    packed["n"] = 3
    packed["v"] = faces
    with replacing(path) as tmp, tmp.open("wb") as fh:
        fh.write(header.encode("ascii"))
        fh.write(np.ascontiguousarray(vertices, dtype="<f8").tobytes())
        fh.write(packed.tobytes())


def _runs(face_materials: np.ndarray, names: list[str]) -> list[list[Any]]:
    fm = np.asarray(face_materials)
    starts = np.flatnonzero(np.r_[True, fm[1:] != fm[:-1]])
    counts = np.diff(np.r_[starts, len(fm)])
    return [[names[int(fm[s])], int(c)] for s, c in zip(starts, counts, strict=True)]


def _materials(scene: Scene) -> dict[str, Any]:
    """The ``materials:`` mapping: a texture's basis materials (named
    :func:`~spectrinsic.scenes.materials.basis_name`, consecutive) as its one textured entry."""
    textures = {m.texture.basis[0]: m.texture for m in scene.meshes if m.texture is not None}
    covered = {b for t in textures.values() for b in t.basis}
    out: dict[str, Any] = {}
    for i, m in enumerate(scene.materials):
        tex = textures.get(i)
        if tex is not None and tex.image is not None:
            raise SceneError(
                f"scene {scene.name!r}: image texture {tex.name!r} cannot be saved as YAML; "
                "render its asset file instead"
            )
        if tex is not None:
            expected = [basis_name(tex.name, b) for b in range(len(tex.basis))]
            if list(tex.basis) != list(range(i, i + len(tex.basis))) or expected != [
                scene.materials[b].name for b in tex.basis
            ]:
                raise SceneError(
                    f"scene {scene.name!r}: texture {tex.name!r} cannot be saved: its basis "
                    f"materials must be consecutive and named {', '.join(expected)}"
                )
            out[tex.name] = textured_entry(tex, [scene.materials[b].spectrum for b in tex.basis])
        elif i not in covered:
            out[m.name] = material_entry(m)
    return out


def scene_to_yaml_dict(scene: Scene, mesh_files: Mapping[str, str] | None = None) -> dict[str, Any]:
    """The YAML document of *scene*; meshes named in *mesh_files* reference that relative path
    instead of holding inline geometry."""
    names = [m.name for m in scene.materials]
    if len(set(names)) != len(names):
        raise SceneError(
            f"scene {scene.name!r}: materials: names must be unique to be saved, got {names}"
        )
    mesh_files = mesh_files or {}
    meshes = []
    for m in scene.meshes:
        entry: dict[str, Any] = {"name": m.name, "object_id": int(m.object_id)}
        if m.name in mesh_files:
            entry["file"] = mesh_files[m.name]
        else:
            entry["vertices"] = np.asarray(m.vertices, dtype=np.float64).tolist()
            entry["faces"] = np.asarray(m.faces, dtype=np.int64).tolist()
        runs = _runs(m.face_materials, names)
        if m.texture is not None:
            entry["material"] = m.texture.name
        elif len(runs) == 1:
            entry["material"] = runs[0][0]
        else:
            entry["face_materials"] = runs
        meshes.append(entry)
    defaults = Light(kind="point", spectrum="", power=1.0)
    lights = []
    for light in scene.lights:
        entry = {"kind": light.kind, "spectrum": light.spectrum, "power": float(light.power)}
        for f in fields(Light):
            value = getattr(light, f.name)
            # the placement keys its kind uses: always (the reader needs them), others never
            used = f.name in LIGHT_FIELDS[light.kind] and f.name not in LIGHT_DEFAULTED
            unused = f.name in LIGHT_PLACEMENT and f.name not in LIGHT_FIELDS[light.kind]
            changed = value != getattr(defaults, f.name)
            if f.name not in entry and (used or changed) and not unused:
                entry[f.name] = list(map(float, value)) if isinstance(value, tuple) else value
        lights.append(entry)
    cam = scene_to_dict(scene)["camera"]
    doc: dict[str, Any] = {
        "format": FORMAT_VERSION,
        "name": scene.name,
        "materials": _materials(scene),
        "meshes": meshes,
        "lights": lights,
        "camera": cam,
    }
    if scene.metadata:
        doc["metadata"] = scene_to_dict(scene)["metadata"]
    return doc


def _dumper() -> type:
    """A SafeDumper writing rows of numbers (and other scalar lists) on one line each."""

    class Dumper(yaml.SafeDumper):
        pass

    def seq(dumper: yaml.SafeDumper, data: list) -> Any:
        flat = all(not isinstance(x, (list, dict)) for x in data)
        return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flat)

    Dumper.add_representer(list, seq)
    return Dumper


def save_scene(scene: Scene, path: str | os.PathLike[str], *, inline_max_faces: int = 64) -> Path:
    """Write *scene* as YAML at *path*; meshes with more than *inline_max_faces* faces go to
    float64 binary PLY files in ``<stem>_meshes/`` next to it. Returns *path*."""
    path = Path(path)
    refuse_link(path)  # before the mesh folder is made beside it
    folder = path.parent / f"{path.stem}_meshes"
    mesh_files: dict[str, str] = {}
    for i, m in enumerate(scene.meshes):
        if len(m.faces) > inline_max_faces:
            folder.mkdir(parents=True, exist_ok=True)
            fname = f"{i:03d}-{re.sub(r'[^A-Za-z0-9._-]+', '_', m.name)}.ply"
            _write_ply(folder / fname, m.vertices, m.faces)
            mesh_files[m.name] = f"{folder.name}/{fname}"
    doc = scene_to_yaml_dict(scene, mesh_files)
    header = f"# spectrinsic scene (format {FORMAT_VERSION}); see spectrinsic/scenes/FORMAT.md\n"
    text = yaml.dump(
        doc,
        Dumper=_dumper(),
        sort_keys=False,
        default_flow_style=False,
        width=4096,
        allow_unicode=True,
    )
    write_text_file(path, header + text)
    return path
