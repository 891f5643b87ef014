"""Mesh files (OBJ, PLY, GLB/GLTF, STL, OFF) as scenes, through trimesh, with a material-name ->
spectrum map.

A mesh file carries geometry and material names but no spectra, lights or camera: every
material name must be in the map (or a default spectrum is given), and the scene gets a framing
camera and one CIE D65 point light above it, so any mesh renders with full ground truth. Only
the named file is read (no textures, no referenced files outside its folder are needed).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from spectrinsic.errors import SceneError
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene
from spectrinsic.scenes.validate import validate_scene

__all__ = ["MESH_SUFFIXES", "load_mesh_scene"]

MESH_SUFFIXES = (".obj", ".ply", ".glb", ".gltf", ".stl", ".off")
#: Irradiance (relative units) at the model's centre from the default light.
_IRRADIANCE = math.pi


def _geometries(path: Path) -> list[tuple[str, str, np.ndarray, np.ndarray]]:
    """``(geometry name, material name, vertices, faces)`` of every triangle mesh in the file,
    in world space, sorted by geometry name (file order is not stable across formats)."""
    import trimesh

    try:
        loaded: Any = trimesh.load(str(path), force="scene", process=False)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types for corrupt files
        raise SceneError(f"{path}: cannot read it as a mesh ({type(exc).__name__}: {exc})") from exc
    out = []
    for node in sorted(loaded.graph.nodes_geometry):
        matrix, key = loaded.graph[node]
        geom = loaded.geometry[key]
        faces = np.asarray(getattr(geom, "faces", np.empty((0, 3))), dtype=np.int64)
        if faces.ndim != 2 or len(faces) == 0:
            continue
        verts = np.asarray(geom.vertices, dtype=np.float64)
        verts = verts @ np.asarray(matrix)[:3, :3].T + np.asarray(matrix)[:3, 3]
        material = getattr(getattr(geom.visual, "material", None), "name", None) or str(key)
        out.append((str(node), str(material), verts, faces))
    if not out:
        raise SceneError(f"{path}: holds no triangles")
    return out


def _frame(vertices: np.ndarray, width: int, height: int) -> tuple[Camera, Light]:
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    centre, radius = (lo + hi) / 2, max(float(np.linalg.norm(hi - lo)) / 2, 1e-3)
    fov = 40.0
    direction = np.array([0.6, -0.7, 0.45])
    direction /= np.linalg.norm(direction)
    origin = centre + direction * radius / math.sin(math.radians(fov) / 2) * 1.2
    light_pos = centre + np.array([-0.4, -0.6, 1.0]) * 3 * radius
    camera = Camera(origin=tuple(float(x) for x in origin),  # type: ignore[arg-type]
                    target=tuple(float(x) for x in centre),  # type: ignore[arg-type]
                    fov_deg=fov, width=width, height=height)
    d2 = float(np.sum((light_pos - centre) ** 2))
    light = Light(kind="point", spectrum="cie:D65", power=_IRRADIANCE * d2,
                  position=tuple(float(x) for x in light_pos))  # type: ignore[arg-type]
    return camera, light


def load_mesh_scene(
    path: str | os.PathLike[str],
    *,
    materials: Mapping[str, str],
    width: int,
    height: int,
    default_spectrum: str | None = None,
    data_dir: str | None = None,
) -> Scene:
    """Read a mesh file into a validated :class:`~spectrinsic.scenes.model.Scene`.

    Parameters
    ----------
    path
        An ``.obj``, ``.ply``, ``.glb``/``.gltf``, ``.stl`` or ``.off`` file.
    materials
        Material name (OBJ ``usemtl``, glTF material, else the geometry's name) -> reflectance
        spectrum name, e.g. ``{"red_paint": "munsell:5R 4/14"}``.
    width, height
        Image size in pixels of the framing camera.
    default_spectrum
        Reflectance of materials not in *materials*; ``None``: such a material is an error.

    Raises
    ------
    SceneError
        One line naming the file and the unmapped material, or an unreadable file.
    """
    path = Path(path)
    geoms = _geometries(path)
    names: list[str] = []
    meshes = []
    for i, (node, material, verts, faces) in enumerate(geoms):
        spectrum = materials.get(material, default_spectrum)
        if spectrum is None:
            known = sorted({g[1] for g in geoms})
            raise SceneError(f"{path}: material {material!r} is not in the material map; the file's "
                             f"materials are {known}")
        if spectrum not in names:
            names.append(spectrum)
        meshes.append(Mesh(name=f"{node}", vertices=verts, faces=faces,
                           face_materials=np.full(len(faces), names.index(spectrum), dtype=np.int64),
                           object_id=i))
    camera, light = _frame(np.concatenate([m.vertices for m in meshes]), width, height)
    scene = Scene(name=path.stem, meshes=tuple(meshes),
                  materials=tuple(Material(name=n, spectrum=n) for n in names), lights=(light,),
                  camera=camera, metadata={"source": path.name})
    return validate_scene(scene, source=str(path), data_dir=data_dir)
