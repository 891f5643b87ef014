"""Mitsuba XML shapes as triangles, counted before any is built.

Every shape Mitsuba loads: ``obj`` and ``ply`` (read by trimesh, as every mesh file of
spectrinsic), ``serialized`` (``shape_index``; Mitsuba's own loader of that one built-in shape), ``rectangle``, ``cube``,
``disk``, ``sphere`` (``center``, ``radius``) and ``cylinder`` (``p0``, ``p1``, ``radius``;
tessellated, :mod:`~spectrinsic.scenes.mitsuba_parts`), each with its ``to_world`` and
``flip_normals``; ``shapegroup`` and ``instance`` (each instance is a copy of its group's
shapes under the instance's transform). Each shape's triangles are wound so that their normals
face the side Mitsuba's face, under mirroring transforms too (:func:`reversed_winding`).

:func:`occurrences` lists every shape as it appears (an instance's shapes once per instance), and
:func:`check_budget` counts their faces and vertices from file headers and the built-in
shapes' sizes *before* loading any, so one scene holds at most
:data:`~spectrinsic.scenes.meshes.MAX_FACES` faces and
:data:`~spectrinsic.scenes.meshes.MAX_VERTICES` vertices whatever the format, repeated
references counted each time (issue 44).
"""

from __future__ import annotations

import re
import struct
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError
from . import mitsuba_parts as parts
from .budget import SceneBudget
from .mesh_counts import mesh_counts
from .mitsuba_files import confined_file
from .mitsuba_tree import XmlNode, mesh_file, mesh_file_uv

__all__ = [
    "BUILT_IN",
    "FILE_SHAPES",
    "Placed",
    "occurrences",
    "check_budget",
    "triangles",
    "textured_triangles",
    "sphere_radius",
    "KEEP_SIDE",
    "mirrors",
    "reversed_winding",
    "stored_normals",
]

#: Shapes made of triangles here, and shapes read from a file.
BUILT_IN = ("rectangle", "cube", "disk", "sphere", "cylinder")
FILE_SHAPES = ("obj", "ply", "serialized")
#: Shapes whose normals Mitsuba maps by the inverse transpose of their own ``to_world``: a
#: mirroring one leaves them on the same side (:func:`reversed_winding`).
KEEP_SIDE = ("rectangle", "cube", "disk", "cylinder")
_GEOMETRY = {"to_world", "flip_normals", "id"}
_OBJ_NORMAL = re.compile(rb"^[ \t]*vn[ \t]", re.M)
_PARAMS = {
    "obj": {"filename", "face_normals"},
    "ply": {"filename", "face_normals"},
    "serialized": {"filename", "face_normals", "shape_index"},
    "rectangle": set(),
    "cube": set(),
    "disk": set(),
    "sphere": {"center", "radius"},
    "cylinder": {"p0", "p1", "radius"},
}


@dataclass(frozen=True, eq=False)
class Placed:
    """One shape as it appears in the scene: *node*, under the *matrix* of the instances
    around it, named *name* and labelled *where* in messages."""

    node: XmlNode
    matrix: np.ndarray
    name: str
    where: str


def occurrences(root: XmlNode) -> list[Placed]:
    """Every shape of the scene, an instance's shapes once per instance (module docstring)."""
    out: list[Placed] = []
    for i, child in enumerate(root.children):
        if child.kind != "shape" or child.plugin == "shapegroup":
            continue
        where = f"element {i} {child.label()}"
        name = child.id if child.id and not child.id.startswith("_unnamed") else f"shape{i}"
        if child.plugin != "instance":
            out.append(Placed(child, np.eye(4), name, where))
            continue
        groups = [c for c in child.children if c.plugin == "shapegroup"]
        if len(groups) != 1:
            raise SceneError(f"{where}: an instance needs exactly one <ref> to a shapegroup")
        m = _matrix(child)
        for k, shape in enumerate(s for s in groups[0].children if s.kind == "shape"):
            out.append(Placed(shape, m, f"{name}.{k}", f"{where} shape {k} {shape.label()}"))
    return out


def _matrix(node: XmlNode) -> np.ndarray:
    m = node.props.get("to_world")
    return np.eye(4) if m is None else np.asarray(m, float)


def _check_params(p: Placed) -> None:
    plugin = p.node.plugin
    if plugin not in _PARAMS:
        raise SceneError(
            f"{p.where}: unsupported element {p.node.label()}; expected a shape of type "
            + ", ".join(_PARAMS)
        )
    extra = set(p.node.props) - _PARAMS[plugin] - _GEOMETRY
    if extra:
        raise SceneError(
            f"{p.where}: unsupported parameter {sorted(extra)[0]!r} in {p.node.label()}"
        )


def _file(p: Placed, base: Path) -> Path:
    rel = p.node.props.get("filename")
    path = confined_file(rel if isinstance(rel, str) else "", base, p.where)
    if p.node.plugin != "serialized" and path.suffix.lower() != f".{p.node.plugin}":
        raise SceneError(f"{p.where}: mesh file {rel!r}; expected a .{p.node.plugin} file")
    return path


def _serialized_head(path: Path, index: int, where: str) -> tuple[int, int, int]:
    """Flags, vertices and triangles of mesh *index* of a Mitsuba ``.serialized`` file, from
    the head of its zlib stream (the file's offset table at its end locates mesh *index*)."""
    with path.open("rb") as fh:
        head = fh.read(4)
        offset = 0
        if index:
            fh.seek(-4, 2)
            (count,) = struct.unpack("<I", fh.read(4))
            if not 0 <= index < count:
                raise SceneError(f"{where}: shape_index {index}; the file holds {count} meshes")
            fh.seek(-4 - 8 * (count - index), 2)
            (offset,) = struct.unpack("<Q", fh.read(8))
            fh.seek(offset)
            head = fh.read(4)
        magic, version = struct.unpack("<HH", head) if len(head) == 4 else (0, 0)
        if magic != 0x041C or version not in (3, 4):
            raise SceneError(f"{where}: {path.name} is not a Mitsuba .serialized mesh")
        data = zlib.decompressobj().decompress(fh.read(65536), 4096)
    at = 4
    if version == 4:
        at = data.index(b"\0", 4) + 1
    n_v, n_f = struct.unpack_from("<QQ", data, at)
    return struct.unpack_from("<I", data)[0], int(n_v), int(n_f)


def _counts(p: Placed, base: Path) -> tuple[int, int]:
    """Vertices and faces *p* will have, without building it."""
    plugin = p.node.plugin
    if plugin in BUILT_IN:
        faces = parts.faces_of(plugin)
        return faces + 2, faces  # indexed: a closed sphere has F/2 + 2, a disk F + 1
    path = _file(p, base)
    if plugin == "serialized":
        index = p.node.integer("shape_index", 0)
        return _serialized_head(path, index, p.where)[1:]
    return mesh_counts(path)


def check_budget(placed: list[Placed], base: Path) -> None:
    """Refuse the scene, before anything is loaded, if its shapes hold more faces or vertices
    than one scene may: each shape, every placement of it, is charged to the one scene budget
    of every format (:class:`~spectrinsic.scenes.budget.SceneBudget`)."""
    budget = SceneBudget(f"{len(placed)} shapes")
    for p in placed:
        _check_params(p)
        v, f = _counts(p, base)
        budget.charge(p.where, faces=f, vertices=v)


def _named(p: Placed) -> str:
    """*p* and its mesh file as the scene states it (relative to the scene's folder), for a
    refusal of the file's content."""
    return f"{p.where}: mesh file {p.node.props.get('filename')!r}"


def _mesh_file(p: Placed, base: Path) -> tuple[np.ndarray, np.ndarray]:
    import trimesh

    path = _file(p, base)
    if p.node.plugin == "serialized":
        try:
            return mesh_file(p.node.plugin, str(path), p.node.integer("shape_index", 0))
        except SceneError as exc:
            raise SceneError(f"{_named(p)}: {exc}") from None
    # no check_mesh_size: check_budget counted this file's header, within the same limits
    try:
        if p.node.plugin == "obj":
            return _obj(path, trimesh.exchange.obj.load_obj)
        mesh: Any = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types for corrupt files
        raise SceneError(f"{_named(p)}: cannot read it ({type(exc).__name__})") from None
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)


def _obj(path: Path, load_obj: Any) -> tuple[np.ndarray, np.ndarray]:
    """An OBJ file's triangles by trimesh's OBJ parser *load_obj* alone (materials skipped: the
    scene's BSDF applies), its objects concatenated; twice as fast as ``trimesh.load``'s scene
    path."""
    with path.open("rb") as fh:
        loaded = load_obj(fh, skip_materials=True, maintain_order=True, group_material=False)
    vertices, faces, offset = [], [], 0
    for part in loaded.get("geometry", {}).values():
        v = np.asarray(part["vertices"], float).reshape(-1, 3)
        vertices.append(v)
        faces.append(np.asarray(part["faces"], np.int64).reshape(-1, 3) + offset)
        offset += len(v)
    if not faces:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    return np.concatenate(vertices), np.concatenate(faces)


def sphere_radius(p: Placed) -> float:
    """A ``sphere``'s ``radius`` (default 1), refused in one line unless > 0: Mitsuba turns a
    sphere of negative radius inside out (its normals point inward, a one-sided BSDF is black
    from outside), while our tessellation would render it lit and write inward normals."""
    radius = p.node.number("radius", 1.0)
    if not radius > 0:
        raise SceneError(
            f"{p.where}: sphere radius {radius:g}; expected > 0 (a negative radius turns "
            "Mitsuba's sphere inside out)"
        )
    return radius


def _finite(p: Placed, v: np.ndarray) -> np.ndarray:
    """A mesh file's vertices *v*, refused in one line naming the file (as the scene states
    it, relative to the scene's folder) if any is NaN or infinite: the scene's own check
    after the transform would name only the shape's id."""
    bad = np.flatnonzero(~np.isfinite(v).all(axis=1))
    if bad.size:
        raise SceneError(
            f"{_named(p)}: {bad.size} vertices are NaN or infinite (first: vertex "
            f"{int(bad[0])}); expected finite coordinates"
        )
    return v


def _local(p: Placed, base: Path) -> tuple[np.ndarray, np.ndarray]:
    props = p.node.props
    plugin = p.node.plugin
    if plugin in FILE_SHAPES:
        v, f = _mesh_file(p, base)
        return _finite(p, v), f
    if plugin == "sphere":
        centre = np.asarray(props.get("center", np.zeros(3)), float)
        return parts.sphere(centre, sphere_radius(p))
    if plugin == "cylinder":
        p0 = np.asarray(props.get("p0", np.zeros(3)), float)
        p1 = np.asarray(props.get("p1", np.array([0.0, 0.0, 1.0])), float)
        radius = p.node.number("radius", 1.0)
        if not (radius > 0 and np.linalg.norm(p1 - p0) > 0):
            raise SceneError(f"{p.where}: a cylinder needs radius > 0 and p0 != p1")
        return parts.cylinder(p0, p1, radius)
    return getattr(parts, plugin)()  # type: ignore[no-any-return]


def triangles(p: Placed, base: Path) -> tuple[np.ndarray, np.ndarray]:
    """World-space vertices ``(V, 3)`` and faces ``(F, 3)`` of *p*."""
    v, f = _local(p, base)
    if reversed_winding(p, base):
        f = f[:, ::-1]
    local = _matrix(p.node)
    if not (np.isfinite(local).all() and np.isfinite(p.matrix).all()):  # before the product
        raise SceneError(
            f"{p.where}: its to_world transform holds a non-finite number (a value beyond "
            "float range, e.g. 1e400); expected finite numbers"
        )
    return parts.apply(p.matrix @ local, v), f


def textured_triangles(p: Placed, base: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`triangles` of *p* and the ``(F, 3, 2)`` texture coordinates of each face
    corner in our convention (v up: v = 0 is the image's bottom row), the ones Mitsuba's
    bitmap lookup uses: a ``rectangle``'s ``((x + 1) / 2, (y + 1) / 2)`` and a mesh file's
    texture coordinates as Mitsuba's own loader reads them (then the geometry is that loader's
    too), each Mitsuba ``(u, v)`` turned to ours ``(u, 1 - v)``.

    Raises
    ------
    SceneError
        A shape without texture coordinates (other built-in shapes, a mesh file without them).
    """
    plugin = p.node.plugin
    if plugin == "rectangle":
        v, f = parts.rectangle()
        uv = np.stack([(v[:, 0] + 1) / 2, (v[:, 1] + 1) / 2], axis=1)
    elif plugin in FILE_SHAPES:
        path = _file(p, base)
        try:
            v, f, uv = mesh_file_uv(plugin, str(path), p.node.integer("shape_index", 0))
        except SceneError as exc:
            raise SceneError(f"{_named(p)}: {exc}") from None
        _finite(p, v)
    else:
        uv = np.zeros((0, 0))
    if uv.shape[1:] != (2,):
        raise SceneError(
            f"{p.where}: a bitmap texture on {p.node.label()} needs texture coordinates; "
            "expected a rectangle or a mesh file with them"
        )
    corners = np.stack([uv[:, 0], 1.0 - uv[:, 1]], axis=1)[f]
    if reversed_winding(p, base):
        f, corners = f[:, ::-1], corners[:, ::-1]
    return parts.apply(p.matrix @ _matrix(p.node), v), f, corners


def mirrors(m: np.ndarray) -> bool:
    """Whether the 4 × 4 transform *m* mirrors space (its linear part's determinant < 0)."""
    return bool(np.linalg.det(np.asarray(m, float)[:3, :3]) < 0)


def stored_normals(p: Placed, base: Path) -> bool:
    """Whether Mitsuba shades mesh file *p* with the vertex normals the file stores (unless
    ``face_normals``; else it computes them from the transformed triangles): an OBJ with
    ``vn`` lines, a PLY whose vertices have ``nx``, a ``serialized`` mesh flagged ``0x0001``."""
    if p.node.plugin not in FILE_SHAPES or props_true(p.node, "face_normals"):
        return False
    path = _file(p, base)
    if p.node.plugin == "serialized":
        flags = _serialized_head(path, p.node.integer("shape_index", 0), p.where)[0]
        return bool(flags & 0x0001)  # Mitsuba 3.9.1 shades with them whatever 0x0010 says
    with path.open("rb") as fh:
        if p.node.plugin == "ply":
            head = fh.read(65536).split(b"end_header", 1)[0]
            return any(line.split()[::2] == [b"property", b"nx"] for line in head.splitlines())
        carry = b""
        while block := fh.read(2**20):  # streamed: the vn lines of an OBJ come early
            lines = carry + block
            cut = lines.rfind(b"\n") + 1
            if _OBJ_NORMAL.search(lines, 0, cut):
                return True
            carry = lines[cut:]
        return _OBJ_NORMAL.search(carry) is not None


def reversed_winding(p: Placed, base: Path) -> bool:
    """Whether *p*'s triangles are wound the other way round, so that their normals (the
    right-hand rule on the transformed corners) point to Mitsuba's side of the surface.

    Mitsuba 3.9.1 (measured with its ``aov`` integrator's ``sh_normal``): ``flip_normals``
    turns every shape's normals over; an instance's mirroring ``to_world`` never does (it maps
    normals by its inverse transpose), nor does a shape's own mirroring ``to_world`` on the
    shapes of :data:`KEEP_SIDE` and on mesh files with :func:`stored_normals`; a ``sphere``'s
    and another mesh file's own mirroring ``to_world`` does (their normals follow the mirrored
    surface), as a mirrored winding does here.
    """
    own = mirrors(_matrix(p.node)) and (
        p.node.plugin in KEEP_SIDE or (p.node.plugin in FILE_SHAPES and stored_normals(p, base))
    )
    return props_true(p.node, "flip_normals") ^ mirrors(p.matrix) ^ own


def props_true(node: XmlNode, key: str) -> bool:
    """Whether boolean parameter *key* of *node* is given and true."""
    return node.props.get(key) is True
