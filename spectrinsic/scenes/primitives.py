"""Procedural primitives: closed, one-colour :class:`~spectrinsic.scenes.parts.Part` meshes built
with trimesh or by hand (no downloaded assets).

:func:`box`, :func:`sphere`, :func:`ellipsoid`, :func:`revolve`, :func:`cylinder`, :func:`cone`,
:func:`capsule` and :func:`torus`. Every primitive is watertight with outward-facing normals
(counter-clockwise seen from outside), so a point's inside/outside status is well defined (scene
validation relies on it). :func:`revolve` paints one spectrum per profile segment; the others
are one colour (repaint them with :mod:`spectrinsic.scenes.painting`).

Units: lengths in metres, angles in degrees; +z is up.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import SceneError
from .parts import Part

__all__ = ["box", "sphere", "ellipsoid", "revolve", "cylinder", "cone", "capsule", "torus"]


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
