"""Furniture and rooms as unions of primitives: :func:`table`, :func:`round_table`,
:func:`shelf`, :func:`chair`, :func:`sofa`, :func:`floor_lamp` and :func:`room`.

Room walls are boxes of finite thickness, so the air inside a room is *outside* every solid (a
point's inside/outside status stays well defined for scene validation).

Units: lengths in metres, angles in degrees; +z is up.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..errors import SceneError
from .parts import Part, merge, moved
from .primitives import box, cone, cylinder

__all__ = ["table", "round_table", "shelf", "shelf_boards", "chair", "sofa", "floor_lamp", "room"]


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


def shelf_boards(height: float, boards: int, thickness: float = 0.03) -> list[tuple[float, float]]:
    """``(top z, free height above)`` of each board of :func:`shelf` (the top board: inf), m."""
    zs = np.linspace(thickness / 2, height - thickness / 2, boards + 1) + thickness / 2
    gaps = [float(b - a - thickness) for a, b in zip(zs[:-1], zs[1:], strict=True)]
    return [(float(z), g) for z, g in zip(zs, [*gaps, np.inf], strict=True)]


def round_table(radius: float, height: float, spectrum: str, *, top: float = 0.04) -> Part:
    """A pedestal table standing on z = 0: a round top, a central column and a round foot."""
    return merge(
        cylinder(radius, top, spectrum, center=(0, 0, height - top / 2), sections=32),
        cylinder(0.05, height - top, spectrum, center=(0, 0, (height - top) / 2), sections=16),
        cylinder(radius * 0.55, 0.03, spectrum, center=(0, 0, 0.015), sections=24),
    )


def sofa(width: float, depth: float, spectrum: str, *, seat: float = 0.42) -> Part:
    """A sofa standing on z = 0, its back on the +y side: base, seat cushions, back, arms."""
    arm = 0.15
    cushions = max(1, int(round((width - 2 * arm) / 0.6)))
    cw = (width - 2 * arm) / cushions
    parts = [
        box((width, depth, 0.25), spectrum, center=(0, 0, 0.125)),
        box((width, 0.2, 0.8), spectrum, center=(0, depth / 2 - 0.1, 0.4)),
    ]
    parts += [
        box((arm, depth, 0.6), spectrum, center=(sx * (width - arm) / 2, 0, 0.3)) for sx in (-1, 1)
    ]
    parts += [
        box(
            (cw - 0.01, depth - 0.22, seat - 0.25),
            spectrum,
            center=(-width / 2 + arm + cw * (i + 0.5), -0.1, (0.25 + seat) / 2),
        )
        for i in range(cushions)
    ]
    return merge(*parts)


def floor_lamp(height: float, spectrum: str) -> Part:
    """A floor lamp (unlit) standing on z = 0: a round base, a pole and a conical shade."""
    return merge(
        cylinder(0.15, 0.03, spectrum, center=(0, 0, 0.015), sections=24),
        cylinder(0.015, height - 0.25, spectrum, center=(0, 0, (height - 0.25) / 2), sections=8),
        cone(0.2, 0.3, spectrum, center=(0, 0, height - 0.3), sections=24),
    )


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
