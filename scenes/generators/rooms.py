"""``rooms``: rooms of random size and shape, closed or open (missing walls or ceiling,
window openings), with furniture standing on the floor and objects resting on table tops and
the floor. Open rooms with dark walls let light escape, so the energy ratio r of direct to
total light spans roughly 0.3 (closed, light walls, lit indirectly) to 0.9 (open, dark walls).
"""

from __future__ import annotations

import numpy as np

from spectrinsic.scenes.furniture import chair, shelf, table
from spectrinsic.scenes.generators.base import GeneratorOptions, Layout
from spectrinsic.scenes.generators.camera import Footprints
from spectrinsic.scenes.generators.lights import LightVolume
from spectrinsic.scenes.generators.materials import (
    MaterialDistribution,
    draw_reflectance,
    within,
)
from spectrinsic.scenes.generators.shapes import draw_object
from spectrinsic.scenes.model import LIGHT_FIELDS, LIGHT_KINDS
from spectrinsic.scenes.parts import Part, merge, moved
from spectrinsic.scenes.primitives import box

__all__ = ["rooms"]

_WALLS = ("left", "right", "back", "front")
#: The light kinds with a position, which can hang inside a room with a ceiling.
_PLACED_KINDS = tuple(k for k in LIGHT_KINDS if "position" in LIGHT_FIELDS[k])
#: Placed kinds that can be aimed: the uplights of indirectly lit rooms.
_AIMED_KINDS = tuple(k for k in _PLACED_KINDS if "direction" in LIGHT_FIELDS[k])
_T = 0.1  # wall thickness, m


def _slab(lo: np.ndarray, hi: np.ndarray, spectrum: str) -> Part:
    size = np.maximum(hi - lo, 1e-3)
    div = tuple(max(1, int(round(s * 2))) for s in size)
    return box(tuple(size), spectrum, center=tuple((lo + hi) / 2), divisions=div)


def _wall(key: str, size: tuple[float, float, float], spectrum: str, hole: tuple[float, ...] | None) -> Part:
    """Wall *key* of the room ``[0,w]x[0,d]x[0,h]``, with an optional opening ``(a, b, c, e)``:
    along-wall interval [a, b] (fraction of its length) and height interval [c, e] (m)."""
    w, d, h = size
    axis = 1 if key in ("left", "right") else 0
    length = d if axis == 1 else w
    normal_lo = {"left": -_T, "right": w, "back": d, "front": -_T}[key]
    lo, hi = np.zeros(3), np.zeros(3)
    lo[1 - axis], hi[1 - axis] = normal_lo, normal_lo + _T
    pieces = []
    spans = [(0.0, length, 0.0, h)] if hole is None else [
        (0.0, hole[0] * length, 0.0, h), (hole[1] * length, length, 0.0, h),
        (hole[0] * length, hole[1] * length, 0.0, hole[2]),
        (hole[0] * length, hole[1] * length, hole[3], h)]
    for a, b, c, e in spans:
        lo[axis], hi[axis], lo[2], hi[2] = a, b, c, e
        if b - a > 1e-3 and e - c > 1e-3:
            pieces.append(_slab(lo.copy(), hi.copy(), spectrum))
    return merge(*pieces)


def _shell(rng: np.random.Generator, size: tuple[float, float, float],
           user: MaterialDistribution) -> tuple[list[tuple[str, Part]], dict]:
    w, d, h = size
    # half the rooms have light, low-chroma walls (strong interreflection: low r), the others
    # any walls; with missing walls and ceilings this spreads r
    bright = rng.random() < 0.5
    walls = within(MaterialDistribution((7.0, 9.5), (0.0, 4.0)) if bright
                   else MaterialDistribution((2.0, 9.0), (0.0, 10.0)), user)
    missing = [k for k in _WALLS if k != "back" and rng.random() < 0.3]
    ceiling = rng.random() >= 0.35
    parts = [("floor", _slab(np.array([-_T, -_T, -_T]), np.array([w + _T, d + _T, 0.0]),
                             draw_reflectance(rng, walls)))]
    if ceiling:
        parts.append(("ceiling", _slab(np.array([-_T, -_T, h]), np.array([w + _T, d + _T, h + _T]),
                                       draw_reflectance(rng, walls))))
    windows = 0
    for key in _WALLS:
        if key in missing:
            continue
        hole = None
        if rng.random() < 0.4:
            a = rng.uniform(0.15, 0.5)
            hole, windows = (a, a + rng.uniform(0.2, 0.4), rng.uniform(0.6, 1.0), rng.uniform(1.6, h - 0.2)), windows + 1
        parts.append((f"wall-{key}", _wall(key, size, draw_reflectance(rng, walls), hole)))
    return parts, {"missing_walls": missing, "ceiling": ceiling, "windows": windows, "light_walls": bright}


def _furniture(rng: np.random.Generator, size: tuple[float, float, float], floor: Footprints,
               dist: MaterialDistribution) -> tuple[list[tuple[str, Part]], list[tuple[np.ndarray, np.ndarray, float]]]:
    """Tables, shelves, chairs and cabinets on the floor; returns them and the table tops
    ``(lo_xy, hi_xy, z)`` objects may rest on."""
    w, d, _ = size
    parts, tops = [], []
    kinds = ["table", "table", "shelf", "chair", "cabinet"]
    for i in range(int(rng.integers(2, 6))):
        kind = kinds[int(rng.integers(len(kinds)))]
        spectrum = draw_reflectance(rng, dist)
        if kind == "table":
            tw, td, th = rng.uniform(0.6, 1.4), rng.uniform(0.5, 0.9), rng.uniform(0.45, 0.8)
            part = table(tw, td, th, spectrum)
        elif kind == "shelf":
            tw, td, th = rng.uniform(0.6, 1.2), rng.uniform(0.3, 0.45), rng.uniform(0.8, 1.8)
            part = shelf(tw, td, th, spectrum, boards=int(rng.integers(2, 5)))
        elif kind == "chair":
            tw = rng.uniform(0.38, 0.5)
            part = chair(tw, rng.uniform(0.4, 0.5), spectrum, facing_deg=float(rng.choice([0, 90, 180, 270])))
        else:
            tw, td, th = rng.uniform(0.4, 1.0), rng.uniform(0.3, 0.6), rng.uniform(0.4, 1.0)
            part = box((tw, td, th), spectrum, center=(0, 0, th / 2), divisions=(3, 3, 3))
        half = np.ptp(part.vertices[:, :2], axis=0) / 2
        for _ in range(30):
            c = rng.uniform([0.05 + half[0], 0.05 + half[1]], [w - 0.05 - half[0], d - 0.05 - half[1]])
            if floor.try_add(c, half, gap=0.05):
                parts.append((f"{kind}-{i}", moved(part, translate=(c[0], c[1], 0.0))))
                if kind in ("table", "cabinet"):
                    top = float(part.vertices[:, 2].max())
                    tops.append((c - half + 0.04, c + half - 0.04, top))
                break
    return parts, tops


def _objects(rng: np.random.Generator, size: tuple[float, float, float], floor: Footprints,
             tops: list[tuple[np.ndarray, np.ndarray, float]], options: GeneratorOptions) -> tuple[list[tuple[str, Part]], list[str]]:
    """2-8 objects resting on table tops (preferred) or the floor, without overlaps."""
    w, d, _ = size
    parts: list[tuple[str, Part]] = []
    patterns: list[str] = []
    supports = [(lo, hi, z, Footprints([])) for lo, hi, z in tops]
    supports.append((np.array([0.1, 0.1]), np.array([w - 0.1, d - 0.1]), 0.0, floor))
    for i in range(int(rng.integers(2, 9))):
        shape, part, pattern, half = draw_object(rng, options.materials, options.sfu_reflectances)
        patterns += [pattern] if pattern else []
        for _ in range(20):
            lo, hi, z, taken = supports[int(rng.integers(len(supports)))]
            if np.any(hi - lo < 2 * half):
                continue
            c = rng.uniform(lo + half, hi - half)
            if taken.try_add(c, half):
                parts.append((f"{shape}-{i}", moved(part, translate=(c[0], c[1], z))))
                break
    return parts, patterns


def _light_volume(rng: np.random.Generator, size: tuple[float, float, float],
                  openness: dict) -> tuple[LightVolume, str]:
    """Where the lights go, and whether they light the room ``"direct"`` or ``"indirect"``.

    Three in four light rooms with a ceiling are lit indirectly: spots and panels below the
    ceiling aim up at it, so the visible surfaces get their light after one bounce or more.
    These give the lowest energy ratios r (direct / total), down to about 0.3 and below;
    lights aimed at the furniture give the high ones.
    """
    w, d, h = size
    if openness["ceiling"] and openness["light_walls"] and rng.random() < 0.75:
        return LightVolume(lo=(0.4, 0.4, 0.35 * h), hi=(w - 0.4, d - 0.4, 0.6 * h),
                           focus=(w / 2, d / 2, h), kinds=_AIMED_KINDS), "indirect"
    return LightVolume(lo=(0.3, 0.3, 0.6 * h), hi=(w - 0.3, d - 0.3, h - 0.15),
                       focus=(w / 2, d / 2, 0.6),
                       kinds=_PLACED_KINDS if openness["ceiling"] else LIGHT_KINDS), "direct"


def rooms(rng: np.random.Generator, options: GeneratorOptions) -> Layout:
    """Lay out a generated room (see the module docstring)."""
    size = (float(rng.uniform(2.5, 6.0)), float(rng.uniform(2.5, 6.0)), float(rng.uniform(2.3, 3.2)))
    w, d, h = size
    shell, openness = _shell(rng, size, options.materials)
    floor = Footprints([])
    furniture, tops = _furniture(rng, size, floor,
                                 within(MaterialDistribution((2, 8), (0, 12)), options.materials))
    objects, patterns = _objects(rng, size, floor, tops, options)
    targets = [p.vertices.mean(axis=0) for _, p in objects + furniture] or [np.array([w / 2, d / 2, 0.5])]

    def propose(r: np.random.Generator) -> tuple[np.ndarray, np.ndarray, float]:
        origin = r.uniform([0.25, 0.25, 0.9], [w - 0.25, d - 0.25, min(1.9, h - 0.3)])
        target = targets[int(r.integers(len(targets)))] + r.uniform(-0.1, 0.1, 3)
        return origin, target, float(r.uniform(50, 75))

    volume, lighting = _light_volume(rng, size, openness)
    info = {"generator": "rooms", "room_size": list(size), **openness, "lighting": lighting,
            "n_furniture": len(furniture), "n_objects": len(objects),
            "shapes": [n.rsplit("-", 1)[0] for n, _ in objects], "patterns": patterns}
    return Layout(parts=(*shell, *furniture, *objects), lights=volume, propose_camera=propose,
                  info=info)
