"""``objects-on-ground``: 1-5 parametric objects on a flat ground plane (MIT-like scenes)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..parts import Part, moved
from ..primitives import box
from .base import GeneratorOptions, Layout
from .camera import Footprints
from .lights import LightVolume
from .materials import MaterialDistribution, draw_reflectance, within
from .shapes import draw_object

__all__ = ["objects_on_ground"]


def _ground(rng: np.random.Generator, materials: MaterialDistribution) -> Part:
    """A large thin slab whose top is z = 0, a low-chroma chip (within *materials*' ranges)."""
    spectrum = draw_reflectance(rng, within(MaterialDistribution((3, 8), (0, 4)), materials))
    return box((12.0, 12.0, 0.05), spectrum, center=(0, 0, -0.025), divisions=(12, 12, 1))


def _place(
    rng: np.random.Generator, options: GeneratorOptions
) -> tuple[list[tuple[str, Part]], list[str]]:
    """Objects at random spots within 0.35 m of the origin, footprints not overlapping."""
    floor = Footprints([])
    parts: list[tuple[str, Part]] = []
    patterns: list[str] = []
    for i in range(int(rng.integers(1, 6))):
        shape, part, pattern, half = draw_object(
            rng, options.materials, options.sfu_reflectances, texture_library=True
        )
        patterns += [pattern] if pattern else []
        for _ in range(30):
            centre = rng.uniform(-0.35, 0.35, 2)
            if floor.try_add(centre, half):
                placed = moved(part, translate=(centre[0], centre[1], 0.0))
                parts.append((f"{shape}-{i}", replace(placed, semantic="object")))
                break
    return parts, patterns


def objects_on_ground(rng: np.random.Generator, options: GeneratorOptions) -> Layout:
    """Lay out a generated objects-on-ground scene (see the module docstring)."""
    objects, patterns = _place(rng, options)
    verts = np.concatenate([p.vertices for _, p in objects])
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    centre = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi - lo)) / 2, 0.05)

    spots = [
        (
            (p.vertices.min(axis=0) + p.vertices.max(axis=0)) / 2,
            float(np.linalg.norm(np.ptp(p.vertices, axis=0))) / 2,
        )
        for _, p in objects
    ]

    def propose(r: np.random.Generator) -> tuple[np.ndarray, np.ndarray, float]:
        """Aim at one object (or the group), far enough to frame it and some neighbours."""
        fov = float(r.uniform(30, 55))
        aim, size = spots[int(r.integers(len(spots)))] if r.random() < 0.6 else (centre, radius)
        elevation, azimuth = math.radians(r.uniform(12, 65)), r.uniform(0, 2 * math.pi)
        distance = max(size, 0.25 * radius) / math.sin(math.radians(fov) / 2) * r.uniform(0.8, 1.4)
        direction = np.array(
            [
                math.cos(elevation) * math.cos(azimuth),
                math.cos(elevation) * math.sin(azimuth),
                math.sin(elevation),
            ]
        )
        target = aim + r.uniform(-0.1, 0.1, 3) * size
        return target + distance * direction, target, fov

    d = max(6 * radius, 0.5)
    volume = LightVolume(
        lo=(centre[0] - d, centre[1] - d, hi[2] + radius),
        hi=(centre[0] + d, centre[1] + d, hi[2] + d),
        focus=tuple(float(x) for x in centre),  # type: ignore[arg-type]
    )
    info = {
        "generator": "objects-on-ground",
        "kind": "object",
        "n_objects": len(objects),
        "shapes": [n.rsplit("-", 1)[0] for n, _ in objects],
        "patterns": patterns,
    }
    return Layout(
        parts=(*objects, ("ground", replace(_ground(rng, options.materials), semantic="floor"))),
        lights=volume,
        propose_camera=propose,
        info=info,
    )
