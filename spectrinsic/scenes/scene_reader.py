"""Reading YAML scene files (:mod:`spectrinsic.scenes.scene_format`) into
:class:`~spectrinsic.scenes.model.Scene` records.

Files are read with a ``yaml.SafeLoader`` (no Python object tags) bounded in size, nesting and
alias expansion, rejecting duplicate keys (:mod:`spectrinsic.scenes.yaml_limits`). Problems are
one-line :class:`~spectrinsic.errors.SceneError` ``"<file>: <field>: <problem>"``; a file with
several mistakes reports all of them in that one line, separated by ``;``.

Paths are relative to the YAML file's folder; absolute paths and paths leading out of that
folder (``..``, symbolic links) are rejected, so a scene folder can be shared and loaded
without reading anything outside it. Loaded scenes are checked with
:func:`spectrinsic.scenes.validate.validate_scene`.
"""

# long module: one format's reader (the YAML scene file), every section's parser reporting
# through one _Doc so a file's problems come in one line

from __future__ import annotations

import os
import re
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError, did_you_mean, with_article
from .budget import SceneBudget
from .materials import TexturedMaterial, parse_material
from .mesh_counts import check_mesh_size
from .model import (
    LIGHT_DEFAULTED,
    LIGHT_FIELDS,
    LIGHT_KINDS,
    LIGHT_PLACEMENT,
    Camera,
    Light,
    Material,
    Mesh,
    Scene,
    unknown_light_kind,
)
from .parts import Part, moved
from .problems import Problems
from .scene_format import FORMAT_VERSION, MESH_SUFFIXES
from .spectrum_refs import resolve_spectrum_refs
from .textures import Texture
from .validate import validate_scene
from .yaml_limits import load_yaml_file

__all__ = ["load_scene"]

_TOP = ("format", "name", "materials", "meshes", "lights", "camera", "metadata")
_MESH = tuple("name object_id file transform vertices faces material face_materials".split())
_TRANSFORM = ("scale", "rotate_deg", "translate")
_LIGHT = tuple(f.name for f in fields(Light))
_CAMERA = tuple(f.name for f in fields(Camera))


class _Doc:
    """Typed access to a parsed YAML document, with errors naming the file and field."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.budget = SceneBudget(source)  # faces, vertices, texels of the whole scene

    def fail(self, field: str, problem: str) -> SceneError:
        return SceneError(f"{self.source}: {field}: {problem}")

    def mapping(
        self, value: Any, field: str, allowed: tuple[str, ...], required: tuple[str, ...] = ()
    ) -> dict:
        if not isinstance(value, dict):
            raise self.fail(field or "top level", f"expected a mapping, got {type(value).__name__}")
        problems = Problems(self.source)
        for key in value:
            if key not in allowed:
                problems.get(
                    self._raise,
                    f"{field}.{key}" if field else str(key),
                    f"unknown key; expected one of {', '.join(allowed)}"
                    + did_you_mean(str(key), allowed),
                )
        for key in required:
            if key not in value:
                problems.get(
                    self._raise, f"{field}.{key}" if field else key, "missing required key"
                )
        problems.raise_if_any()
        return value

    def _raise(self, field: str, problem: str) -> None:
        raise self.fail(field, problem)

    def string(self, value: Any, field: str) -> str:
        if not isinstance(value, str) or not value.strip():
            raise self.fail(field, f"expected a non-empty string, got {value!r}")
        return value

    def number(self, value: Any, field: str) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(field, f"expected a number, got {type(value).__name__} {value!r}")
        return float(value)

    def integer(self, value: Any, field: str, minimum: int = 0) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            raise self.fail(field, f"expected an integer >= {minimum}, got {value!r}")
        return value

    def vector(self, value: Any, field: str, n: int = 3) -> tuple[float, ...]:
        if not isinstance(value, list) or len(value) != n:
            raise self.fail(field, f"expected a list of {n} numbers, got {value!r}")
        return tuple(self.number(v, f"{field}[{i}]") for i, v in enumerate(value))

    def array(self, value: Any, field: str, dtype: type, columns: int) -> np.ndarray:
        if not isinstance(value, list) or not value:
            raise self.fail(field, f"expected a non-empty list of [{columns} numbers] rows")
        for i, row in enumerate(value):
            if not isinstance(row, list) or len(row) != columns:
                raise self.fail(
                    f"{field}[{i}]", f"expected a list of {columns} numbers, got {row!r}"
                )
            for j, x in enumerate(row):
                ok = isinstance(x, int) if dtype is np.int64 else isinstance(x, (int, float))
                if isinstance(x, bool) or not ok:
                    kind = "an integer" if dtype is np.int64 else "a number"
                    raise self.fail(f"{field}[{i}][{j}]", f"expected {kind}, got {x!r}")
                if dtype is np.int64 and not -(2**31) <= x < 2**31:  # int32 in the renderer
                    raise self.fail(f"{field}[{i}][{j}]", f"index {x} is beyond 32-bit integers")
        try:
            return np.asarray(value, dtype=dtype)
        except OverflowError:  # an integer too large for a float64
            raise self.fail(field, "holds a number too large for a 64-bit float") from None


def _resolve(doc: _Doc, base: Path, value: Any, field: str) -> Path:
    """*value* as a path inside *base* (the scene's folder), or a one-line error."""
    rel = doc.string(value, field)
    if Path(rel).is_absolute() or re.match(r"^[A-Za-z]:[\\/]", rel):
        raise doc.fail(
            field, f"absolute path {rel!r} not allowed; give a path relative to the scene's folder"
        )
    root = base.resolve()
    path = (root / rel).resolve()
    if not path.is_relative_to(root):
        raise doc.fail(field, f"path {rel!r} leads outside the scene's folder {str(root)!r}")
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise doc.fail(
            field,
            f"unsupported mesh file type {path.suffix!r}; expected {', '.join(MESH_SUFFIXES)}",
        )
    if not path.is_file():
        raise doc.fail(field, f"mesh file {rel!r} not found in {str(root)!r}")
    return path


def _read_mesh_file(doc: _Doc, path: Path, field: str) -> tuple[np.ndarray, np.ndarray]:
    import trimesh

    check_mesh_size(path, doc.budget)  # from its header, before trimesh builds it
    try:
        # process=False keeps vertex and face order, so face_materials runs stay valid
        mesh = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types for corrupt files
        raise doc.fail(
            field, f"cannot read {path.name!r} as a mesh ({type(exc).__name__}: {exc})"
        ) from exc
    faces = np.asarray(getattr(mesh, "faces", np.empty((0, 3))), dtype=np.int64)
    if faces.ndim != 2 or len(faces) == 0:
        raise doc.fail(field, f"{path.name!r} holds no triangles")
    return np.asarray(getattr(mesh, "vertices"), dtype=np.float64), faces  # noqa: B009


def _face_materials(
    doc: _Doc, entry: dict, field: str, n_faces: int, materials: dict[str, int] | None
) -> np.ndarray:
    def index(name: Any, where: str) -> int:
        name = doc.string(name, where)
        if materials is None:
            return 0  # the materials themselves are reported broken
        if name not in materials:
            raise doc.fail(
                where,
                f"unknown material {name!r}; expected one of {', '.join(materials)}"
                + did_you_mean(name, materials),
            )
        return materials[name]

    if ("material" in entry) == ("face_materials" in entry):
        raise doc.fail(
            field, "give exactly one of 'material' (every face) or 'face_materials' (runs)"
        )
    if "material" in entry:
        return np.full(n_faces, index(entry["material"], f"{field}.material"), dtype=np.int64)
    runs = entry["face_materials"]
    where = f"{field}.face_materials"
    if not isinstance(runs, list) or not runs:
        raise doc.fail(
            where, "expected a list of [material, count] runs or one material name per face"
        )
    if all(isinstance(r, str) for r in runs):
        out = np.array([index(r, f"{where}[{i}]") for i, r in enumerate(runs)], dtype=np.int64)
    else:
        parts = []
        for i, run in enumerate(runs):
            if not isinstance(run, list) or len(run) != 2:
                raise doc.fail(f"{where}[{i}]", f"expected a [material, count] pair, got {run!r}")
            parts.append(
                np.full(
                    doc.integer(run[1], f"{where}[{i}][1]", 1),
                    index(run[0], f"{where}[{i}][0]"),
                    dtype=np.int64,
                )
            )
        out = np.concatenate(parts)
    if len(out) != n_faces:
        raise doc.fail(where, f"covers {len(out)} faces but the mesh has {n_faces}")
    return out


def _mesh(doc: _Doc, base: Path, entry: Any, i: int, materials: dict[str, int] | None) -> Mesh:
    field = f"meshes[{i}]"
    entry = doc.mapping(entry, field, _MESH, ("name",))
    name = doc.string(entry["name"], f"{field}.name")
    if ("file" in entry) == ("vertices" in entry or "faces" in entry):
        raise doc.fail(field, "give either 'file' or inline 'vertices' and 'faces'")
    if "file" in entry:
        path = _resolve(doc, base, entry["file"], f"{field}.file")
        vertices, faces = _read_mesh_file(doc, path, f"{field}.file")
        if "transform" in entry:
            t = doc.mapping(entry["transform"], f"{field}.transform", _TRANSFORM)
            scale = t.get("scale", 1.0)
            scale = (
                doc.vector(scale, f"{field}.transform.scale")
                if isinstance(scale, list)
                else doc.number(scale, f"{field}.transform.scale")
            )
            if np.any(np.asarray(scale) <= 0):
                raise doc.fail(f"{field}.transform.scale", f"must be > 0, got {scale!r}")
            part = moved(
                Part(vertices, faces, np.zeros(len(faces), dtype=np.int64), ("",)),
                scale=scale,
                rotate_deg=doc.vector(
                    t.get("rotate_deg", [0, 0, 0]), f"{field}.transform.rotate_deg"
                ),
                translate=doc.vector(t.get("translate", [0, 0, 0]), f"{field}.transform.translate"),
            )
            vertices = part.vertices
    else:
        if "transform" in entry:
            raise doc.fail(f"{field}.transform", "only meshes read from a file take a transform")
        for key in ("vertices", "faces"):
            if key not in entry:
                raise doc.fail(
                    f"{field}.{key}",
                    "missing required key (inline geometry needs vertices and faces)",
                )
        # YAML's .nan reaches here as a float: validation reports it with the mesh's name
        vertices = doc.array(entry["vertices"], f"{field}.vertices", np.float64, 3)
        faces = doc.array(entry["faces"], f"{field}.faces", np.int64, 3)
        doc.budget.charge(f"{field} (inline)", faces=len(faces), vertices=len(vertices))
    object_id = doc.integer(entry.get("object_id", i), f"{field}.object_id")
    face_materials = _face_materials(doc, entry, field, len(faces), materials)
    return Mesh(
        name=name,
        vertices=vertices,
        faces=faces,
        face_materials=face_materials,
        object_id=object_id,
    )


def _light(doc: _Doc, entry: Any, i: int) -> Light:
    field = f"lights[{i}]"
    entry = doc.mapping(entry, field, _LIGHT, ("kind", "spectrum", "power"))
    kind = doc.string(entry["kind"], f"{field}.kind")
    if kind not in LIGHT_KINDS:
        raise doc.fail(f"{field}.kind", unknown_light_kind(kind))
    needs = [f for f in LIGHT_FIELDS[kind] if f not in LIGHT_DEFAULTED]
    for key in (k for k in LIGHT_PLACEMENT if k in entry and k not in LIGHT_FIELDS[kind]):
        uses = ", ".join(LIGHT_FIELDS[kind])
        raise doc.fail(f"{field}.{key}", f"{with_article(kind)} light has no {key} (uses {uses})")
    for key in needs:
        if key not in entry:
            raise doc.fail(
                f"{field}.{key}", f"missing; {with_article(kind)} light needs {' and '.join(needs)}"
            )
    kw: dict[str, Any] = {
        "kind": kind,
        "spectrum": doc.string(entry["spectrum"], f"{field}.spectrum"),
        "power": doc.number(entry["power"], f"{field}.power"),
    }
    for key in ("position", "direction"):
        if key in entry:
            kw[key] = doc.vector(entry[key], f"{field}.{key}")
    if "size" in entry:
        kw["size"] = doc.vector(entry["size"], f"{field}.size", 2)
    if "cutoff_deg" in entry:
        kw["cutoff_deg"] = doc.number(entry["cutoff_deg"], f"{field}.cutoff_deg")
    if "radius" in entry:
        kw["radius"] = doc.number(entry["radius"], f"{field}.radius")
    # an unnamed light is named by its spectrum, so labels read "planck:2800K 60 %"
    kw["name"] = doc.string(entry["name"], f"{field}.name") if "name" in entry else kw["spectrum"]
    return Light(**kw)


def _camera(doc: _Doc, entry: Any) -> Camera:
    entry = doc.mapping(entry, "camera", _CAMERA, ("origin", "target", "width", "height"))
    kw: dict[str, Any] = {
        k: doc.vector(entry[k], f"camera.{k}") for k in ("origin", "target", "up") if k in entry
    }
    if "fov_deg" in entry:
        kw["fov_deg"] = doc.number(entry["fov_deg"], "camera.fov_deg")
    kw["width"] = doc.integer(entry["width"], "camera.width", 1)
    kw["height"] = doc.integer(entry["height"], "camera.height", 1)
    if "name" in entry:
        kw["name"] = doc.string(entry["name"], "camera.name")
    return Camera(**kw)


def _scene_from_yaml_data(
    data: Any, *, base: str | os.PathLike[str], source: str = "<scene>"
) -> Scene:
    """Build a scene from a scene file's parsed YAML *data*; mesh files are resolved inside
    folder *base*. Only the structure and types are checked here; see :func:`load_scene` for
    validation (``scene.json`` is read by :func:`~spectrinsic.scenes.model.scene_from_dict`)."""
    doc = _Doc(source)
    problems = Problems(source)
    if not isinstance(data, dict):
        raise doc.fail("top level", f"expected a mapping, got {type(data).__name__}")
    problems.get(doc.mapping, data, "", _TOP, ("name", "materials", "meshes", "lights", "camera"))
    if data.get("format", FORMAT_VERSION) != FORMAT_VERSION:
        problems.get(
            doc._raise,
            "format",
            f"unsupported format version {data['format']!r}; expected {FORMAT_VERSION}",
        )
    parsed = problems.get(_materials, doc, data.get("materials"))
    materials, textures = (None, {}) if parsed is None else parsed
    # without sound materials, every mesh would also report its material as unknown
    lookup = None if materials is None else {m.name: i for i, m in enumerate(materials)}
    if lookup is not None:
        lookup |= {name: t.basis[0] for name, t in textures.items()}
    meshes = [
        problems.get(
            _textured, doc, problems.get(_mesh, doc, Path(base), m, i, lookup), m, textures
        )
        for i, m in enumerate(problems.get(_entries, doc, data, "meshes") or [])
    ]
    lights = [
        problems.get(_light, doc, x, i)
        for i, x in enumerate(problems.get(_entries, doc, data, "lights") or [])
    ]
    camera = problems.get(_camera, doc, data["camera"]) if "camera" in data else None
    name = problems.get(doc.string, data.get("name"), "name") if "name" in data else None
    metadata = data.get("metadata", {}) or {}
    if not isinstance(metadata, dict):
        problems.get(doc._raise, "metadata", f"expected a mapping, got {type(metadata).__name__}")
    problems.raise_if_any()
    return Scene(
        name=name,  # type: ignore[arg-type]  # None only when a problem was raised above
        meshes=tuple(meshes),  # type: ignore[arg-type]
        materials=materials,  # type: ignore[arg-type]
        lights=tuple(lights),  # type: ignore[arg-type]
        camera=camera,  # type: ignore[arg-type]
        metadata=metadata,
    )


def _materials(doc: _Doc, mats: Any) -> tuple[tuple[Material, ...], dict[str, Texture]]:
    """The materials (a textured entry's basis materials in its place) and the textures."""
    if not isinstance(mats, dict) or not mats:
        raise doc.fail(
            "materials",
            "expected a non-empty mapping of material name -> spectrum name or material",
        )
    out: list[Material] = []
    textures: dict[str, Texture] = {}
    for k, v in mats.items():
        parsed = parse_material(doc.string(k, "materials"), v)
        if isinstance(parsed, str):
            raise doc.fail(f"materials.{k}", parsed)
        if isinstance(parsed, TexturedMaterial):
            tex = parsed.texture
            height, width = tex.weights.shape[:2]
            doc.budget.charge(f"materials.{k} ({width}x{height} texels)", texels=width * height)
            textures[k] = replace(tex, basis=tuple(len(out) + b for b in tex.basis))
            out.extend(parsed.materials)
        else:
            out.append(parsed)
    names = [m.name for m in out]
    if len(set(names)) != len(names) or set(textures) & set(names):
        clash = next(n for n in [*names, *textures] if [*names, *textures].count(n) > 1)
        raise doc.fail(
            f"materials.{clash}",
            "duplicate material name (a textured material "
            "'x' names its basis materials 'x[0]', 'x[1]', ...)",
        )
    return tuple(out), textures


def _textured(
    doc: _Doc, mesh: Mesh | None, entry: Any, textures: dict[str, Texture]
) -> Mesh | None:
    """*mesh* with the texture its ``material`` names, if textured."""
    if mesh is None or not textures or not isinstance(entry, dict):
        return mesh
    runs = entry.get("face_materials")
    named = (
        [r[0] if isinstance(r, list) and r else r for r in runs] if isinstance(runs, list) else []
    )
    if any(isinstance(n, str) and n in textures for n in named):
        raise doc.fail(
            f"mesh {mesh.name!r}.face_materials",
            "a textured material covers a whole mesh: give it as 'material'",
        )
    name = entry.get("material")
    return replace(mesh, texture=textures[name]) if name in textures else mesh


def _entries(doc: _Doc, data: dict, key: str) -> list[Any]:
    if key not in data:
        return []  # reported as a missing required key
    if not isinstance(data[key], list) or not data[key]:
        raise doc.fail(key, f"expected a non-empty list, got {data[key]!r}")
    return data[key]


def load_scene(
    path: str | os.PathLike[str], *, data_dir: str | None = None, validate: bool = True
) -> Scene:
    """Read and validate a YAML scene file.

    Parameters
    ----------
    path
        The ``.yaml`` file; mesh files are looked up in its folder.
    data_dir
        Spectral data directory for spectra that need one (``sfu:...``).
    validate
        Run :func:`~spectrinsic.scenes.validate.validate_scene` (spectra, light placement,
        camera visibility). Structure and types are always checked.

    Raises
    ------
    SceneError
        One line naming the file and the field.
    """
    path = Path(path)
    source = str(path)
    data = resolve_spectrum_refs(load_yaml_file(path), path.parent, source)
    scene = _scene_from_yaml_data(data, base=path.parent, source=source)
    if validate:
        validate_scene(scene, source=source, data_dir=data_dir)
    return scene
