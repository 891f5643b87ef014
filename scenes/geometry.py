"""Procedural geometry: closed, painted triangle meshes built with trimesh (no downloaded assets).

A :class:`Part` is a closed triangle mesh whose faces carry *exact* spectra: every face names one
reflectance spectrum from :mod:`spectrinsic.spectra`, so painted stripes, patches and printed
patterns are sharp regions of single spectra (no texture filtering or blending). Parts are
made by primitives (:func:`box`, :func:`sphere`, :func:`ellipsoid`, :func:`revolve`,
:func:`cylinder`, :func:`cone`, :func:`capsule`, :func:`torus`), placed with :func:`moved` or
:func:`deformed`, painted with :func:`bands`, :func:`stripes`, :func:`patches` and
:func:`printed`, combined with :func:`merge`, and turned into scene meshes with
:func:`to_meshes`. Furniture and rooms (:func:`table`, :func:`shelf`, :func:`chair`,
:func:`room`) are unions of boxes.

Every primitive is watertight with outward-facing normals (counter-clockwise seen from
outside), so a point's inside/outside status is well defined (scene validation relies on it).
Room walls are boxes of finite thickness, so the air inside a room is *outside* every solid.

Units: lengths in metres, angles in degrees; +z is up.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from spectrinsic.errors import SceneError
from spectrinsic.scenes.model import Material, Mesh

__all__ = [
    "Part",
    "box",
    "sphere",
    "ellipsoid",
    "revolve",
    "cylinder",
    "cone",
    "capsule",
    "torus",
    "moved",
    "deformed",
    "merge",
    "bands",
    "stripes",
    "patches",
    "printed",
    "table",
    "shelf",
    "chair",
    "room",
    "to_meshes",
]

Vec3 = tuple[float, float, float]


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
    """

    vertices: np.ndarray
    faces: np.ndarray
    labels: np.ndarray
    palette: tuple[str, ...]

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


def _part(vertices: np.ndarray, faces: np.ndarray, spectrum: str) -> Part:
    """A one-colour part with outward normals (faces flipped if the signed volume is < 0)."""
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    tri = vertices[faces]
    signed_volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0
    if signed_volume < 0:
        faces = np.ascontiguousarray(faces[:, ::-1])
    return Part(vertices, faces, np.zeros(len(faces), dtype=np.int64), (spectrum,))


def _from_trimesh(mesh, spectrum: str) -> Part:  # noqa: ANN001
    return _part(np.asarray(mesh.vertices), np.asarray(mesh.faces), spectrum)


# --- primitives -----------------------------------------------------------------------------


def box(
    extents: Sequence[float],
    spectrum: str,
    *,
    center: Sequence[float] = (0.0, 0.0, 0.0),
    divisions: Sequence[int] = (1, 1, 1),
) -> Part:
    """An axis-aligned box whose faces are regular grids (for sharp printed patterns).

    Parameters
    ----------
    extents
        ``(sx, sy, sz)`` side lengths in metres.
    spectrum
        Reflectance spectrum name of every face.
    center
        Centre of the box.
    divisions
        ``(nx, ny, nz)`` grid cells along each axis; every face is a grid of quads, two
        triangles each, so patterns aligned to ``extents / divisions`` have exact edges.
    """
    ext = np.asarray(extents, dtype=np.float64)
    div = np.asarray(divisions, dtype=np.int64)
    if ext.shape != (3,) or np.any(ext <= 0) or div.shape != (3,) or np.any(div < 1):
        raise SceneError(
            f"box extents {list(ext)} and divisions {list(div)} must be 3 positive values"
        )
    verts: list[np.ndarray] = []
    faces: list[np.ndarray] = []
    offset = 0
    for axis in range(3):
        u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3
        nu, nv = div[u_axis], div[v_axis]
        u, v = np.meshgrid(
            np.linspace(-0.5, 0.5, nu + 1), np.linspace(-0.5, 0.5, nv + 1), indexing="ij"
        )
        idx = np.arange((nu + 1) * (nv + 1)).reshape(nu + 1, nv + 1)
        a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
        c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
        quad = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
        for side in (-0.5, 0.5):
            p = np.zeros((u.size, 3))
            p[:, axis] = side
            p[:, u_axis] = u.ravel()
            p[:, v_axis] = v.ravel()
            # (u, v, axis) is right-handed, so (a, b, c) faces +axis; flip on the - side
            tri = quad if side > 0 else quad[:, ::-1]
            verts.append(p)
            faces.append(tri + offset)
            offset += len(p)
    vertices = np.concatenate(verts) * ext + np.asarray(center, dtype=np.float64)
    # weld the grid vertices shared along box edges so the mesh is watertight
    key = np.round(np.concatenate(verts) * 2 * div, 6)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return _part(vertices[first], inverse.reshape(-1)[np.concatenate(faces)], spectrum)


def sphere(
    radius: float,
    spectrum: str,
    *,
    center: Sequence[float] = (0.0, 0.0, 0.0),
    subdivisions: int = 2,
) -> Part:
    """An icosphere of *radius* (``20 * 4**subdivisions`` faces)."""
    return ellipsoid((radius, radius, radius), spectrum, center=center, subdivisions=subdivisions)


def ellipsoid(
    radii: Sequence[float],
    spectrum: str,
    *,
    center: Sequence[float] = (0.0, 0.0, 0.0),
    subdivisions: int = 2,
) -> Part:
    """An axis-aligned ellipsoid with semi-axes *radii*: a scaled icosphere."""
    import trimesh

    unit = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    vertices = np.asarray(unit.vertices) * np.asarray(radii, dtype=np.float64)
    return _part(vertices + np.asarray(center, dtype=np.float64), np.asarray(unit.faces), spectrum)


def revolve(
    profile: Sequence[Sequence[float]],
    spectra: str | Sequence[str],
    *,
    sections: int = 32,
    center: Sequence[float] = (0.0, 0.0, 0.0),
) -> Part:
    """A closed surface of revolution about the z axis (vases, cups, apples, caps).

    Parameters
    ----------
    profile
        ``(N, 2)`` polyline of ``(r, z)`` points, starting and ending on the axis (``r == 0``)
        with every interior point off the axis (``r > 0``). A profile that goes up the outside
        of a cup, over the lip and back down the inside gives a solid with a concave cavity.
    spectra
        One spectrum name for the whole surface, or one per profile segment (``N - 1``):
        painted rings follow the profile exactly.
    sections
        Number of angular sections.
    center
        Position of the profile's ``(0, 0)`` point.
    """
    prof = np.asarray(profile, dtype=np.float64)
    n = len(prof)
    if prof.ndim != 2 or prof.shape[1] != 2 or n < 3:
        raise SceneError(
            f"revolve profile must be (N >= 3, 2) (r, z) points, got shape {prof.shape}"
        )
    if prof[0, 0] != 0 or prof[-1, 0] != 0 or np.any(prof[1:-1, 0] <= 0):
        raise SceneError(
            "revolve profile must start and end on the axis (r = 0) and stay off it between"
        )
    names = [spectra] * (n - 1) if isinstance(spectra, str) else list(spectra)
    if len(names) != n - 1:
        raise SceneError(
            f"revolve needs 1 or {n - 1} spectra (one per profile segment), got {len(names)}"
        )
    theta = 2 * np.pi * np.arange(sections) / sections
    rings = prof[1:-1]
    ring_xyz = np.stack(
        [
            rings[:, :1] * np.cos(theta),
            rings[:, :1] * np.sin(theta),
            np.repeat(rings[:, 1:], sections, axis=1),
        ],
        axis=-1,
    ).reshape(-1, 3)
    bottom, top = len(ring_xyz), len(ring_xyz) + 1
    vertices = np.concatenate([ring_xyz, [[0, 0, prof[0, 1]], [0, 0, prof[-1, 1]]]])
    j = np.arange(sections)
    jn = (j + 1) % sections

    def ring(i: int, k: np.ndarray) -> np.ndarray:  # vertex index of profile point i (1..n-2)
        return (i - 1) * sections + k

    faces, labels = [], []
    for seg in range(n - 1):
        if seg == 0:
            tri = np.stack([np.full(sections, bottom), ring(1, jn), ring(1, j)], 1)
        elif seg == n - 2:
            tri = np.stack([ring(seg, j), ring(seg, jn), np.full(sections, top)], 1)
        else:
            a, b, c, d = ring(seg, j), ring(seg, jn), ring(seg + 1, jn), ring(seg + 1, j)
            tri = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
        faces.append(tri)
        labels.append(np.full(len(tri), seg))
    part = _part(vertices + np.asarray(center, dtype=np.float64), np.concatenate(faces), names[0])
    palette = tuple(dict.fromkeys(names))
    seg_label = np.array([palette.index(s) for s in names], dtype=np.int64)
    return Part(part.vertices, part.faces, seg_label[np.concatenate(labels)], palette)


def cylinder(
    radius: float,
    height: float,
    spectrum: str,
    *,
    center: Sequence[float] = (0.0, 0.0, 0.0),
    sections: int = 24,
    rings: int = 1,
) -> Part:
    """A capped cylinder along z, centred at *center*, its side split into *rings* bands."""
    z = np.linspace(-height / 2, height / 2, rings + 1)
    profile = [(0.0, z[0]), *[(radius, zi) for zi in z], (0.0, z[-1])]
    return revolve(profile, spectrum, sections=sections, center=center)


def cone(
    radius: float,
    height: float,
    spectrum: str,
    *,
    center: Sequence[float] = (0.0, 0.0, 0.0),
    sections: int = 16,
) -> Part:
    """A cone along +z with its base centred at *center*."""
    return revolve(
        [(0.0, 0.0), (radius, 0.0), (0.0, height)], spectrum, sections=sections, center=center
    )


def capsule(
    radius: float,
    length: float,
    spectrum: str,
    *,
    center: Sequence[float] = (0.0, 0.0, 0.0),
    sections: int = 16,
    cap_rings: int = 5,
) -> Part:
    """A capsule along z: a cylinder of *length* with hemispherical caps (total ``length + 2r``)."""
    t = np.linspace(0, np.pi / 2, cap_rings + 1)[1:]
    low = [(radius * np.sin(a), -length / 2 - radius * np.cos(a)) for a in t]
    high = [(radius * np.sin(a), length / 2 + radius * np.cos(a)) for a in t[::-1]]
    profile = [(0.0, -length / 2 - radius), *low, *high, (0.0, length / 2 + radius)]
    return revolve(profile, spectrum, sections=sections, center=center)


def torus(
    major_radius: float,
    minor_radius: float,
    spectrum: str,
    *,
    center: Sequence[float] = (0.0, 0.0, 0.0),
    major_sections: int = 24,
    minor_sections: int = 10,
) -> Part:
    """A torus about the z axis (ring in the xy plane)."""
    import trimesh

    mesh = trimesh.creation.torus(
        major_radius, minor_radius, major_sections=major_sections, minor_sections=minor_sections
    )
    part = _from_trimesh(mesh, spectrum)
    return Part(
        part.vertices + np.asarray(center, dtype=np.float64), part.faces, part.labels, part.palette
    )


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
    return Part(vertices, part.faces, part.labels, part.palette)


def deformed(part: Part, fn: Callable[[np.ndarray], np.ndarray]) -> Part:
    """Apply ``fn((V, 3)) -> (V, 3)`` to the vertices (bend a sheet, squash an apple)."""
    vertices = np.asarray(fn(part.vertices.copy()), dtype=np.float64)
    if vertices.shape != part.vertices.shape:
        raise SceneError(
            f"deformation returned shape {vertices.shape}, expected {part.vertices.shape}"
        )
    return Part(vertices, part.faces, part.labels, part.palette)


def merge(*parts: Part) -> Part:
    """Concatenate parts into one (components stay separate closed surfaces)."""
    palette = tuple(dict.fromkeys(name for p in parts for name in p.palette))
    offsets = np.cumsum([0] + [len(p.vertices) for p in parts])
    vertices = np.concatenate([p.vertices for p in parts])
    faces = np.concatenate([p.faces + o for p, o in zip(parts, offsets, strict=False)])
    labels = np.concatenate(
        [np.array([palette.index(n) for n in p.palette], dtype=np.int64)[p.labels] for p in parts]
    )
    return Part(vertices, faces, labels, palette)


# --- painting -------------------------------------------------------------------------------


def _repaint(part: Part, new: np.ndarray) -> Part:
    """Faces where *new* (an ``(F,)`` object array) is not None take that spectrum."""
    names = part.face_spectra
    keep = np.array([n is None for n in new], dtype=bool)
    names = np.where(keep, names, new)
    palette = tuple(dict.fromkeys(names.tolist()))
    lookup = {n: i for i, n in enumerate(palette)}
    return Part(
        part.vertices, part.faces, np.array([lookup[n] for n in names], dtype=np.int64), palette
    )


def bands(part: Part, spectra: Sequence[str | None], *, axis: int, edges: Sequence[float]) -> Part:
    """Paint bands along *axis*: faces with centroid coordinate in ``[edges[i-1], edges[i])``.

    *spectra* has ``len(edges) + 1`` entries (below the first edge, between edges, above the
    last); ``None`` leaves a band as it was.
    """
    if len(spectra) != len(edges) + 1:
        raise SceneError(
            f"bands needs len(edges) + 1 = {len(edges) + 1} spectra, got {len(spectra)}"
        )
    band = np.searchsorted(
        np.asarray(edges, dtype=np.float64), part.centroids[:, axis], side="right"
    )
    return _repaint(part, np.asarray(list(spectra), dtype=object)[band])


def stripes(
    part: Part, spectra: Sequence[str | None], *, axis: int, width: float, offset: float = 0.0
) -> Part:
    """Paint periodic stripes of *width* along *axis*, cycling through *spectra*."""
    k = np.floor((part.centroids[:, axis] - offset) / width).astype(np.int64) % len(spectra)
    return _repaint(part, np.asarray(list(spectra), dtype=object)[k])


def patches(part: Part, spectrum: str, centres: Sequence[Sequence[float]], radius: float) -> Part:
    """Paint the faces whose centroid lies within *radius* of any of *centres*."""
    c = np.asarray(centres, dtype=np.float64).reshape(-1, 3)
    d = np.linalg.norm(part.centroids[:, None, :] - c[None], axis=-1).min(axis=1)
    new = np.full(len(part.faces), None, dtype=object)
    new[d <= radius] = spectrum
    return _repaint(part, new)


def printed(
    part: Part,
    rows: Sequence[str],
    legend: Mapping[str, str],
    *,
    origin: Sequence[float],
    cell: float,
    axes: tuple[int, int] = (0, 1),
    facing: Sequence[float] = (0.0, 0.0, 1.0),
) -> Part:
    """Print a character grid onto the faces that face *facing* (like ink on paper).

    Row 0 of *rows* is printed at the largest coordinate along ``axes[1]`` (text reads top to
    bottom), column 0 at *origin* along ``axes[0]``; each character covers a square *cell*.
    Characters in *legend* are inked with their spectrum; any other (``" "``, ``"."``) leaves
    the face unchanged.

    >>> p = printed(box((1, 1, 1), "flat:0.8", divisions=(2, 2, 1)), ["R."], {"R": "flat:0.1"},
    ...             origin=(-0.5, -0.5), cell=0.5)
    >>> sorted(set(p.face_spectra))
    ['flat:0.1', 'flat:0.8']
    """
    u_ax, v_ax = axes
    cen = part.centroids
    up = part.normals @ (np.asarray(facing, dtype=np.float64) / np.linalg.norm(facing)) > 0.9
    col = np.floor((cen[:, u_ax] - origin[0]) / cell).astype(np.int64)
    row = len(rows) - 1 - np.floor((cen[:, v_ax] - origin[1]) / cell).astype(np.int64)
    new = np.full(len(part.faces), None, dtype=object)
    for f in np.flatnonzero(up & (row >= 0) & (row < len(rows)) & (col >= 0)):
        line = rows[row[f]]
        if col[f] < len(line) and line[col[f]] in legend:
            new[f] = legend[line[col[f]]]
    return _repaint(part, new)


# --- furniture and rooms --------------------------------------------------------------------


def table(
    width: float,
    depth: float,
    height: float,
    spectrum: str,
    *,
    top: float = 0.04,
    leg: float = 0.06,
    center: Sequence[float] = (0.0, 0.0, 0.0),
) -> Part:
    """A table standing on z = center[2]: a top board and four square legs."""
    cx, cy, cz = center
    parts = [box((width, depth, top), spectrum, center=(cx, cy, cz + height - top / 2))]
    for sx in (-1, 1):
        for sy in (-1, 1):
            x = cx + sx * (width / 2 - leg)
            y = cy + sy * (depth / 2 - leg)
            parts.append(
                box((leg, leg, height - top), spectrum, center=(x, y, cz + (height - top) / 2))
            )
    return merge(*parts)


def shelf(
    width: float,
    depth: float,
    height: float,
    spectrum: str,
    *,
    boards: int = 3,
    thickness: float = 0.03,
    center: Sequence[float] = (0.0, 0.0, 0.0),
) -> Part:
    """An open bookshelf (sides, back, *boards* shelves) standing on z = center[2], open to -y.

    Its compartments are concave boxes: light bounces between the boards and the back.
    """
    cx, cy, cz = center
    t = thickness
    parts = [
        box((t, depth, height), spectrum, center=(cx - width / 2 + t / 2, cy, cz + height / 2)),
        box((t, depth, height), spectrum, center=(cx + width / 2 - t / 2, cy, cz + height / 2)),
        box(
            (width - 2 * t, t, height),
            spectrum,
            center=(cx, cy + depth / 2 - t / 2, cz + height / 2),
        ),
    ]
    for z in np.linspace(t / 2, height - t / 2, boards + 1):
        parts.append(box((width - 2 * t, depth - t, t), spectrum, center=(cx, cy - t / 2, cz + z)))
    return merge(*parts)


def chair(
    seat: float,
    height: float,
    spectrum: str,
    *,
    back: float = 0.45,
    leg: float = 0.04,
    center: Sequence[float] = (0.0, 0.0, 0.0),
    facing_deg: float = 0.0,
) -> Part:
    """A chair of square *seat* side and seat *height*, its back on the +y side before rotation
    by *facing_deg* about z."""
    t = 0.04
    parts = [box((seat, seat, t), spectrum, center=(0, 0, height - t / 2))]
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(
                box(
                    (leg, leg, height - t),
                    spectrum,
                    center=(sx * (seat / 2 - leg / 2), sy * (seat / 2 - leg / 2), (height - t) / 2),
                )
            )
    parts.append(box((seat, t, back), spectrum, center=(0, seat / 2 - t / 2, height + back / 2)))
    return moved(merge(*parts), rotate_deg=(0, 0, facing_deg), translate=center)


def room(
    size: Sequence[float],
    spectra: Mapping[str, str],
    *,
    thickness: float = 0.1,
    divisions: int = 4,
) -> dict[str, Part]:
    """The shell of a closed room whose air is the box ``[0, w] x [0, d] x [0, h]``.

    Parameters
    ----------
    size
        ``(w, d, h)`` interior width (x), depth (y) and height (z) in metres.
    spectra
        Spectrum of each of ``"floor"``, ``"ceiling"``, ``"left"`` (x = 0), ``"right"``
        (x = w), ``"back"`` (y = d) and ``"front"`` (y = 0).
    thickness
        Wall thickness; walls are closed boxes outside the air volume, overlapping at corners.
    divisions
        Grid cells per metre on the walls (finer faces for the id maps, not for shading).

    Returns
    -------
    dict
        One part per surface, keyed as in *spectra*.
    """
    w, d, h = (float(v) for v in size)
    t = thickness
    missing = {"floor", "ceiling", "left", "right", "back", "front"} - set(spectra)
    if missing:
        raise SceneError(f"room spectra lack {sorted(missing)}")
    specs = {
        "floor": ((w + 2 * t, d + 2 * t, t), (w / 2, d / 2, -t / 2)),
        "ceiling": ((w + 2 * t, d + 2 * t, t), (w / 2, d / 2, h + t / 2)),
        "left": ((t, d, h), (-t / 2, d / 2, h / 2)),
        "right": ((t, d, h), (w + t / 2, d / 2, h / 2)),
        "back": ((w, t, h), (w / 2, d + t / 2, h / 2)),
        "front": ((w, t, h), (w / 2, -t / 2, h / 2)),
    }
    out = {}
    for name, (ext, centre) in specs.items():
        div = tuple(max(1, int(round(e * divisions))) for e in ext)
        out[name] = box(ext, spectra[name], center=centre, divisions=div)
    return out


# --- to the scene model ---------------------------------------------------------------------


def to_meshes(
    parts: Sequence[tuple[str, Part]], *, first_object_id: int = 0
) -> tuple[tuple[Mesh, ...], tuple[Material, ...]]:
    """Turn named parts into scene meshes (one object id each) sharing one material table.

    Materials are the distinct spectra in order of first use, each named after its spectrum.
    """
    palette = tuple(dict.fromkeys(name for _, p in parts for name in p.palette))
    lookup = {n: i for i, n in enumerate(palette)}
    meshes = []
    for k, (name, p) in enumerate(parts):
        remap = np.array([lookup[n] for n in p.palette], dtype=np.int64)
        meshes.append(
            Mesh(
                name=name,
                vertices=p.vertices.copy(),
                faces=p.faces.copy(),
                face_materials=remap[p.labels],
                object_id=first_object_id + k,
            )
        )
    return tuple(meshes), tuple(Material(name=n, spectrum=n) for n in palette)
