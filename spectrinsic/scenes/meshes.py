"""Mesh files (OBJ, PLY, GLB/GLTF, STL, OFF) as scenes, through trimesh, with a material-name ->
spectrum map.

A mesh file carries geometry and material names but no spectra, lights or camera: every
material name must be in the map (or a default spectrum is given), and the scene gets a framing
camera and one CIE D65 point light above it, so any mesh renders with full ground truth. Only
the named file is read (no textures, no referenced files outside its folder are needed).

A glTF material's ``pbrMetallicRoughness`` factors set the gloss as for ``.blend`` files: metallic
≥ 0.5 makes a metal (``conductor``, Al: the factors name no metal; no spectrum needed), else
roughness < 0.5 a coated diffuse (``plastic``, η = 1.5); GGX α = roughness². Absent factors
count as matte (not glTF's default of 1), so files without them import as before. With
``colours_from_asset=True`` (``--colours-from-asset``), a material not in the map takes its
``baseColorFactor`` as an ``rgb:`` reflectance if the file states one
(:mod:`spectrinsic.scenes.gltf_colours`); without it an unmapped material is an error, as for
``.blend`` files. Textures and every other field are ignored.
"""

from __future__ import annotations

import json
import math
import os
import struct
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError
from .budget import MAX_FACES, MAX_VERTICES, SceneBudget
from .gltf_colours import gltf_base_colours
from .materials import METAL_SPECTRUM
from .model import Camera, Light, Material, Mesh, Scene
from .validate import validate_scene

__all__ = [
    "MESH_SUFFIXES",
    "MAX_VERTICES",
    "MAX_FACES",
    "mesh_counts",
    "check_mesh_size",
    "load_mesh_scene",
]

MESH_SUFFIXES = (".obj", ".ply", ".glb", ".gltf", ".stl", ".off")
#: Largest glTF JSON chunk read to count the accessors (the geometry itself is binary).
_GLTF_JSON_MAX = 64 * 2**20
#: Irradiance (relative units) at the model's centre from the default light.
_IRRADIANCE = math.pi


def _ply_counts(head: bytes) -> tuple[int, int]:
    """Vertex and face counts from a PLY header (ASCII even in binary PLY files)."""
    counts = {"vertex": 0, "face": 0}
    for line in head.split(b"end_header", 1)[0].splitlines():
        parts = line.split()
        if (
            len(parts) == 3
            and parts[0] == b"element"
            and parts[1].decode("ascii", "replace") in counts
        ):
            counts[parts[1].decode("ascii")] = int(parts[2])
    return counts["vertex"], counts["face"]


def _text_counts(path: Path, vertex: bytes, face: bytes) -> tuple[int, int]:
    """Lines starting with *vertex* / *face*, streamed (no more than one line in memory)."""
    n_v = n_f = 0
    with path.open("rb") as fh:
        for line in fh:
            stripped = line.lstrip()
            n_v += stripped.startswith(vertex)
            n_f += stripped.startswith(face)
    return n_v, n_f


def _accessor_count(accessors: list[Any], index: Any) -> int:
    if (
        isinstance(index, int)
        and 0 <= index < len(accessors)
        and isinstance(accessors[index], dict)
    ):
        count = accessors[index].get("count", 0)
        return count if isinstance(count, int) and count > 0 else 0
    return 0


def _gltf_counts(document: dict[str, Any]) -> tuple[int, int]:
    """``(vertices, faces)`` a glTF document declares, from its accessors' ``count`` (indices / 3,
    or positions / 3 without indices), each mesh counted once per node that places it (trimesh
    builds one copy per node); a file with no nodes counts each mesh once."""
    accessors = document.get("accessors") or []
    per_mesh = []
    for mesh in document.get("meshes") or []:
        n_v = n_f = 0
        for primitive in (mesh.get("primitives") or []) if isinstance(mesh, dict) else []:
            positions = _accessor_count(
                accessors, (primitive.get("attributes") or {}).get("POSITION")
            )
            indices = _accessor_count(accessors, primitive.get("indices"))
            n_v += positions
            n_f += (indices if "indices" in primitive else positions) // 3
        per_mesh.append((n_v, n_f))
    nodes = [n for n in document.get("nodes") or [] if isinstance(n, dict) and "mesh" in n]
    uses = [
        n["mesh"] for n in nodes if isinstance(n["mesh"], int) and 0 <= n["mesh"] < len(per_mesh)
    ]
    placed = [per_mesh[i] for i in uses] if nodes else per_mesh
    return sum(v for v, _ in placed), sum(f for _, f in placed)


def mesh_counts(path: Path) -> tuple[int, int]:
    """``(vertices, faces)`` a mesh file declares, read from its header (PLY, OFF, binary
    STL, glTF/GLB accessors) or counted line by line (OBJ, ASCII STL) without building the
    mesh. Malformed headers count as 0: trimesh reports them when it reads the file."""

    suffix = path.suffix.lower()
    with path.open("rb") as fh:
        head = fh.read(1 << 16)
    try:
        if suffix == ".ply":
            return _ply_counts(head)
        if suffix == ".off":
            words = b" ".join(line.split(b"#", 1)[0] for line in head.splitlines()).split()
            return (
                (int(words[1]), int(words[2]))
                if words[:1] == [b"OFF"]
                else (int(words[0]), int(words[1]))
            )
        if suffix == ".stl" and not head.lstrip().startswith(b"solid"):
            faces = struct.unpack("<I", head[80:84])[0]
            return 3 * faces, faces
        if suffix == ".stl":
            return _text_counts(path, b"vertex", b"facet")
        if suffix == ".obj":
            return _text_counts(path, b"v ", b"f ")
        if suffix == ".glb":
            length = struct.unpack("<I", head[12:16])[0]
            return _gltf_counts(json.loads(_glb_json(path, length)))
        if suffix == ".gltf":
            return _gltf_counts(json.loads(path.read_bytes()))
    except (ValueError, IndexError, struct.error, AttributeError, TypeError, RecursionError):
        pass
    return 0, 0


def _glb_json(path: Path, length: int) -> bytes:
    """The JSON chunk of a GLB file (its first chunk, *length* bytes after the 20-byte head)."""
    if not 0 < length <= _GLTF_JSON_MAX:
        raise ValueError(f"JSON chunk of {length} bytes")
    with path.open("rb") as fh:
        fh.seek(20)
        return fh.read(length)


def check_mesh_size(path: Path, budget: SceneBudget | None = None) -> None:
    """Charge what the mesh file declares to *budget* (a budget of its own if ``None``), before
    it is loaded: more than :data:`MAX_VERTICES` vertices or :data:`MAX_FACES` faces in the
    scene is refused in one line naming the file and the count."""
    n_v, n_f = mesh_counts(path)
    budget = SceneBudget(str(path)) if budget is None else budget
    budget.charge(f"{path.name!r} ({n_v:,} vertices, {n_f:,} faces)", faces=n_f, vertices=n_v)


def _pbr_gloss(material: Any) -> dict[str, Any]:
    """Gloss fields of :class:`Material` from a trimesh PBR material (module docstring)."""
    metallic = getattr(material, "metallicFactor", None)
    roughness = getattr(material, "roughnessFactor", None)
    alpha = min(max(float(roughness), 0.0), 1.0) ** 2 if roughness is not None else 1.0
    if metallic is not None and float(metallic) >= 0.5:
        return {"kind": "conductor", "metal": "Al", "roughness": alpha}
    if roughness is not None and float(roughness) < 0.5:
        return {"kind": "plastic", "roughness": alpha}
    return {}


def _geometries(path: Path) -> list[tuple[str, str, np.ndarray, np.ndarray, dict[str, Any]]]:
    """``(geometry name, material name, vertices, faces, gloss)`` of every triangle mesh in the
    file, in world space, sorted by geometry name (file order is not stable across formats)."""
    import trimesh

    check_mesh_size(path)
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
        pbr = getattr(geom.visual, "material", None)
        material = getattr(pbr, "name", None) or str(key)
        out.append((str(node), str(material), verts, faces, _pbr_gloss(pbr)))
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
    camera = Camera(
        origin=tuple(float(x) for x in origin),  # type: ignore[arg-type]
        target=tuple(float(x) for x in centre),  # type: ignore[arg-type]
        fov_deg=fov,
        width=width,
        height=height,
    )
    d2 = float(np.sum((light_pos - centre) ** 2))
    light = Light(
        kind="point",
        spectrum="cie:D65",
        power=_IRRADIANCE * d2,
        position=tuple(float(x) for x in light_pos),  # type: ignore[arg-type]
    )
    return camera, light


def load_mesh_scene(
    path: str | os.PathLike[str],
    *,
    materials: Mapping[str, str],
    width: int,
    height: int,
    default_spectrum: str | None = None,
    data_dir: str | None = None,
    colours_from_asset: bool = False,
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
    colours_from_asset
        Give glTF materials not in *materials* their ``baseColorFactor`` as an ``rgb:``
        reflectance before *default_spectrum* (module docstring).

    Raises
    ------
    SceneError
        One line naming the file and the unmapped material, or an unreadable file.
    """
    path = Path(path)
    geoms = _geometries(path)
    colours = gltf_base_colours(path) if colours_from_asset else {}
    table: dict[str, Material] = {}  # matte materials keep their spectrum's name
    meshes = []
    for i, (node, material, verts, faces, gloss) in enumerate(geoms):
        spectrum = (
            METAL_SPECTRUM
            if gloss.get("kind") == "conductor"
            else materials.get(material, colours.get(material, default_spectrum))
        )
        if spectrum is None:
            known = sorted({g[1] for g in geoms})
            raise SceneError(
                f"{path}: material {material!r} is not in the material map; the file's "
                f"materials are {known}"
            )
        name = f"{spectrum} ({material})" if gloss else spectrum
        table.setdefault(name, Material(name=name, spectrum=spectrum, **gloss))
        meshes.append(
            Mesh(
                name=f"{node}",
                vertices=verts,
                faces=faces,
                face_materials=np.full(len(faces), list(table).index(name), dtype=np.int64),
                object_id=i,
            )
        )
    camera, light = _frame(np.concatenate([m.vertices for m in meshes]), width, height)
    scene = Scene(
        name=path.stem,
        meshes=tuple(meshes),
        materials=tuple(table.values()),
        lights=(light,),
        camera=camera,
        metadata={"source": path.name},
    )
    return validate_scene(scene, source=str(path), data_dir=data_dir)
