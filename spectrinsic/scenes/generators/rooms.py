"""``rooms``: rooms of random size and shape, closed or open (missing walls or ceiling,
window openings), with furniture standing on the floor (tables, round tables, shelves, chairs,
sofas, floor lamps, cabinets) and objects resting on table tops, shelf boards and the floor.
Cameras frame a piece of furniture or an object and see at least :data:`FRAMED_COVERAGE` of
furniture and objects. Open rooms with dark walls let light escape, so the energy ratio r of direct to
total light spans roughly 0.3 (closed, light walls, lit indirectly) to 0.9 (open, dark walls).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ..furniture import chair, floor_lamp, round_table, shelf, shelf_boards, sofa, table
from ..model import DRAWN_LIGHT_KINDS, LIGHT_FIELDS
from ..parts import Part, merge, moved
from ..primitives import box
from .base import GeneratorOptions, Layout
from .camera import Footprints
from .daylight import Daylight, draw_daylight, window_flux
from .lights import LightVolume
from .materials import MaterialDistribution, draw_reflectance, within
from .shapes import draw_object

__all__ = ["rooms"]

_WALLS = ("left", "right", "back", "front")
#: The light kinds with a position, which can hang inside a room with a ceiling.
_PLACED_KINDS = tuple(k for k in DRAWN_LIGHT_KINDS if "position" in LIGHT_FIELDS[k])
#: Placed kinds that can be aimed: the uplights of indirectly lit rooms.
_AIMED_KINDS = tuple(k for k in _PLACED_KINDS if "direction" in LIGHT_FIELDS[k])
_T = 0.1  # wall thickness, m
#: The semantic class of each kind of furniture (:mod:`~spectrinsic.scenes.semantic`; the
#: others are their own class). Rooms draw no window part: a window is an opening.
_FURNITURE_CLASS = {"round-table": "table"}
#: Least fraction of a room view's rays on furniture and objects (not walls, floor, ceiling).
FRAMED_COVERAGE = 0.3


def _slab(lo: np.ndarray, hi: np.ndarray, spectrum: str, semantic: str = "") -> Part:
    """The box from corner *lo* to corner *hi*, of semantic class *semantic*."""
    size = np.maximum(hi - lo, 1e-3)
    div = tuple(max(1, int(round(s * 2))) for s in size)
    part = box(tuple(size), spectrum, center=tuple((lo + hi) / 2), divisions=div)
    return replace(part, semantic=semantic)


def _wall(
    key: str, size: tuple[float, float, float], spectrum: str, hole: tuple[float, ...] | None
) -> Part:
    """Wall *key* of the room ``[0,w]x[0,d]x[0,h]``, with an optional opening ``(a, b, c, e)``:
    along-wall interval [a, b] (fraction of its length) and height interval [c, e] (m)."""
    w, d, h = size
    axis = 1 if key in ("left", "right") else 0
    length = d if axis == 1 else w
    normal_lo = {"left": -_T, "right": w, "back": d, "front": -_T}[key]
    lo, hi = np.zeros(3), np.zeros(3)
    lo[1 - axis], hi[1 - axis] = normal_lo, normal_lo + _T
    pieces = []
    spans = (
        [(0.0, length, 0.0, h)]
        if hole is None
        else [
            (0.0, hole[0] * length, 0.0, h),
            (hole[1] * length, length, 0.0, h),
            (hole[0] * length, hole[1] * length, 0.0, hole[2]),
            (hole[0] * length, hole[1] * length, hole[3], h),
        ]
    )
    for a, b, c, e in spans:
        lo[axis], hi[axis], lo[2], hi[2] = a, b, c, e
        if b - a > 1e-3 and e - c > 1e-3:
            pieces.append(_slab(lo.copy(), hi.copy(), spectrum))
    return replace(merge(*pieces), semantic="wall")


def _shell(
    rng: np.random.Generator,
    size: tuple[float, float, float],
    user: MaterialDistribution,
    day: Daylight | None = None,
) -> tuple[list[tuple[str, Part]], dict]:
    """Floor, walls and ceiling; a daylight room (*day*) is closed, with its one window."""
    w, d, h = size
    # half the rooms have light, low-chroma walls (strong interreflection: low r), the others
    # any walls; with missing walls and ceilings this spreads r
    bright = rng.random() < 0.5
    walls = within(
        MaterialDistribution((7.0, 9.5), (0.0, 4.0))
        if bright
        else MaterialDistribution((2.0, 9.0), (0.0, 10.0)),
        user,
    )
    missing = [k for k in _WALLS if k != "back" and rng.random() < 0.3]
    ceiling = rng.random() >= 0.35
    if day is not None:
        missing, ceiling = [], True
    parts = [
        (
            "floor",
            _slab(
                np.array([-_T, -_T, -_T]),
                np.array([w + _T, d + _T, 0.0]),
                draw_reflectance(rng, walls),
                "floor",
            ),
        )
    ]
    if ceiling:
        parts.append(
            (
                "ceiling",
                _slab(
                    np.array([-_T, -_T, h]),
                    np.array([w + _T, d + _T, h + _T]),
                    draw_reflectance(rng, walls),
                    "ceiling",
                ),
            )
        )
    windows = 0
    for key in _WALLS:
        if key in missing:
            continue
        hole = None
        if rng.random() < 0.4:
            a = rng.uniform(0.15, 0.5)
            hole, windows = (
                (a, a + rng.uniform(0.2, 0.4), rng.uniform(0.6, 1.0), rng.uniform(1.6, h - 0.2)),
                windows + 1,
            )
        if day is not None:
            hole, windows = (day.hole if key == day.wall else None), 1
        parts.append((f"wall-{key}", _wall(key, size, draw_reflectance(rng, walls), hole)))
    return parts, {
        "missing_walls": missing,
        "ceiling": ceiling,
        "windows": windows,
        "light_walls": bright,
    }


Support = tuple[np.ndarray, np.ndarray, float, float]  # (lo_xy, hi_xy, z, free height above)


def _piece(
    rng: np.random.Generator, kind: str, spectrum: str
) -> tuple[Part, list[tuple[float, float]]]:
    """One piece of furniture on z = 0 around the origin, and its supports ``(z, free height)``
    as fractions of its footprint's inner rectangle (tops of tables and cabinets, shelf boards)."""
    if kind == "table":
        part = table(rng.uniform(0.6, 1.4), rng.uniform(0.5, 0.9), rng.uniform(0.45, 0.8), spectrum)
        return part, [(float(part.vertices[:, 2].max()), np.inf)]
    if kind == "round-table":
        part = round_table(rng.uniform(0.3, 0.55), rng.uniform(0.45, 0.75), spectrum)
        return part, [(float(part.vertices[:, 2].max()), np.inf)]
    if kind == "shelf":
        th, boards = rng.uniform(0.8, 1.8), int(rng.integers(2, 5))
        part = shelf(rng.uniform(0.6, 1.2), rng.uniform(0.3, 0.45), th, spectrum, boards=boards)
        return part, shelf_boards(th, boards)
    if kind == "chair":
        return chair(
            rng.uniform(0.38, 0.5),
            rng.uniform(0.4, 0.5),
            spectrum,
            facing_deg=float(rng.choice([0, 90, 180, 270])),
        ), []
    if kind == "sofa":
        return sofa(rng.uniform(1.2, 2.2), rng.uniform(0.75, 0.95), spectrum), []
    if kind == "lamp":
        return floor_lamp(rng.uniform(1.3, 1.7), spectrum), []
    tw, td, th = rng.uniform(0.4, 1.0), rng.uniform(0.3, 0.6), rng.uniform(0.4, 1.0)
    return box((tw, td, th), spectrum, center=(0, 0, th / 2), divisions=(3, 3, 3)), [(th, np.inf)]


def _furniture(
    rng: np.random.Generator,
    size: tuple[float, float, float],
    floor: Footprints,
    dist: MaterialDistribution,
) -> tuple[list[tuple[str, Part]], list[Support]]:
    """Tables, shelves, chairs, sofas, lamps and cabinets on the floor; returns them and the
    surfaces objects may rest on (table tops, cabinet tops, shelf boards)."""
    w, d, _ = size
    parts: list[tuple[str, Part]] = []
    tops: list[Support] = []
    kinds = ["table", "round-table", "shelf", "shelf", "chair", "sofa", "lamp", "cabinet"]
    for i in range(int(rng.integers(3, 7))):
        kind = kinds[int(rng.integers(len(kinds)))]
        part, levels = _piece(rng, kind, draw_reflectance(rng, dist))
        lo, hi = part.vertices[:, :2].min(axis=0), part.vertices[:, :2].max(axis=0)
        half = (hi - lo) / 2
        inner_lo, inner_hi = lo + 0.04, hi - 0.04
        if kind == "shelf":  # boards lie between the sides, in front of the back (+y)
            inner_hi = inner_hi - np.array([0.0, 0.03])
        if kind == "round-table":  # the square inside the round top
            inner_lo, inner_hi = lo * 0.7, hi * 0.7
        for _ in range(30):
            c = rng.uniform(
                [0.05 + half[0], 0.05 + half[1]], [w - 0.05 - half[0], d - 0.05 - half[1]]
            )
            if floor.try_add(c, half, gap=0.05):
                placed = moved(part, translate=(c[0], c[1], 0.0))
                semantic = _FURNITURE_CLASS.get(kind, kind)
                parts.append((f"{kind}-{i}", replace(placed, semantic=semantic)))
                tops += [(c + inner_lo, c + inner_hi, z, room) for z, room in levels]
                break
    return parts, tops


def _objects(
    rng: np.random.Generator,
    size: tuple[float, float, float],
    floor: Footprints,
    tops: list[Support],
    options: GeneratorOptions,
) -> tuple[list[tuple[str, Part]], list[str]]:
    """3-10 objects resting on table tops and shelf boards (preferred) or the floor, without
    overlaps and below the board above."""
    w, d, _ = size
    parts: list[tuple[str, Part]] = []
    patterns: list[str] = []
    supports = [(lo, hi, z, room, Footprints([])) for lo, hi, z, room in tops]
    supports.append((np.array([0.1, 0.1]), np.array([w - 0.1, d - 0.1]), 0.0, np.inf, floor))
    for i in range(int(rng.integers(3, 11))):
        shape, part, pattern, half = draw_object(rng, options.materials, options.sfu_reflectances)
        tall = float(np.ptp(part.vertices[:, 2]))
        for _ in range(20):
            lo, hi, z, room, taken = supports[int(rng.integers(len(supports)))]
            if np.any(hi - lo < 2 * half) or tall > room - 0.02:
                continue
            c = rng.uniform(lo + half, hi - half)
            if taken.try_add(c, half):
                placed = moved(part, translate=(c[0], c[1], z))
                parts.append((f"{shape}-{i}", replace(placed, semantic="object")))
                patterns += [pattern] if pattern else []
                break
    return parts, patterns


def _light_volume(
    rng: np.random.Generator, size: tuple[float, float, float], openness: dict
) -> tuple[LightVolume, str]:
    """Where the lights go, and whether they light the room ``"direct"`` or ``"indirect"``.

    Three in four light rooms with a ceiling are lit indirectly: spots and panels below the
    ceiling aim up at it, so the visible surfaces get their light after one bounce or more.
    These give the lowest energy ratios r (direct / total), down to about 0.3 and below;
    lights aimed at the furniture give the high ones.
    """
    w, d, h = size
    if openness["ceiling"] and openness["light_walls"] and rng.random() < 0.75:
        return LightVolume(
            lo=(0.4, 0.4, 0.35 * h),
            hi=(w - 0.4, d - 0.4, 0.6 * h),
            focus=(w / 2, d / 2, h),
            kinds=_AIMED_KINDS,
        ), "indirect"
    return LightVolume(
        lo=(0.3, 0.3, 0.6 * h),
        hi=(w - 0.3, d - 0.3, h - 0.15),
        focus=(w / 2, d / 2, 0.6),
        kinds=_PLACED_KINDS if openness["ceiling"] else DRAWN_LIGHT_KINDS,
    ), "direct"


def _framing(
    size: tuple[float, float, float], parts: list[Part]
) -> Callable[[np.random.Generator], tuple[np.ndarray, np.ndarray, float]]:
    """Camera proposals that frame one piece of furniture or object and its neighbours: the
    camera stands 1-1.7 times the distance at which the piece fills the field of view, at eye
    or seated height, looking at it from a random side (clipped to the room)."""
    w, d, h = size
    spots = [
        (
            (p.vertices.min(axis=0) + p.vertices.max(axis=0)) / 2,
            max(float(np.linalg.norm(np.ptp(p.vertices, axis=0))) / 2, 0.15),
        )
        for p in parts
    ]
    spots = spots or [(np.array([w / 2, d / 2, 0.5]), 0.5)]

    def propose(r: np.random.Generator) -> tuple[np.ndarray, np.ndarray, float]:
        aim, radius = spots[int(r.integers(len(spots)))]
        fov = float(r.uniform(45, 70))
        distance = max(radius / np.sin(np.radians(fov) / 2) * r.uniform(1.0, 1.7), 0.6)
        azimuth = r.uniform(0, 2 * np.pi)
        origin = aim + distance * np.array([np.cos(azimuth), np.sin(azimuth), 0.0])
        origin[:2] = np.clip(origin[:2], 0.25, [w - 0.25, d - 0.25])
        origin[2] = r.uniform(0.8, min(1.8, h - 0.3))
        return origin, aim + r.uniform(-0.1, 0.1, 3) * radius, fov

    return propose


def rooms(rng: np.random.Generator, options: GeneratorOptions) -> Layout:
    """Lay out a generated room (see the module docstring)."""
    size = (
        float(rng.uniform(2.5, 6.0)),
        float(rng.uniform(2.5, 6.0)),
        float(rng.uniform(2.3, 3.2)),
    )
    w, d, h = size
    # a child generator leaves the layout's draws as they were: rooms not drawn for daylight
    # (all of them with --daylight-share 0, the default) are unchanged
    day_rng = rng.spawn(1)[0] if options.daylight_share > 0 else None
    day = None
    if day_rng is not None and day_rng.random() < options.daylight_share:
        day = draw_daylight(day_rng, size, _T, only=options.daylight_only)
    shell, openness = _shell(rng, size, options.materials, day)
    floor = Footprints([])
    furniture, tops = _furniture(
        rng, size, floor, within(MaterialDistribution((2, 8), (0, 12)), options.materials)
    )
    objects, patterns = _objects(rng, size, floor, tops, options)
    propose = _framing(size, [p for _, p in furniture + objects])
    volume, lighting = _light_volume(rng, size, openness)
    info = {
        "generator": "rooms",
        "kind": "complex",
        "room_size": list(size),
        **openness,
        "lighting": lighting,
        "n_furniture": len(furniture),
        "n_objects": len(objects),
        "shapes": [n.rsplit("-", 1)[0] for n, _ in objects],
        "patterns": patterns,
    }
    if day is not None:
        info["daylight"] = day.info()
    return Layout(
        parts=(*shell, *furniture, *objects),
        lights=volume,
        propose_camera=propose,
        info=info,
        min_coverage=FRAMED_COVERAGE,
        view_rule=True,
        room_lights=None if day is None else day.room_lights,
        flux_density=0.0 if day is None else window_flux(day) / (2 * (w * d + w * h + d * h)),
    )
