"""Geometry, camera viewpoints and light rigs of the built-in library scenes (thesis Figs.
5.6-5.7 and Appendix C.2); the illuminant spectra of a rig come later
(:mod:`spectrinsic.scenes.library`).

- :func:`object_layout`: one object of :data:`spectrinsic.scenes.objects.OBJECTS` on a neutral,
  spectrally flat ground (reflectance 0.5), one view, lights placed around the object;
- :data:`ROOM_LAYOUTS`: the three closed rooms (``room-living``, ``room-corner``,
  ``room-studio``) with coloured walls, furniture and several objects, concave arrangements
  (wall corners, shelf compartments, cup and vase cavities) and 3 views each.

Units: metres and degrees (fields of view horizontal); +z is up.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .furniture import chair, room, shelf, table
from .model import LightKind
from .objects import OBJECTS
from .parts import Part, merge, moved
from .primitives import box

__all__ = ["GROUND", "LightSpot", "Layout", "object_layout", "ROOM_LAYOUTS"]

GROUND = "flat:0.5"
_M = "munsell:"


@dataclass(frozen=True)
class LightSpot:
    """Where a light of a rig sits, and where it points."""

    kind: LightKind
    position: tuple[float, float, float]
    size: tuple[float, float] = (0.5, 0.5)


@dataclass(frozen=True)
class Layout:
    """Geometry, views and light rigs of one library scene (spectra of lights come later)."""

    parts: tuple[tuple[str, Part], ...]
    views: tuple[tuple[tuple[float, float, float], tuple[float, float, float], float], ...]
    focus: tuple[float, float, float]
    single: LightSpot
    pair: tuple[LightSpot, LightSpot]


# --- layouts --------------------------------------------------------------------------------


def object_layout(key: str) -> Layout:
    part = OBJECTS[key]()
    lo, hi = part.vertices.min(axis=0), part.vertices.max(axis=0)
    centre = (lo + hi) / 2
    radius = float(np.linalg.norm(hi - lo) / 2)
    ground = box((12.0, 12.0, 0.05), GROUND, center=(0, 0, -0.025), divisions=(12, 12, 1))
    fov = 35.0
    distance = radius / math.sin(math.radians(fov) / 2) * 1.25
    elevation, azimuth = math.radians(30), math.radians(-70)
    eye = centre + distance * np.array(
        [
            math.cos(elevation) * math.cos(azimuth),
            math.cos(elevation) * math.sin(azimuth),
            math.sin(elevation),
        ]
    )
    d = max(6 * radius, 0.4)

    def around(direction: Sequence[float]) -> tuple[float, float, float]:
        u = np.asarray(direction, float) / np.linalg.norm(direction)
        return tuple(float(x) for x in centre + d * u)  # type: ignore[return-value]

    return Layout(
        parts=((key, part), ("ground", ground)),
        views=((tuple(eye.tolist()), tuple(centre.tolist()), fov),),
        focus=tuple(centre.tolist()),
        single=LightSpot("point", around((-0.4, -0.8, 1.0))),
        pair=(
            LightSpot("point", around((-0.9, -0.5, 0.8))),
            LightSpot("point", around((0.9, -0.4, 0.9))),
        ),
    )


def _room_living() -> Layout:
    """A living room: red and cream walls meet behind a table with a vase, cup and apple; a
    shelf with a printed box and a frog; a chair."""
    w, d, h = 4.0, 3.5, 2.6
    shell = room(
        (w, d, h),
        {
            "floor": _M + "10YR 5/4",
            "ceiling": "flat:0.8",
            "left": _M + "5R 5/12",
            "right": _M + "2.5Y 8/4",
            "back": "flat:0.75",
            "front": "flat:0.75",
        },
    )
    wood = _M + "5YR 4/4"
    table_top = 0.75
    parts = [(f"wall-{k}", p) for k, p in shell.items()]
    parts += [
        ("table", table(1.2, 0.8, table_top, wood, center=(1.4, 2.3, 0))),
        ("vase", moved(OBJECTS["vase"](), scale=1.6, translate=(1.2, 2.45, table_top))),
        (
            "cup",
            moved(
                OBJECTS["cup"](),
                scale=1.5,
                rotate_deg=(0, 0, 200),
                translate=(1.65, 2.15, table_top),
            ),
        ),
        ("apple", moved(OBJECTS["apple"](), scale=1.3, translate=(1.85, 2.45, table_top))),
        ("shelf", shelf(1.0, 0.4, 1.6, _M + "7.5Y 8/6", boards=3, center=(3.2, d - 0.2, 0))),
        ("box", moved(OBJECTS["box"](), scale=1.3, translate=(3.0, d - 0.22, 0.03))),
        ("frog", moved(OBJECTS["frog"](), scale=2.0, translate=(3.35, d - 0.24, 0.5533))),
        ("chair", chair(0.45, 0.45, _M + "5PB 4/10", center=(2.3, 1.8, 0), facing_deg=60)),
    ]
    focus = (1.6, 2.3, table_top + 0.1)
    return Layout(
        parts=tuple(parts),
        views=(
            ((2.8, 0.3, 1.6), focus, 60.0),
            ((0.4, 0.4, 1.4), (1.6, 2.5, 0.7), 60.0),
            ((3.6, 0.8, 1.2), (2.6, 3.0, 0.6), 65.0),
        ),
        focus=focus,
        single=LightSpot("point", (2.0, 1.75, 2.3)),
        pair=(LightSpot("point", (0.8, 1.4, 2.2)), LightSpot("point", (3.2, 1.6, 2.2))),
    )


def _room_corner() -> Layout:
    """A small room whose green and yellow walls form a concave corner holding a stack of
    coloured cubes, a turtle, a deer and a chair, lit by spots."""
    w, d, h = 2.6, 2.6, 2.4
    shell = room(
        (w, d, h),
        {
            "floor": "flat:0.6",
            "ceiling": "flat:0.8",
            "left": _M + "5G 5/8",
            "right": "flat:0.7",
            "back": _M + "5Y 8/10",
            "front": "flat:0.7",
        },
    )
    parts = [(f"wall-{k}", p) for k, p in shell.items()]
    parts += [
        (
            "cube-red",
            box((0.5, 0.5, 0.5), _M + "5R 4/12", center=(0.3, d - 0.3, 0.25), divisions=(2, 2, 2)),
        ),
        (
            "cube-blue",
            box((0.4, 0.4, 0.4), _M + "5PB 5/10", center=(0.3, d - 0.3, 0.7), divisions=(2, 2, 2)),
        ),
        ("cube-purple", box((0.35, 0.35, 0.35), _M + "5P 4/10", center=(0.85, d - 0.25, 0.175))),
        (
            "turtle",
            moved(OBJECTS["turtle"](), scale=2.0, rotate_deg=(0, 0, 30), translate=(1.1, 1.5, 0)),
        ),
        (
            "deer",
            moved(OBJECTS["deer"](), scale=2.0, rotate_deg=(0, 0, -40), translate=(1.7, 1.9, 0)),
        ),
        ("chair", chair(0.45, 0.45, _M + "10R 5/10", center=(2.0, 0.9, 0), facing_deg=-120)),
    ]
    focus = (0.8, 1.9, 0.4)
    return Layout(
        parts=tuple(parts),
        views=(
            ((2.2, 0.3, 1.5), focus, 60.0),
            ((1.3, 0.2, 0.8), (0.9, 2.0, 0.4), 55.0),
            ((2.3, 1.2, 1.9), (0.6, 2.2, 0.3), 60.0),
        ),
        focus=focus,
        single=LightSpot("spot", (1.6, 0.8, 2.2)),
        pair=(LightSpot("spot", (0.6, 0.6, 2.2)), LightSpot("point", (2.0, 1.6, 2.1))),
    )


def _room_studio() -> Layout:
    """A studio under ceiling panels: a blue wall, a shelf of coloured books, a desk with a
    printed page and a mug, a vase on the floor."""
    w, d, h = 3.0, 3.0, 2.5
    shell = room(
        (w, d, h),
        {
            "floor": _M + "2.5Y 8/4",
            "ceiling": "flat:0.8",
            "left": "flat:0.75",
            "right": _M + "5PB 5/10",
            "back": "flat:0.75",
            "front": "flat:0.75",
        },
    )
    parts = [(f"wall-{k}", p) for k, p in shell.items()]
    books = [_M + "5RP 5/12", _M + "10GY 6/8", _M + "7.5R 6/10", _M + "5B 5/8", _M + "10YR 7/10"]
    book_parts = [
        box(
            (0.06, 0.25, 0.3 - 0.03 * (i % 3)),
            books[i % len(books)],
            center=(2.0 + 0.07 * i, d - 0.2, 0.03 + (0.3 - 0.03 * (i % 3)) / 2),
        )
        for i in range(8)
    ]
    parts += [
        ("shelf", shelf(1.2, 0.4, 1.5, "flat:0.7", boards=3, center=(2.3, d - 0.2, 0))),
        ("books", merge(*book_parts)),
        ("desk", table(1.0, 0.6, 0.72, _M + "5YR 4/4", center=(0.9, 2.2, 0))),
        ("paper", moved(OBJECTS["paper"](), rotate_deg=(0, 0, 10), translate=(0.8, 2.15, 0.72))),
        ("cup", moved(OBJECTS["cup"](), scale=1.4, translate=(1.2, 2.3, 0.72))),
        ("vase", moved(OBJECTS["vase"](), scale=2.5, translate=(1.9, 1.4, 0))),
    ]
    focus = (1.4, 2.1, 0.6)
    return Layout(
        parts=tuple(parts),
        views=(
            ((1.5, 0.2, 1.5), focus, 60.0),
            ((0.3, 0.5, 1.3), (1.2, 2.3, 0.6), 55.0),
            ((2.7, 0.4, 1.1), (1.7, 2.2, 0.6), 60.0),
        ),
        focus=focus,
        single=LightSpot("area", (1.3, 1.6, h - 0.05), (0.6, 0.6)),
        pair=(
            LightSpot("area", (0.7, 1.5, h - 0.05), (0.5, 0.5)),
            LightSpot("area", (2.2, 1.7, h - 0.05), (0.5, 0.5)),
        ),
    )


ROOM_LAYOUTS: dict[str, Callable[[], Layout]] = {
    "room-living": _room_living,
    "room-corner": _room_corner,
    "room-studio": _room_studio,
}
