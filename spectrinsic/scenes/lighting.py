"""A sample's lighting as data: how many lights, which spectra, how far apart their colours are.

Every source of samples (the library's four conditions, the generators' ``white`` /
``one-colour`` / ``two-colour`` families, a user's scene files, relit samples) records its
lights in ``meta.json`` (``lights[i]``: ``spectrum``, ``xy`` chromaticity, ``share`` of the
image's luminance). :func:`describe_lighting` reads those records and measures the condition,
so an evaluation groups samples by what they hold, not by a fixed list of condition names:

* ``WL``: one light colour, and it is white (CIE 1931 xy within :data:`WHITE_XY_TOLERANCE` of
  D65, the library's white);
* ``1L``: one light colour, not white;
* ``2L``: two or more light colours (xy more than :data:`SAME_COLOUR_XY` apart).

These are the columns of thesis Tables 5.3/5.4 (white light, one coloured light, two coloured
lights); the library's conditions fall in them as the thesis groups them
(``white`` -> WL, ``one-colour`` -> 1L, ``two-colour-a/b`` -> 2L).

>>> d = describe_lighting([{"spectrum": "cie:D65", "xy": [0.3127, 0.3290], "share": 1.0}])
>>> d.group, d.family, d.n_lights, d.n_colours
('WL', 'white', 1, 1)
>>> two = [{"spectrum": "cie:A", "xy": [0.4476, 0.4074], "share": 0.6},
...        {"spectrum": "cie:F2", "xy": [0.3721, 0.3751], "share": 0.4}]
>>> d = describe_lighting(two)
>>> d.group, round(d.xy_spread, 3)
('2L', 0.082)
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

__all__ = [
    "GROUPS",
    "LightingCondition",
    "SAME_COLOUR_XY",
    "WHITE_XY",
    "WHITE_XY_TOLERANCE",
    "describe_lighting",
]

#: The lighting groups, in the tables' order (thesis Tables 5.3/5.4).
GROUPS: tuple[str, ...] = ("WL", "1L", "2L")
#: CIE 1931 xy of D65 (the library's white, ``cie:D65``), 2-degree observer.
WHITE_XY: tuple[float, float] = (0.31271, 0.32902)
#: Largest xy distance from :data:`WHITE_XY` of a light counted as white (the library's coloured
#: lights are at least 0.03 from white: ``scenes.library.MIN_XY_DISTANCE``).
WHITE_XY_TOLERANCE = 0.01
#: Lights whose xy are closer than this count as one colour.
SAME_COLOUR_XY = 0.01


@dataclass(frozen=True)
class LightingCondition:
    """What a sample's lights are, measured from their records.

    Attributes
    ----------
    n_lights
        Lights that reach the image (``share > 0``; all of them when no share is recorded).
    spectra
        Their distinct spectrum names, in the order they first appear.
    n_colours
        Distinct light colours (xy more than :data:`SAME_COLOUR_XY` apart).
    xy_spread
        Largest CIE 1931 xy distance between two of the lights (0 for one colour), unitless.
    white
        Every light is white (within :data:`WHITE_XY_TOLERANCE` of D65).
    """

    n_lights: int
    spectra: tuple[str, ...]
    n_colours: int
    xy_spread: float
    white: bool

    @property
    def family(self) -> str:
        """The generators' name of the group: ``white``, ``one-colour`` or ``two-colour``."""
        return {"WL": "white", "1L": "one-colour", "2L": "two-colour"}[self.group]

    @property
    def group(self) -> str:
        """``"WL"``, ``"1L"`` or ``"2L"`` (module docstring)."""
        if self.n_colours >= 2:
            return "2L"
        return "WL" if self.white else "1L"


def _distance(a: Sequence[float], b: Sequence[float]) -> float:
    return math.hypot(float(a[0]) - float(b[0]), float(a[1]) - float(b[1]))


def describe_lighting(lights: Sequence[Mapping[str, Any]]) -> LightingCondition:
    """The :class:`LightingCondition` of the light records *lights* (``meta.json``'s ``lights``).

    Raises
    ------
    ValueError
        No light, or a light without an ``xy`` pair.
    """
    if not lights:
        raise ValueError("no lights recorded; expected at least one light with an 'xy' pair")
    for i, light in enumerate(lights):
        xy = light.get("xy")
        if not isinstance(xy, Sequence) or len(xy) != 2:
            raise ValueError(f"lights[{i}].xy is {xy!r}; expected an [x, y] pair")
    lit = [light for light in lights if float(light.get("share", 1.0)) > 0.0] or list(lights)
    colours: list[Sequence[float]] = []
    for light in lit:
        if all(_distance(light["xy"], c) > SAME_COLOUR_XY for c in colours):
            colours.append(light["xy"])
    spread = max((_distance(a, b) for a in colours for b in colours), default=0.0)
    spectra = tuple(dict.fromkeys(str(light.get("spectrum", "")) for light in lit))
    white = all(_distance(light["xy"], WHITE_XY) <= WHITE_XY_TOLERANCE for light in lit)
    return LightingCondition(len(lit), spectra, len(colours), spread, white)
