"""Lights for generated scenes: 1-4 lights of every kind, random positions and powers, and
spectra from whites (Planckian range, CIE daylight, white LEDs, fluorescents, SFU measured set)
and saturated sources (narrow-band LEDs, RGB-mix LEDs, lamps behind colour filters).

Condition families (as in the library): ``white`` (every light CIE D65), ``one-colour`` (every
light one coloured SPD at least :data:`~spectrinsic.scenes.library.MIN_XY_DISTANCE` from D65 in
CIE 1931 xy) and ``two-colour`` (two coloured SPDs at least :data:`TWO_COLOUR_XY` apart,
alternating over >= 2 lights). A coloured light is drawn from the saturated pools with
probability :data:`SATURATED_SHARE`, else from the whites of other temperatures; an optional
saturation range keeps only lights whose |Duv| (Ohno 2013, CIE 1960 uv distance from the
Planckian locus) lies in it.

Why |Duv| and not the xy distance from D65: a 2000 K black body is 0.23 from D65 in xy yet
reads as a warm white, while a green-tinted light 0.05 from D65 reads as coloured; Duv measures
the tint off the locus of whites, whatever the temperature. Its blind spot, deep red and amber
LEDs (which lie on the locus' extension below 1500 K, |Duv| < 0.01), is why the range is a
filter on top of the pools, not the only way to get colour.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ...errors import SceneError
from ...spectra import get_sensors, get_spectrum, responses, xy_to_duv, xyz_to_xy
from ..library import MIN_XY_DISTANCE, TARGET_IRRADIANCE, WHITE
from ..model import DRAWN_LIGHT_KINDS, LIGHT_FIELDS, Light, LightKind, light_power, make_light

__all__ = [
    "FAMILIES",
    "SATURATED_SHARE",
    "TWO_COLOUR_XY",
    "MAX_SATURATION_LOW",
    "LightVolume",
    "check_saturation",
    "draw_illuminant",
    "draw_lights",
    "light_duv",
    "light_xy",
]

FAMILIES: tuple[str, ...] = ("white", "one-colour", "two-colour")
#: Least CIE 1931 xy distance between the two colours of a ``two-colour`` scene: about 20
#: MacAdam steps (one step is 0.001-0.004 in xy), a difference everyone sees side by side.
TWO_COLOUR_XY = 0.08
#: Probability that a coloured light comes from the saturated pools (LEDs, filtered lamps).
SATURATED_SHARE = 0.6
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
_LAMPS = ("cie:A", "cie:LED-B3", "cie:FL2", "planck:3000K", "planck:4500K", "daylight:6500K")
#: Highest lower bound of a |Duv| range: about 1 in 6 saturated draws lies above 0.15, few
#: above 0.2 (the violet and green ends of the spectrum locus).
MAX_SATURATION_LOW = 0.15
#: Most candidate draws for a family's coloured lights before the scene fails.
_ATTEMPTS = 400


@dataclass(frozen=True)
class LightVolume:
    """Where lights may go: the box ``[lo, hi]`` (metres), the point they aim at, and the kinds
    that can light the scene (a directional light cannot enter a room with a ceiling)."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    focus: tuple[float, float, float]
    kinds: tuple[LightKind, ...] = DRAWN_LIGHT_KINDS


def _spd_draws(sfu: Sequence[str]) -> dict[str, Callable[[np.random.Generator], str]]:
    """Whites of many temperatures (the pools of the library's non-Planckian set)."""
    draws: dict[str, Callable[[np.random.Generator], str]] = {
        "planck": lambda r: f"planck:{int(round(r.uniform(2000, 10000), -1))}K",
        "daylight": lambda r: f"daylight:{int(round(r.uniform(4000, 10000), -1))}K",
        "led": lambda r: _LEDS[int(r.integers(len(_LEDS)))],
        "fluorescent": lambda r: _FLUORESCENTS[int(r.integers(len(_FLUORESCENTS)))],
    }
    if sfu:
        draws["sfu"] = lambda r: sfu[int(r.integers(len(sfu)))]
    return draws


def _narrow_led(r: np.random.Generator) -> str:
    return f"led:{int(r.integers(440, 641))}/{int(r.integers(15, 36))}"


def _rgb_led(r: np.random.Generator) -> str:
    """Three LEDs (red, green, blue) at random peak power ratios: the mixed colours of RGB lamps."""
    peaks = (r.integers(615, 646), r.integers(510, 546), r.integers(445, 476))
    widths = r.integers(15, 36, 3)
    ratios = r.uniform(0.02, 1.0, 3).round(2)
    return "led:" + "+".join(
        f"{int(p)}/{int(w)}@{a:g}" for p, w, a in zip(peaks, widths, ratios, strict=True)
    )


def _filtered(r: np.random.Generator, sfu: Sequence[str]) -> str:
    """A white lamp (or an SFU illuminant) behind a smooth colour filter."""
    lamps = (*_LAMPS, *sfu)
    lamp = lamps[int(r.integers(len(lamps)))]
    shape = ("bandpass", "longpass", "shortpass")[int(r.integers(3))]
    if shape == "bandpass":
        spec = f"bandpass:{int(r.integers(430, 651))}/{int(r.integers(40, 121))}"
    elif shape == "longpass":
        spec = f"longpass:{int(r.integers(500, 621))}/{int(r.integers(20, 61))}"
    else:
        spec = f"shortpass:{int(r.integers(460, 561))}/{int(r.integers(20, 61))}"
    return f"filtered:{lamp}|{spec}"


def _saturated_draws(sfu: Sequence[str]) -> dict[str, Callable[[np.random.Generator], str]]:
    """Saturated sources: narrow-band LEDs, RGB-mix LEDs, filtered lamps (SFU ones with *sfu*)."""
    return {"narrow-led": _narrow_led, "rgb-led": _rgb_led, "filtered": lambda r: _filtered(r, sfu)}


def draw_illuminant(
    rng: np.random.Generator, sfu: Sequence[str] = (), *, saturated: bool = False
) -> str:
    """One illuminant name: a pool drawn uniformly, then a member of it. The white pools are
    planck 2000-10000 K, daylight 4000-10000 K, white LED, fluorescent (SFU when *sfu* is
    given); with *saturated*, narrow-band LED, RGB-mix LED and filtered lamp."""
    draws = _saturated_draws(sfu) if saturated else _spd_draws(sfu)
    family = list(draws)[int(rng.integers(len(draws)))]
    return draws[family](rng)


@functools.lru_cache(maxsize=4096)
def light_xy(name: str, data_dir: str | None = None) -> tuple[float, float]:
    """CIE 1931 xy of illuminant *name* (2 degree observer, 360-830 nm)."""
    cmf = get_sensors("cie1931")
    spd = get_spectrum(name, data_dir=data_dir).on(cmf.wavelengths)
    x, y = xyz_to_xy(responses(spd, cmf.curves, cmf.wavelengths))
    return float(x), float(y)


@functools.lru_cache(maxsize=4096)
def light_duv(name: str, data_dir: str | None = None) -> float:
    """Duv of illuminant *name* (Ohno 2013, see :func:`~spectrinsic.spectra.xy_to_duv`)."""
    return float(xy_to_duv(np.array(light_xy(name, data_dir))))


def check_saturation(saturation: tuple[float, float]) -> None:
    """Refuse a |Duv| range that no pool can fill (raises :class:`SceneError`, one line)."""
    lo, hi = saturation
    if not 0.0 <= lo <= hi or lo > MAX_SATURATION_LOW:
        raise SceneError(
            f"light saturation {lo:g},{hi:g}: expected 0 <= LO <= HI and LO <= "
            f"{MAX_SATURATION_LOW:g} (|Duv|, Ohno 2013; 0.02 is visibly tinted)"
        )


def _apart(a: str, b: str, data_dir: str | None, least: float) -> bool:
    return math.dist(light_xy(a, data_dir), light_xy(b, data_dir)) >= least


def _candidate(
    rng: np.random.Generator,
    sfu: Sequence[str],
    data_dir: str | None,
    saturation: tuple[float, float] | None,
) -> str | None:
    """A coloured light (>= MIN_XY_DISTANCE from D65, |Duv| in *saturation*), or None."""
    name = draw_illuminant(rng, sfu, saturated=bool(rng.random() < SATURATED_SHARE))
    if not _apart(name, WHITE, data_dir, MIN_XY_DISTANCE):
        return None
    if (
        saturation is not None
        and not saturation[0] <= abs(light_duv(name, data_dir)) <= saturation[1]
    ):
        return None
    return name


def _family_spectra(
    family: str,
    n: int,
    rng: np.random.Generator,
    sfu: Sequence[str],
    data_dir: str | None,
    saturation: tuple[float, float] | None = None,
) -> list[str]:
    """The spectrum of each of *n* lights of a condition *family*."""
    if family == "white":
        return [WHITE] * n
    coloured: list[str] = []
    for _ in range(_ATTEMPTS):
        name = _candidate(rng, sfu, data_dir, saturation)
        if name is not None and all(_apart(name, c, data_dir, TWO_COLOUR_XY) for c in coloured):
            coloured.append(name)
        if len(coloured) == (1 if family == "one-colour" else 2):
            return [coloured[i % len(coloured)] for i in range(n)]
    raise SceneError(
        f"could not draw distinct coloured illuminants for {family!r}"
        + (f" with |Duv| in {saturation}" if saturation else "")
    )


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
    saturation: tuple[float, float] | None = None,
) -> tuple[Light, ...]:
    """1-*max_lights* lights of random kinds, positions in *volume* and powers.

    Parameters
    ----------
    family
        One of :data:`FAMILIES` (``two-colour`` always has >= 2 lights).
    free
        ``free(point) -> bool``: whether a position lies in free space (not inside a solid).
    saturation
        ``(lo, hi)`` range of |Duv| of the coloured families' lights (None: any).

    Notes
    -----
    Each light's power is set so all lights together give about ``TARGET_IRRADIANCE`` at the
    focus, then scaled by a random factor in [0.5, 2].
    """
    n = int(rng.integers(2 if family == "two-colour" else 1, max_lights + 1))
    spectra = _family_spectra(family, n, rng, sfu, data_dir, saturation)
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
