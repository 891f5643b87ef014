"""Parametric objects for generated scenes: today's library objects and new primitives, each
with random scale, proportions and subdivision, standing on z = 0 and centred on the z axis.

Every builder takes an explicit :class:`numpy.random.Generator` and a base reflectance name,
and returns a closed :class:`~spectrinsic.scenes.parts.Part`. Units: metres, degrees.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ..objects import OBJECTS
from ..parts import Part, moved
from ..primitives import box, capsule, cone, cylinder, ellipsoid, revolve, torus
from .materials import PIXEL_TEXTURE, MaterialDistribution, paint, pixel_texture, repaint_outside

__all__ = ["SHAPES", "shape_names", "make_shape", "draw_object", "on_ground"]

Builder = Callable[[np.random.Generator, str], Part]


def on_ground(part: Part) -> Part:
    """Move *part* so that its lowest point is on z = 0 and its footprint is centred at 0."""
    lo, hi = part.vertices.min(axis=0), part.vertices.max(axis=0)
    return moved(part, translate=(-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2]))


def _block(rng: np.random.Generator, spectrum: str) -> Part:
    size = rng.uniform(0.06, 0.25, 3)
    div = tuple(int(d) for d in rng.integers(2, 7, 3))
    return box(tuple(size), spectrum, center=(0, 0, size[2] / 2), divisions=div)


def _pillar(rng: np.random.Generator, spectrum: str) -> Part:
    r, h = rng.uniform(0.03, 0.09), rng.uniform(0.08, 0.3)
    return cylinder(
        r, h, spectrum, sections=int(rng.integers(8, 33)), rings=int(rng.integers(2, 8))
    )


def _ball(rng: np.random.Generator, spectrum: str) -> Part:
    radii = rng.uniform(0.03, 0.1) * rng.uniform(0.7, 1.3, 3)
    return ellipsoid(tuple(radii), spectrum, subdivisions=int(rng.integers(1, 4)))


def _cone(rng: np.random.Generator, spectrum: str) -> Part:
    return cone(
        rng.uniform(0.03, 0.1), rng.uniform(0.06, 0.25), spectrum, sections=int(rng.integers(6, 33))
    )


def _capsule(rng: np.random.Generator, spectrum: str) -> Part:
    part = capsule(
        rng.uniform(0.02, 0.06), rng.uniform(0.04, 0.2), spectrum, sections=int(rng.integers(8, 25))
    )
    return moved(part, rotate_deg=(90.0 * int(rng.integers(0, 2)), 0, 0))


def _ring(rng: np.random.Generator, spectrum: str) -> Part:
    major = rng.uniform(0.04, 0.1)
    return torus(
        major,
        major * rng.uniform(0.15, 0.45),
        spectrum,
        major_sections=int(rng.integers(12, 33)),
        minor_sections=int(rng.integers(6, 13)),
    )


def _vessel(rng: np.random.Generator, spectrum: str) -> Part:
    """A bowl or pot: a surface of revolution with a cavity (concave, interreflections)."""
    height, radius = rng.uniform(0.05, 0.2), rng.uniform(0.04, 0.1)
    z = np.linspace(0.0, height, int(rng.integers(6, 14)))
    bulge = rng.uniform(-0.3, 0.5)
    r = radius * (0.7 + 0.3 * z / height + bulge * np.sin(np.pi * z / height) * 0.5)
    wall = 0.12 * radius
    inner = [(ri - wall, zi) for ri, zi in zip(r[::-1], z[::-1], strict=True) if zi >= wall]
    profile = [(0.0, 0.0), *zip(r, z, strict=True), *inner, (0.0, wall)]
    return revolve(profile, spectrum, sections=int(rng.integers(12, 37)))


def _library(key: str) -> Builder:
    def build(rng: np.random.Generator, spectrum: str) -> Part:
        stretch = rng.uniform(0.8, 1.25, 3)
        return moved(OBJECTS[key](), scale=tuple(float(rng.uniform(0.8, 2.0)) * stretch))

    build.__doc__ = f"The library's {key!r} with random scale and proportions (its own paint)."
    return build


#: Builders by name; ``lib-*`` keep the library object's paint, the others take *spectrum*.
SHAPES: dict[str, Builder] = {
    "block": _block,
    "pillar": _pillar,
    "ball": _ball,
    "cone": _cone,
    "capsule": _capsule,
    "ring": _ring,
    "vessel": _vessel,
    **{f"lib-{key}": _library(key) for key in OBJECTS},
}


def shape_names() -> list[str]:
    """Names of the parametric shapes, in :data:`SHAPES` order."""
    return list(SHAPES)


def make_shape(name: str, rng: np.random.Generator, spectrum: str) -> Part:
    """Build shape *name* with random parameters from *rng*, resting on z = 0, upright or
    turned about z by a random angle (degrees)."""
    part = SHAPES[name](rng, spectrum)
    return on_ground(moved(part, rotate_deg=(0, 0, float(rng.uniform(0, 360)))))


def draw_object(
    rng: np.random.Generator,
    materials: MaterialDistribution,
    sfu: Sequence[str] = (),
    *,
    texture_library: bool = False,
) -> tuple[str, Part, str | None, np.ndarray]:
    """A random shape, painted from *materials* (library objects keep those of their own
    colours that lie in *materials*' ranges; the others are redrawn from it). With
    *texture_library* a library object too takes a per-pixel texture with probability
    ``materials.texture_fraction`` (``objects-on-ground``, which draws mostly library
    objects, so that ``--texture-fraction`` applies to it; drawn only when above 0).

    Returns
    -------
    tuple
        ``(shape name, part on z = 0, pattern name or None, (2,) footprint half-sizes in m)``.
    """
    names = shape_names()
    shape = names[int(rng.integers(len(names)))]
    part = make_shape(shape, rng, "flat:0.5")
    pattern = None
    if not shape.startswith("lib-"):
        part, pattern = paint(part, rng, materials, sfu)
    elif (
        texture_library
        and materials.texture_fraction > 0
        and rng.random() < materials.texture_fraction
    ):
        part, pattern = pixel_texture(part, rng, materials, sfu), PIXEL_TEXTURE
    else:
        part = repaint_outside(part, rng, materials)
    return shape, part, pattern, np.ptp(part.vertices[:, :2], axis=0) / 2
