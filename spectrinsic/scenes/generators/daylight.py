"""Daylight for generated rooms (``dataset --generator rooms --daylight-share F``): one window
in one wall, the sun shining in through it and the sky seen through it.

The sun is a ``directional`` light with a CIE daylight spectrum (CIE 015:2018 D-series) of
correlated colour temperature in :data:`SUN_CCT` (direct sunlight at mid elevations is about
5000-5800 K); the sky a uniform ``sky`` dome (Mitsuba ``constant``) of a temperature in
:data:`SKY_CCT` (clear blue sky, about 7000-15000 K; Wyszecki & Stiles 1982, section 1.2).
The sun's irradiance normal to its rays is ``TARGET_IRRADIANCE`` times a factor in
:data:`SUN_GAIN`; the sky's irradiance on an unoccluded horizontal surface (π × its radiance)
is a fraction in :data:`SKY_TO_SUN` of that, the diffuse-to-direct ratio of clear skies.
A daylight room is closed (four walls, a ceiling) with this one opening, so sun and sky come
in through the window only. The window is an axis-aligned box through the wall,
:attr:`Daylight.opening`; the sun patch on the floor follows from it and the sun direction in
closed form (``tests/scenes/generators/test_daylight_rooms.py``).

How much of the room's light is daylight: each daylight room draws a target share of the
radiant flux entering the room, :data:`FLUX_SHARE` (``--daylight-only``: 1), and
:meth:`Daylight.room_lights` scales the room's electric lights so that sun and sky carry that
share of the total flux (:func:`window_flux` against :func:`lamp_flux`), or drops them for a
daylight-only room. A closed room reflects all light alike, so the flux share sets roughly the
light share of what a camera sees; the measured distribution is in ``docs/daylight.md``.
Without this balance the lamps, set to light the room's focus at the target irradiance,
outshone the window: sun and sky gave 1-6 % of the light in 7 of 8 rooms (issue 42).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ...errors import SceneError
from ..library import TARGET_IRRADIANCE
from ..model import Light, light_power, make_light

__all__ = [
    "FLUX_SHARE",
    "ONLY_FLUX_DENSITY",
    "SKY_CCT",
    "SKY_TO_SUN",
    "SUN_CCT",
    "SUN_GAIN",
    "Daylight",
    "draw_daylight",
    "lamp_flux",
    "window_flux",
]

SUN_CCT = (4800.0, 6000.0)  # K
SKY_CCT = (7000.0, 15000.0)  # K
SUN_GAIN = (0.5, 2.0)  # sun irradiance / TARGET_IRRADIANCE
SKY_TO_SUN = (0.1, 0.3)  # sky horizontal irradiance / sun irradiance normal to its rays
#: Range of the share of the room's radiant flux that sun and sky carry in a mixed room (drawn
#: uniformly): from lamps dominating to daylight dominating, neither alone.
FLUX_SHARE = (0.2, 0.9)
#: A daylight-only room's window flux per m² of its surfaces (Φ/A, the mean irradiance of the
#: light's first incidence), as a fraction of ``TARGET_IRRADIANCE``: sun and sky are scaled to
#: it, so the room, not the sun patch, is exposed as the lamps' rooms are (the patch is then
#: some 10-50 times brighter, as in real sunlit rooms).
ONLY_FLUX_DENSITY = 0.25
#: Room walls and the direction into the room from each (rooms span [0,w] x [0,d] x [0,h]).
_INWARD = {"left": (1.0, 0.0, 0.0), "right": (-1.0, 0.0, 0.0), "back": (0.0, -1.0, 0.0)}
_INWARD["front"] = (0.0, 1.0, 0.0)


@dataclass(frozen=True)
class Daylight:
    """The window, sun and sky of a daylight room.

    Attributes
    ----------
    wall
        The wall with the window (``left``, ``right``, ``back``, ``front``).
    hole
        ``(a, b, sill, head)``: the opening spans fractions a..b of the wall's length and
        heights sill..head (m), as the rooms generator's wall openings.
    opening
        ``(lo, hi)``: the opening as an axis-aligned box through the wall (m).
    lights
        The sun (``directional``, named ``sun``) and the sky (``sky``, named ``sky``).
    share
        The share of the room's radiant flux that sun and sky carry, 0 < share <= 1 (1: a
        daylight-only room, no lamps).
    """

    wall: str
    hole: tuple[float, float, float, float]
    opening: tuple[tuple[float, float, float], tuple[float, float, float]]
    lights: tuple[Light, ...]
    share: float = 1.0

    def room_lights(self, lamps: tuple[Light, ...]) -> tuple[Light, ...]:
        """The room's lights: *lamps* scaled so that sun and sky carry :attr:`share` of the
        flux (none of them when the share is 1), then the sun and the sky."""
        if self.share >= 1.0:
            return self.lights
        electric = sum(lamp_flux(lamp) for lamp in lamps)
        scale = window_flux(self) * (1.0 - self.share) / (self.share * electric)
        return tuple(replace(lamp, power=lamp.power * scale) for lamp in lamps) + self.lights

    def info(self) -> dict[str, Any]:
        """The scene metadata entry (``daylight``): window box, sun direction and spectra."""
        sun, sky = self.lights
        return {
            "wall": self.wall,
            "opening": [list(self.opening[0]), list(self.opening[1])],
            "sun_direction": list(sun.direction),
            "sun": sun.spectrum,
            "sky": sky.spectrum,
            "flux_share": self.share,
        }


def window_flux(day: Daylight) -> float:
    """Radiant flux (relative units) the sun and sky send through the window opening of area
    A: ``E A cos θ`` from a sun of irradiance E at angle θ to the wall's normal, and ``π L A``
    from the half of a uniform sky of radiance L outside the wall. Approximation: the wall's
    thickness (its reveal) is not counted."""
    lo, hi = (np.asarray(c, float) for c in day.opening)
    inward = np.asarray(_INWARD[day.wall])
    along = np.delete(hi - lo, int(np.argmax(np.abs(inward))))
    area = float(along[0] * along[1])
    sun, sky = day.lights
    return area * (sun.power * abs(float(np.dot(sun.direction, inward))) + math.pi * sky.power)


def lamp_flux(light: Light) -> float:
    """Radiant flux (relative units) of a light placed in a room: ``4π I`` for a point light of
    intensity I, ``2π (1 - cos θc) I`` for a spot of cone half-angle θc (an upper bound:
    Mitsuba's spot falls off smoothly from 3/4 θc), ``π L A`` for a one-sided area light of
    radiance L and area A."""
    if light.kind == "point":
        return 4.0 * math.pi * light.power
    if light.kind == "spot":
        return 2.0 * math.pi * (1.0 - math.cos(math.radians(light.cutoff_deg))) * light.power
    if light.kind == "area":
        return math.pi * light.power * light.size[0] * light.size[1]
    raise SceneError(f"lamp_flux: a {light.kind!r} light does not stand in a closed room")


def _sun_direction(
    rng: np.random.Generator, wall: str, depth: float, sill: float
) -> tuple[float, float, float]:
    """Unit direction the sunlight travels: into the room through *wall*, 30 degrees at most off
    its normal sideways, and steep enough that the patch starts on the floor (the floor point
    below the sill's edge lies at least 0.3 m inside a room *depth* m deep)."""
    inward = np.array(_INWARD[wall])
    along = np.abs(np.cross(inward, (0.0, 0.0, 1.0)))
    least = math.degrees(math.atan2(sill, depth - 0.3))
    elevation = math.radians(rng.uniform(max(25.0, least + 2.0), 60.0))
    lateral = math.radians(rng.uniform(-30.0, 30.0))
    flat = math.cos(lateral) * inward + math.sin(lateral) * along
    d = math.cos(elevation) * flat - np.array([0.0, 0.0, math.sin(elevation)])
    return (float(d[0]), float(d[1]), float(d[2]))


def draw_daylight(
    rng: np.random.Generator,
    size: tuple[float, float, float],
    thickness: float,
    *,
    only: bool = False,
) -> Daylight:
    """A window in one wall of the room of *size* ``(w, d, h)`` m with walls *thickness* m
    thick, and a sun and sky shining through it (see the module docstring); with *only*, the
    room's only light (its flux share is 1, sun and sky scaled to :data:`ONLY_FLUX_DENSITY`)."""
    w, d, h = size
    wall = tuple(_INWARD)[int(rng.integers(len(_INWARD)))]
    axis = 1 if wall in ("left", "right") else 0
    length, depth = (d, w) if axis == 1 else (w, d)
    a = float(rng.uniform(0.2, 0.45))
    b = a + float(rng.uniform(0.25, 0.4))
    sill = float(rng.uniform(0.5, 0.9))
    hole = (a, b, sill, float(rng.uniform(1.7, min(2.2, h - 0.15))))
    lo, hi = np.zeros(3), np.zeros(3)
    lo[axis], hi[axis] = hole[0] * length, hole[1] * length
    lo[1 - axis] = {"left": -thickness, "right": w, "back": d, "front": -thickness}[wall]
    hi[1 - axis] = lo[1 - axis] + thickness
    lo[2], hi[2] = hole[2], hole[3]
    direction = _sun_direction(rng, wall, depth, hole[2])
    sun_t, sky_t = (int(round(rng.uniform(*r), -1)) for r in (SUN_CCT, SKY_CCT))
    e_sun = TARGET_IRRADIANCE * float(rng.uniform(*SUN_GAIN))
    e_sky = e_sun * float(rng.uniform(*SKY_TO_SUN))
    zero = np.zeros(3)
    sun = make_light(
        "directional",
        f"daylight:{sun_t}K",
        light_power("directional", zero, zero, zero, (1.0, 1.0), e_sun),
        name="sun",
        direction=direction,
    )
    sky = make_light(
        "sky",
        f"daylight:{sky_t}K",
        light_power("sky", zero, zero, zero, (1.0, 1.0), e_sky),
        name="sky",
    )
    box = (tuple(float(x) for x in lo), tuple(float(x) for x in hi))
    share = float(rng.uniform(*FLUX_SHARE))  # drawn last: the window and sun stay as they were
    day = Daylight(wall=wall, hole=hole, opening=box, lights=(sun, sky), share=share)  # type: ignore[arg-type]
    if not only:
        return day
    area = 2.0 * (w * d + w * h + d * h)
    gain = ONLY_FLUX_DENSITY * TARGET_IRRADIANCE * area / window_flux(day)
    lights = tuple(replace(light, power=light.power * gain) for light in day.lights)
    return replace(day, lights=lights, share=1.0)
