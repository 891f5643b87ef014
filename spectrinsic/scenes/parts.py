"""Painted parts: closed triangle meshes whose faces carry exact spectra, and how they are placed,
combined and turned into scene meshes.

A :class:`Part` is a closed triangle mesh whose faces carry *exact* spectra: every face names one
reflectance spectrum from :mod:`spectrinsic.spectra`, so painted stripes, patches and printed
patterns are sharp regions of single spectra (no texture filtering or blending). Parts are made
by the primitives of :mod:`spectrinsic.scenes.primitives`, placed with :func:`moved` or
:func:`deformed`, painted with :mod:`spectrinsic.scenes.painting`, combined with :func:`merge`,
and turned into scene meshes with :func:`to_meshes`. Furniture and rooms are in
:mod:`spectrinsic.scenes.furniture`.

Units: lengths in metres, angles in degrees; +z is up.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import SceneError
from .model import Material, Mesh
from .textures import basis_name, make_texture

__all__ = ["Part", "moved", "deformed", "merge", "to_meshes"]


@dataclass(frozen=True, eq=False)
class Part:
    """A closed triangle mesh with one spectrum per face.

    Attributes
    ----------
    vertices
        ``(V, 3)`` float64 positions in metres.
    faces
        ``(F, 3)`` int64 vertex indices, counter-clockwise seen from outside.
    labels
        ``(F,)`` int64 index of each face's spectrum in :attr:`palette`.
    palette
        Reflectance spectrum names (``"munsell:5R 4/14"``, ``"flat:0.5"``).
    texture
        ``(pattern, size, seed)`` of a spectral texture over the whole part whose basis is
        :attr:`palette` (:func:`~spectrinsic.scenes.textures.make_texture`; the labels are then
        all 0), or ``None``.
    semantic
        The class of the mesh it becomes (:mod:`~spectrinsic.scenes.semantic`), set by the
        generator on a placed part; empty: the class its name maps to.
    """

    vertices: np.ndarray
    faces: np.ndarray
    labels: np.ndarray
    palette: tuple[str, ...]
    texture: tuple[str, int, int] | None = None
    semantic: str = ""

    @property
    def face_spectra(self) -> np.ndarray:
        """``(F,)`` object array: the spectrum name of every face."""
        return np.asarray(self.palette, dtype=object)[self.labels]

    @property
    def centroids(self) -> np.ndarray:
        """``(F, 3)`` float64 face centroids."""
        return self.vertices[self.faces].mean(axis=1)

    @property
    def normals(self) -> np.ndarray:
        """``(F, 3)`` float64 unit face normals (outward)."""
        tri = self.vertices[self.faces]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)

    def trimesh(self):  # noqa: ANN201 - trimesh is imported lazily
        """Return the part as a :class:`trimesh.Trimesh` (vertices and face order kept)."""
        import trimesh

        return trimesh.Trimesh(self.vertices, self.faces, process=False)


# --- placement ------------------------------------------------------------------------------


def moved(
    part: Part,
    *,
    translate: Sequence[float] = (0.0, 0.0, 0.0),
    rotate_deg: Sequence[float] = (0.0, 0.0, 0.0),
    scale: float | Sequence[float] = 1.0,
) -> Part:
    """Scale (about the origin), then rotate about x, y, z (degrees), then translate."""
    s = np.broadcast_to(np.asarray(scale, dtype=np.float64), (3,))
    if np.any(s <= 0):
        raise SceneError(f"scale must be positive, got {list(s)}")
    rx, ry, rz = np.radians(np.asarray(rotate_deg, dtype=np.float64))

    def rot(angle: float, i: int, j: int) -> np.ndarray:
        m = np.eye(3)
        m[i, i] = m[j, j] = np.cos(angle)
        m[i, j], m[j, i] = -np.sin(angle), np.sin(angle)
        return m

    matrix = rot(rz, 0, 1) @ rot(ry, 2, 0) @ rot(rx, 1, 2)
    vertices = (part.vertices * s) @ matrix.T + np.asarray(translate, dtype=np.float64)
    return Part(vertices, part.faces, part.labels, part.palette, part.texture)


def deformed(part: Part, fn: Callable[[np.ndarray], np.ndarray]) -> Part:
    """Apply ``fn((V, 3)) -> (V, 3)`` to the vertices (bend a sheet, squash an apple)."""
    vertices = np.asarray(fn(part.vertices.copy()), dtype=np.float64)
    if vertices.shape != part.vertices.shape:
        raise SceneError(
            f"deformation returned shape {vertices.shape}, expected {part.vertices.shape}"
        )
    return Part(vertices, part.faces, part.labels, part.palette, part.texture)


def merge(*parts: Part) -> Part:
    """Concatenate parts into one (components stay separate closed surfaces); textured parts
    stay meshes of their own."""
    if any(p.texture is not None for p in parts):
        raise SceneError("merge: a textured part is a mesh of its own; merge it untextured")
    palette = tuple(dict.fromkeys(name for p in parts for name in p.palette))
    offsets = np.cumsum([0] + [len(p.vertices) for p in parts])
    vertices = np.concatenate([p.vertices for p in parts])
    faces = np.concatenate([p.faces + o for p, o in zip(parts, offsets, strict=False)])
    labels = np.concatenate(
        [np.array([palette.index(n) for n in p.palette], dtype=np.int64)[p.labels] for p in parts]
    )
    return Part(vertices, faces, labels, palette)


# --- to the scene model ---------------------------------------------------------------------


def to_meshes(
    parts: Sequence[tuple[str, Part]], *, first_object_id: int = 0
) -> tuple[tuple[Mesh, ...], tuple[Material, ...]]:
    """Turn named parts into scene meshes (one object id each) sharing one material table.

    Materials are the distinct spectra in order of first use, each named after its spectrum; a
    textured part's basis spectra follow as materials of their own, ``<part name>[b]``
    (:func:`~spectrinsic.scenes.materials.basis_name`), so the scene saves as YAML.
    """
    palette = tuple(
        dict.fromkeys(name for _, p in parts if p.texture is None for name in p.palette)
    )
    lookup = {n: i for i, n in enumerate(palette)}
    materials = [Material(name=n, spectrum=n) for n in palette]
    meshes = []
    for k, (name, p) in enumerate(parts):
        texture = None
        if p.texture is None:
            face_materials = np.array([lookup[n] for n in p.palette], dtype=np.int64)[p.labels]
        else:
            basis = tuple(range(len(materials), len(materials) + len(p.palette)))
            materials += [Material(basis_name(name, b), s) for b, s in enumerate(p.palette)]
            texture = make_texture(name, basis, *p.texture)
            face_materials = np.full(len(p.faces), basis[0], dtype=np.int64)
        meshes.append(
            Mesh(
                name=name,
                vertices=p.vertices.copy(),
                faces=p.faces.copy(),
                face_materials=face_materials,
                object_id=first_object_id + k,
                texture=texture,
                semantic=p.semantic,
            )
        )
    return tuple(meshes), tuple(materials)
