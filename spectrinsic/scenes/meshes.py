"""Mesh files (OBJ, PLY, GLB/GLTF, STL, OFF) as scenes, through trimesh, with a material-name ->
spectrum map.

A mesh file carries geometry and material names but no spectra, lights or camera: every
material name must be in the map (or a default spectrum is given), and the scene gets a framing
camera and one CIE D65 point light above it, so any mesh renders with full ground truth. Only
the named file and the files it names inside its folder (glTF buffers and images, OBJ ``mtllib``
files and ``map_Kd`` images) are read.

A glTF material's ``pbrMetallicRoughness`` factors set the gloss as for ``.blend`` files: metallic
≥ 0.5 makes a metal (``conductor``, Al: the factors name no metal; no spectrum needed), else
roughness < 0.5 a coated diffuse (``plastic``, η = 1.5); GGX α = roughness². Absent factors
count as matte (not glTF's default of 1), so files without them import as before. A material
with ``KHR_materials_transmission`` factor 1 is glass, tinted by its ``baseColorFactor``
(:mod:`~spectrinsic.scenes.gltf_glass`; a partial factor is refused in one line).

Colours from the asset (``colours_from_asset=True``, the default; ``--no-colours-from-asset``
turns it off): a material not in the map takes the colour its file states, a glTF
``baseColorFactor`` or MTL ``Kd`` as an ``rgb:`` reflectance, or a glTF ``baseColorTexture`` /
MTL ``map_Kd`` image as an exact spectral texture over the 8 RGB-cube corner reflectances,
mapped by the mesh's own texture coordinates (:mod:`spectrinsic.scenes.gltf_colours`,
:mod:`spectrinsic.scenes.mtl_colours`, :mod:`spectrinsic.scenes.image_textures`). A material
with neither a colour nor a mapping (nor a default spectrum) is an error naming the options.
A textured material must be matte (a glossy one is refused: its basis would not be diffuse).
A glTF material's ``alphaMode`` (``MASK``, ``BLEND``) and ``normalTexture``, and an MTL
material's ``d``/``map_d``, become the mesh's opacity mask and normal map whatever the colours
(:mod:`spectrinsic.scenes.gltf_maps`, :mod:`spectrinsic.scenes.mtl_maps`).
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError
from .budget import MAX_FACES, MAX_VERTICES
from .gltf_buffers import check_gltf_buffers
from .gltf_colours import GLTF_SUFFIXES, gltf_colours
from .gltf_glass import gltf_glass
from .gltf_maps import gltf_maps, warn_mirrored_uv
from .image_textures import AssetColour, ImageTexture, corner_spectra
from .materials import METAL_SPECTRUM
from .mesh_counts import check_mesh_size
from .model import NON_DIFFUSE_KINDS, Camera, Light, Material, Mesh, Scene
from .mtl_colours import mtl_colours
from .mtl_maps import mtl_maps
from .semantic import SemanticMap, classify
from .surface_maps import MeshMaps
from .textures import Texture, make_image_texture
from .validate import validate_scene

__all__ = [
    "MESH_SUFFIXES",
    "MAX_VERTICES",
    "MAX_FACES",
    "load_mesh_scene",
]

MESH_SUFFIXES = (".obj", ".ply", ".glb", ".gltf", ".stl", ".off")
#: Irradiance (relative units) at the model's centre from the default light.
_IRRADIANCE = math.pi


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


#: The in-memory material library that names an OBJ's ``usemtl`` materials when it has none.
_USEMTL_LIBRARY = "__spectrinsic_usemtl__.mtl"


def _usemtl_names(text: str) -> list[str]:
    """An OBJ's ``usemtl`` names in order of first use, when it names no ``mtllib`` (trimesh
    drops the names of materials no library defines and calls the parts ``<file>_1``...)."""
    names: list[str] = []
    for line in text.splitlines():
        words = line.split(maxsplit=1)
        if words[:1] == ["mtllib"]:
            return []
        if words[:1] == ["usemtl"] and len(words) == 2 and words[1].strip() not in names:
            names.append(words[1].strip())
    return names


def _load_mesh_file(path: Path) -> Any:
    """*path* as a trimesh scene; an OBJ whose ``usemtl`` materials no library defines is read
    with an in-memory library of those names (``newmtl NAME`` each, no colour), so its parts
    keep the names the file gives them, which ``--material-map`` then maps."""
    import trimesh
    from trimesh.resolvers import FilePathResolver

    names = (
        _usemtl_names(path.read_text(encoding="utf-8", errors="replace"))
        if (path.suffix.lower() == ".obj")
        else []
    )
    if not names:
        return trimesh.load(str(path), force="scene", process=False)
    library = "".join(f"newmtl {name}\n" for name in names).encode()

    class _Resolver(FilePathResolver):  # type: ignore[misc]
        def get(self, name: str) -> bytes:
            return library if name == _USEMTL_LIBRARY else bytes(super().get(name))

    text = f"mtllib {_USEMTL_LIBRARY}\n".encode() + path.read_bytes()
    return trimesh.load(
        io.BytesIO(text),
        file_type="obj",
        force="scene",
        process=False,
        resolver=_Resolver(str(path)),
    )


_Geometry = tuple[str, str, np.ndarray, np.ndarray, dict[str, Any], "np.ndarray | None"]


def _geometries(path: Path) -> list[_Geometry]:
    """``(geometry name, material name, vertices, faces, gloss, uv)`` of every triangle mesh in
    the file, in world space, sorted by geometry name (file order is not stable across formats);
    ``uv`` ``(F, 3, 2)`` are the face corners' texture coordinates (v up), ``None`` without."""

    check_mesh_size(path)
    if path.suffix.lower() in GLTF_SUFFIXES:  # trimesh reads a short buffer without complaint
        check_gltf_buffers(path)
    try:
        loaded: Any = _load_mesh_file(path)
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
        uv = getattr(geom.visual, "uv", None)
        corner_uv = None if uv is None or len(uv) != len(verts) else np.asarray(uv, float)[faces]
        out.append((str(node), str(material), verts, faces, _pbr_gloss(pbr), corner_uv))
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


def _asset_colours(path: Path) -> dict[str, AssetColour]:
    return gltf_colours(path) if path.suffix.lower() in GLTF_SUFFIXES else mtl_colours(path)


def _mesh_maps(maps: MeshMaps | None, uv: np.ndarray | None, where: str) -> MeshMaps | None:
    """*maps* of a material on a mesh's faces with texture coordinates *uv*."""
    if maps is None:
        return None
    if uv is None:
        raise SceneError(
            f"{where}: its material has a mask or normal texture but the mesh has no uv"
        )
    maps = replace(maps, uv=uv)
    warn_mirrored_uv(maps, where)
    return maps


def _unmapped(path: Path, material: str, geoms: list[_Geometry]) -> SceneError:
    known = sorted({g[1] for g in geoms})
    return SceneError(
        f"{path}: material {material!r} is not in the material map and the file gives it no "
        f"colour; the file's materials are {known} (use --material-map or --default-spectrum; "
        "--colours-from-asset reads the colours the file states)"
    )


class _Table:
    """The scene's materials by name (matte materials keep their spectrum's name)."""

    def __init__(self) -> None:
        self.table: dict[str, Material] = {}

    def index(self, name: str, spectrum: str, gloss: dict[str, Any]) -> int:
        self.table.setdefault(name, Material(name=name, spectrum=spectrum, **gloss))
        return list(self.table).index(name)

    def texture(self, image: ImageTexture, uv: np.ndarray | None, name: str, where: str) -> Texture:
        """The texture *name* of *image* over the 8 corner materials, on faces with *uv*."""
        if uv is None:
            raise SceneError(f"{where}: material {name!r} has a texture but the mesh has no uv")
        basis = tuple(self.index(s, s, {}) for s in corner_spectra())
        return make_image_texture(name, basis, image, uv)


def load_mesh_scene(
    path: str | os.PathLike[str],
    *,
    materials: Mapping[str, str],
    width: int,
    height: int,
    default_spectrum: str | None = None,
    data_dir: str | None = None,
    colours_from_asset: bool = True,
    semantic: SemanticMap | None = None,
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
        Reflectance of materials neither in *materials* nor coloured by the file; ``None``:
        such a material is an error.
    colours_from_asset
        Give materials not in *materials* the colour or texture the file states (glTF base
        colour, MTL ``Kd``/``map_Kd``) before *default_spectrum* (module docstring).
    semantic
        The names → class map (:mod:`~spectrinsic.scenes.semantic`; None: the default) each
        mesh's class comes from: its node's name, then the file's name of its material.

    Raises
    ------
    SceneError
        One line naming the file and the unmapped material, or an unreadable file.
    """
    path = Path(path)
    geoms = _geometries(path)
    colours = _asset_colours(path) if colours_from_asset else {}
    surface_maps = gltf_maps(path) or mtl_maps(path)  # masks are geometry: whatever the colours
    table = _Table()
    meshes = []
    glass = gltf_glass(path)
    for i, (node, material, verts, faces, gloss, uv) in enumerate(geoms):
        gloss = glass.get(material, gloss)
        colour = None if material in materials or material in glass else colours.get(material)
        texture = None
        if gloss.get("kind") in NON_DIFFUSE_KINDS:
            spectrum: str | None = METAL_SPECTRUM
        elif colour is not None and colour.image is not None:
            if gloss:
                raise SceneError(
                    f"{path}: material {material!r} is textured and glossy; "
                    "expected a matte textured material (or map it with --material-map)"
                )
            texture = table.texture(colour.image, uv, material, f"{path}: mesh {node!r}")
            spectrum = None
        else:
            spectrum = materials.get(material, colour.spectrum if colour else default_spectrum)
            if spectrum is None:
                raise _unmapped(path, material, geoms)
        face = (
            texture.basis[0]
            if texture is not None
            else table.index(f"{spectrum} ({material})" if gloss else spectrum, spectrum, gloss)  # type: ignore[arg-type]
        )
        meshes.append(
            Mesh(
                name=f"{node}",
                vertices=verts,
                faces=faces,
                face_materials=np.full(len(faces), face, dtype=np.int64),
                object_id=i,
                texture=texture,
                semantic=classify([f"{node}", material], semantic),
                maps=_mesh_maps(surface_maps.get(material), uv, f"{path}: mesh {node!r}"),
            )
        )
    points = np.concatenate([m.vertices for m in meshes])
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if bad.size:  # before the framing, whose sums would only spread the NaN (and warn)
        raise SceneError(
            f"{path}: {bad.size} vertices are NaN or infinite (first: vertex {int(bad[0])} "
            "over the file's meshes); expected finite coordinates"
        )
    camera, light = _frame(points, width, height)
    scene = Scene(
        name=path.stem,
        meshes=tuple(meshes),
        materials=tuple(table.table.values()),
        lights=(light,),
        camera=camera,
        metadata={"source": path.name},
    )
    return validate_scene(scene, source=str(path), data_dir=data_dir)
