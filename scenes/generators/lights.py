"""Lights for generated scenes: 1-4 lights of every kind, random positions and powers, and
spectra from the Planckian range, CIE daylight, LEDs, fluorescents and the SFU measured set.

Condition families (as in the library): ``white`` (every light CIE D65), ``one-colour`` (every
light one coloured SPD at least :data:`~spectrinsic.scenes.library.MIN_XY_DISTANCE` from D65 in
CIE 1931 xy) and ``two-colour`` (two coloured SPDs that far apart, alternating over >= 2 lights).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from spectrinsic.errors import SceneError
from spectrinsic.scenes.library import MIN_XY_DISTANCE, TARGET_IRRADIANCE, WHITE
from spectrinsic.scenes.model import (
    LIGHT_FIELDS,
    LIGHT_KINDS,
    Light,
    LightKind,
    light_power,
    make_light,
)
from spectrinsic.spectra import get_sensors, get_spectrum, responses, xyz_to_xy

__all__ = ["FAMILIES", "LightVolume", "draw_illuminant", "draw_lights"]

FAMILIES: tuple[str, ...] = ("white", "one-colour", "two-colour")
_LEDS = (
    "cie:LED-B1",
    "cie:LED-B2",
    "cie:LED-B3",
    "cie:LED-B4",
    "cie:LED-B5",
    "cie:LED-BH1",
    "cie:LED-RGB1",
    "cie:LED-V1",
    "cie:LED-V2",
)
_FLUORESCENTS = tuple(f"cie:FL{i}" for i in range(1, 13))


@dataclass(frozen=True)
class LightVolume:
    """Where lights may go: the box ``[lo, hi]`` (metres), the point they aim at, and the kinds
    that can light the scene (a directional light cannot enter a room with a ceiling)."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    focus: tuple[float, float, float]
    kinds: tuple[LightKind, ...] = LIGHT_KINDS


def _spd_draws(sfu: Sequence[str]) -> dict[str, Callable[[np.random.Generator], str]]:
    draws: dict[str, Callable[[np.random.Generator], str]] = {
        "planck": lambda r: f"planck:{int(round(r.uniform(2000, 10000), -1))}K",
        "daylight": lambda r: f"daylight:{int(round(r.uniform(4000, 10000), -1))}K",
        "led": lambda r: _LEDS[int(r.integers(len(_LEDS)))],
        "fluorescent": lambda r: _FLUORESCENTS[int(r.integers(len(_FLUORESCENTS)))],
    }
    if sfu:
        draws["sfu"] = lambda r: sfu[int(r.integers(len(sfu)))]
    return draws


def draw_illuminant(rng: np.random.Generator, sfu: Sequence[str] = ()) -> str:
    """One illuminant name: a family drawn uniformly (planck 2000-10000 K, daylight
    4000-10000 K, LED, fluorescent, SFU when *sfu* is given), then a member of it."""
    draws = _spd_draws(sfu)
    family = list(draws)[int(rng.integers(len(draws)))]
    return draws[family](rng)


@functools.lru_cache(maxsize=4096)
def _xy(name: str, data_dir: str | None) -> tuple[float, float]:
    cmf = get_sensors("cie1931")
    spd = get_spectrum(name, data_dir=data_dir).on(cmf.wavelengths)
    x, y = xyz_to_xy(responses(spd, cmf.curves, cmf.wavelengths))
    return float(x), float(y)


def _far(a: str, b: str, data_dir: str | None) -> bool:
    return math.dist(_xy(a, data_dir), _xy(b, data_dir)) >= MIN_XY_DISTANCE


def _family_spectra(
    family: str, n: int, rng: np.random.Generator, sfu: Sequence[str], data_dir: str | None
) -> list[str]:
    """The spectrum of each of *n* lights of a condition *family*."""
    if family == "white":
        return [WHITE] * n
    coloured: list[str] = []
    for _ in range(200):
        name = draw_illuminant(rng, sfu)
        if _far(name, WHITE, data_dir) and all(_far(name, c, data_dir) for c in coloured):
            coloured.append(name)
        if len(coloured) == (1 if family == "one-colour" else 2):
            return [coloured[i % len(coloured)] for i in range(n)]
    raise SceneError(f"could not draw distinct coloured illuminants for {family!r}")


def _one_light(
    i: int,
    kind: LightKind,
    spectrum: str,
    position: np.ndarray,
    volume: LightVolume,
    share: float,
    rng: np.random.Generator,
) -> Light:
    focus = np.asarray(volume.focus, float)
    direction = focus - position
    direction /= np.linalg.norm(direction)
    size = (float(rng.uniform(0.2, 0.8)), float(rng.uniform(0.2, 0.8)))
    power = light_power(kind, position, direction, focus, size, share) * float(
        rng.uniform(0.5, 2.0)
    )
    placement: dict[str, object] = {
        "position": tuple(float(x) for x in position),
        "direction": tuple(float(x) for x in direction),
        "size": size,
    }
    if "cutoff_deg" in LIGHT_FIELDS[kind]:  # drawn only for the kinds that have a cone
        placement["cutoff_deg"] = float(rng.uniform(25.0, 60.0))
    return make_light(kind, spectrum, power, name=f"light{i}", **placement)


def draw_lights(
    rng: np.random.Generator,
    family: str,
    volume: LightVolume,
    *,
    free: Callable[[np.ndarray], bool],
    sfu: Sequence[str] = (),
    data_dir: str | None = None,
    max_lights: int = 4,
) -> tuple[Light, ...]:
    """1-*max_lights* lights of random kinds, positions in *volume* and powers.

    Parameters
    ----------
    family
        One of :data:`FAMILIES` (``two-colour`` always has >= 2 lights).
    free
        ``free(point) -> bool``: whether a position lies in free space (not inside a solid).

    Notes
    -----
    Each light's power is set so all lights together give about ``TARGET_IRRADIANCE`` at the
    focus, then scaled by a random factor in [0.5, 2].
    """
    n = int(rng.integers(2 if family == "two-colour" else 1, max_lights + 1))
    spectra = _family_spectra(family, n, rng, sfu, data_dir)
    lo, hi = np.asarray(volume.lo, float), np.asarray(volume.hi, float)
    lights = []
    for i, spectrum in enumerate(spectra):
        kind = volume.kinds[int(rng.integers(len(volume.kinds)))]
        for _ in range(50):
            position = rng.uniform(lo, hi)
            if free(position):
                break
        else:
            raise SceneError("no free position for a light in the light volume")
        lights.append(_one_light(i, kind, spectrum, position, volume, TARGET_IRRADIANCE / n, rng))
    return tuple(lights)
