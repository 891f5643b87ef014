"""The built-in scene library (thesis Figs. 5.6-5.7 and Appendix C.2).

- 8 single-object scenes (``obj-apple`` ... ``obj-deer``, :data:`spectrinsic.scenes.objects.OBJECTS`):
  one MIT-like object on a neutral, spectrally flat ground (reflectance 0.5), one view;
- 3 complex scenes (``room-living``, ``room-corner``, ``room-studio``): closed rooms with
  coloured walls, furniture and several objects, with concave arrangements (wall corners,
  shelf compartments, cup and vase cavities) so interreflections and colour bleeding show;
  3 camera viewpoints each;
- 4 illumination conditions (:data:`CONDITIONS`) for every scene and view:

  ``white``
      one light of CIE D65;
  ``one-colour``
      one light drawn from the union of ``illuminant_set("planckian")`` and
      ``illuminant_set("non-planckian")``, at least :data:`MIN_XY_DISTANCE` from D65 in CIE
      1931 xy;
  ``two-colour-a``
      two lights at two positions: one Planckian and one non-Planckian;
  ``two-colour-b``
      two lights drawn from the union, a different pair from ``two-colour-a``.

  The two lights of a pair are at least :data:`MIN_XY_DISTANCE` apart in xy. The draws use
  ``numpy`` generators seeded by :func:`spectrinsic.rng.seed_from_key` from the caller's
  *seed* and the scene name: the same seed gives the same lights for every view of a scene.

Every light's power is set so that the irradiance it delivers at the scene's focus (on a
surface facing it) is ``TARGET_IRRADIANCE / n_lights``: all conditions of a scene are equally
bright and only their colour changes.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from spectrinsic.errors import SceneError, validate_choice
from spectrinsic.rng import generator, seed_from_key
from spectrinsic.scenes import geometry as g
from spectrinsic.scenes.model import Camera, Light, LightKind, Scene, light_power
from spectrinsic.scenes.objects import OBJECTS
from spectrinsic.scenes.sample_id import SampleId
from spectrinsic.spectra import get_sensors, get_spectrum, illuminant_set, responses, xyz_to_xy

__all__ = [
    "CONDITIONS",
    "CONDITION_DESCRIPTIONS",
    "WHITE",
    "MIN_XY_DISTANCE",
    "TARGET_IRRADIANCE",
    "scene_names",
    "n_views",
    "build",
    "condition_illuminants",
    "default_samples",
]

CONDITIONS: tuple[str, ...] = ("white", "one-colour", "two-colour-a", "two-colour-b")
#: One line per condition (``spectrinsic list conditions``); the module docstring has the rules.
CONDITION_DESCRIPTIONS: dict[str, str] = {
    "white": "one light of CIE D65",
    "one-colour": "one coloured light, Planckian or not, distinct from D65",
    "two-colour-a": "two lights of distinct colours: one Planckian, one non-Planckian",
    "two-colour-b": "two lights of distinct colours, a pair other than two-colour-a",
}
#: The spectrum of the ``white`` condition.
WHITE = "cie:D65"
#: Least CIE 1931 xy distance between the two lights of a pair and between a coloured light and
#: D65 (the 4000 K-like fluorescents and LED lie within 0.01 of each other and are not distinct).
MIN_XY_DISTANCE = 0.03
#: Irradiance (relative units) at the scene's focus from all lights of a condition together.
TARGET_IRRADIANCE = math.pi
#: Cone half-angle of the library's spot lights.
SPOT_CUTOFF_DEG = 40.0
GROUND = "flat:0.5"
_M = "munsell:"


@dataclass(frozen=True)
class _LightSpot:
    """Where a light of a rig sits, and where it points."""

    kind: LightKind
    position: tuple[float, float, float]
    size: tuple[float, float] = (0.5, 0.5)


@dataclass(frozen=True)
class _Layout:
    """Geometry, views and light rigs of one library scene (spectra of lights come later)."""

    parts: tuple[tuple[str, g.Part], ...]
    views: tuple[tuple[tuple[float, float, float], tuple[float, float, float], float], ...]
    focus: tuple[float, float, float]
    single: _LightSpot
    pair: tuple[_LightSpot, _LightSpot]


# --- layouts --------------------------------------------------------------------------------


def _object_layout(key: str) -> _Layout:
    part = OBJECTS[key]()
    lo, hi = part.vertices.min(axis=0), part.vertices.max(axis=0)
    centre = (lo + hi) / 2
    radius = float(np.linalg.norm(hi - lo) / 2)
    ground = g.box((12.0, 12.0, 0.05), GROUND, center=(0, 0, -0.025), divisions=(12, 12, 1))
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

    return _Layout(
        parts=((key, part), ("ground", ground)),
        views=((tuple(eye.tolist()), tuple(centre.tolist()), fov),),
        focus=tuple(centre.tolist()),
        single=_LightSpot("point", around((-0.4, -0.8, 1.0))),
        pair=(
            _LightSpot("point", around((-0.9, -0.5, 0.8))),
            _LightSpot("point", around((0.9, -0.4, 0.9))),
        ),
    )


def _room_living() -> _Layout:
    """A living room: red and cream walls meet behind a table with a vase, cup and apple; a
    shelf with a printed box and a frog; a chair."""
    w, d, h = 4.0, 3.5, 2.6
    shell = g.room(
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
        ("table", g.table(1.2, 0.8, table_top, wood, center=(1.4, 2.3, 0))),
        ("vase", g.moved(OBJECTS["vase"](), scale=1.6, translate=(1.2, 2.45, table_top))),
        (
            "cup",
            g.moved(
                OBJECTS["cup"](),
                scale=1.5,
                rotate_deg=(0, 0, 200),
                translate=(1.65, 2.15, table_top),
            ),
        ),
        ("apple", g.moved(OBJECTS["apple"](), scale=1.3, translate=(1.85, 2.45, table_top))),
        ("shelf", g.shelf(1.0, 0.4, 1.6, _M + "7.5Y 8/6", boards=3, center=(3.2, d - 0.2, 0))),
        ("box", g.moved(OBJECTS["box"](), scale=1.3, translate=(3.0, d - 0.22, 0.03))),
        ("frog", g.moved(OBJECTS["frog"](), scale=2.0, translate=(3.35, d - 0.24, 0.5533))),
        ("chair", g.chair(0.45, 0.45, _M + "5PB 4/10", center=(2.3, 1.8, 0), facing_deg=60)),
    ]
    focus = (1.6, 2.3, table_top + 0.1)
    return _Layout(
        parts=tuple(parts),
        views=(
            ((2.8, 0.3, 1.6), focus, 60.0),
            ((0.4, 0.4, 1.4), (1.6, 2.5, 0.7), 60.0),
            ((3.6, 0.8, 1.2), (2.6, 3.0, 0.6), 65.0),
        ),
        focus=focus,
        single=_LightSpot("point", (2.0, 1.75, 2.3)),
        pair=(_LightSpot("point", (0.8, 1.4, 2.2)), _LightSpot("point", (3.2, 1.6, 2.2))),
    )


def _room_corner() -> _Layout:
    """A small room whose green and yellow walls form a concave corner holding a stack of
    coloured cubes, a turtle, a deer and a chair, lit by spots."""
    w, d, h = 2.6, 2.6, 2.4
    shell = g.room(
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
            g.box(
                (0.5, 0.5, 0.5), _M + "5R 4/12", center=(0.3, d - 0.3, 0.25), divisions=(2, 2, 2)
            ),
        ),
        (
            "cube-blue",
            g.box(
                (0.4, 0.4, 0.4), _M + "5PB 5/10", center=(0.3, d - 0.3, 0.7), divisions=(2, 2, 2)
            ),
        ),
        ("cube-purple", g.box((0.35, 0.35, 0.35), _M + "5P 4/10", center=(0.85, d - 0.25, 0.175))),
        (
            "turtle",
            g.moved(OBJECTS["turtle"](), scale=2.0, rotate_deg=(0, 0, 30), translate=(1.1, 1.5, 0)),
        ),
        (
            "deer",
            g.moved(OBJECTS["deer"](), scale=2.0, rotate_deg=(0, 0, -40), translate=(1.7, 1.9, 0)),
        ),
        ("chair", g.chair(0.45, 0.45, _M + "10R 5/10", center=(2.0, 0.9, 0), facing_deg=-120)),
    ]
    focus = (0.8, 1.9, 0.4)
    return _Layout(
        parts=tuple(parts),
        views=(
            ((2.2, 0.3, 1.5), focus, 60.0),
            ((1.3, 0.2, 0.8), (0.9, 2.0, 0.4), 55.0),
            ((2.3, 1.2, 1.9), (0.6, 2.2, 0.3), 60.0),
        ),
        focus=focus,
        single=_LightSpot("spot", (1.6, 0.8, 2.2)),
        pair=(_LightSpot("spot", (0.6, 0.6, 2.2)), _LightSpot("point", (2.0, 1.6, 2.1))),
    )


def _room_studio() -> _Layout:
    """A studio under ceiling panels: a blue wall, a shelf of coloured books, a desk with a
    printed page and a mug, a vase on the floor."""
    w, d, h = 3.0, 3.0, 2.5
    shell = g.room(
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
        g.box(
            (0.06, 0.25, 0.3 - 0.03 * (i % 3)),
            books[i % len(books)],
            center=(2.0 + 0.07 * i, d - 0.2, 0.03 + (0.3 - 0.03 * (i % 3)) / 2),
        )
        for i in range(8)
    ]
    parts += [
        ("shelf", g.shelf(1.2, 0.4, 1.5, "flat:0.7", boards=3, center=(2.3, d - 0.2, 0))),
        ("books", g.merge(*book_parts)),
        ("desk", g.table(1.0, 0.6, 0.72, _M + "5YR 4/4", center=(0.9, 2.2, 0))),
        ("paper", g.moved(OBJECTS["paper"](), rotate_deg=(0, 0, 10), translate=(0.8, 2.15, 0.72))),
        ("cup", g.moved(OBJECTS["cup"](), scale=1.4, translate=(1.2, 2.3, 0.72))),
        ("vase", g.moved(OBJECTS["vase"](), scale=2.5, translate=(1.9, 1.4, 0))),
    ]
    focus = (1.4, 2.1, 0.6)
    return _Layout(
        parts=tuple(parts),
        views=(
            ((1.5, 0.2, 1.5), focus, 60.0),
            ((0.3, 0.5, 1.3), (1.2, 2.3, 0.6), 55.0),
            ((2.7, 0.4, 1.1), (1.7, 2.2, 0.6), 60.0),
        ),
        focus=focus,
        single=_LightSpot("area", (1.3, 1.6, h - 0.05), (0.6, 0.6)),
        pair=(
            _LightSpot("area", (0.7, 1.5, h - 0.05), (0.5, 0.5)),
            _LightSpot("area", (2.2, 1.7, h - 0.05), (0.5, 0.5)),
        ),
    )


_COMPLEX: dict[str, Callable[[], _Layout]] = {
    "room-living": _room_living,
    "room-corner": _room_corner,
    "room-studio": _room_studio,
}
_OBJECT_SCENES = {f"obj-{key}": key for key in OBJECTS}


# --- public API -----------------------------------------------------------------------------


def scene_names(kind: str | None = None) -> list[str]:
    """Library scene names: ``kind`` None (all), ``"object"`` (8) or ``"complex"`` (3)."""
    if kind is None:
        return [*_OBJECT_SCENES, *_COMPLEX]
    validate_choice(kind, ("object", "complex"), "library scene kind", error=SceneError)
    return list(_OBJECT_SCENES) if kind == "object" else list(_COMPLEX)


def _check_name(name: str) -> str:
    return validate_choice(name, scene_names(), "library scene", error=SceneError)


def n_views(name: str) -> int:
    """Number of camera viewpoints of scene *name*: 1 for objects, 3 for complex scenes."""
    return 1 if _check_name(name) in _OBJECT_SCENES else 3


def _layout(name: str) -> _Layout:
    return _object_layout(_OBJECT_SCENES[name]) if name in _OBJECT_SCENES else _COMPLEX[name]()


def _chromaticities(names: Sequence[str]) -> dict[str, np.ndarray]:
    cmf = get_sensors("cie1931")
    return {
        n: xyz_to_xy(responses(get_spectrum(n).on(cmf.wavelengths), cmf.curves, cmf.wavelengths))
        for n in names
    }


def condition_illuminants(name: str, condition: str, *, seed: int) -> tuple[str, ...]:
    """The illuminant spectrum names of *condition* for scene *name* (1 or 2 names).

    All conditions of a scene are drawn from one generator seeded by ``seed_from_key(seed,
    name)``, in a fixed order, so ``two-colour-b`` always differs from ``two-colour-a``.
    """
    _check_name(name)
    validate_choice(condition, CONDITIONS, "illumination condition", error=SceneError)
    if condition == "white":
        return (WHITE,)
    planck, other = illuminant_set("planckian"), illuminant_set("non-planckian")
    pool = planck + other
    xy = _chromaticities((*pool, WHITE))

    def far(a: str, b: str) -> bool:
        return float(np.linalg.norm(xy[a] - xy[b])) >= MIN_XY_DISTANCE

    rng = generator(seed_from_key(seed, f"library-illuminants:{name}"))
    coloured = [n for n in pool if far(n, WHITE)]
    one = (coloured[int(rng.integers(len(coloured)))],)
    pairs_a = [(p, q) for p in planck for q in other if far(p, q)]
    a = pairs_a[int(rng.integers(len(pairs_a)))]
    pairs_b = [pq for pq in itertools.combinations(pool, 2) if far(*pq) and set(pq) != set(a)]
    b = pairs_b[int(rng.integers(len(pairs_b)))]
    # which light of a pair sits at which position is part of the draw
    a = a if rng.random() < 0.5 else a[::-1]
    b = b if rng.random() < 0.5 else b[::-1]
    return {"one-colour": one, "two-colour-a": a, "two-colour-b": b}[condition]


def _power(spot: _LightSpot, direction: np.ndarray, focus: np.ndarray, irradiance: float) -> float:
    """Power giving *irradiance* at *focus* on a surface facing the light
    (:func:`spectrinsic.scenes.model.light_power`)."""
    return light_power(spot.kind, np.asarray(spot.position, float), direction, focus, spot.size,
                       irradiance)


def _check_view(name: str, view: int) -> None:
    """Raise :class:`SceneError` unless *name* is a library scene and *view* one of its views."""
    _check_name(name)
    if (
        isinstance(view, bool)
        or not isinstance(view, (int, np.integer))
        or not 0 <= view < n_views(name)
    ):
        raise SceneError(
            f"view {view!r} of library scene {name!r}: expected 0..{n_views(name) - 1}"
        )


def _light(
    spot: _LightSpot, spectrum: str, focus: np.ndarray, irradiance: float, *, name: str
) -> Light:
    """The light at *spot* aimed at *focus* (area lights face down) delivering *irradiance*
    (relative units, see :data:`TARGET_IRRADIANCE` and :func:`_power`) with illuminant
    *spectrum*."""
    direction = focus - np.asarray(spot.position, float)
    direction = direction / np.linalg.norm(direction)
    if spot.kind == "area":
        direction = np.array([0.0, 0.0, -1.0])
    # only the fields a light's kind uses are set, so saved scenes stay tidy
    extra: dict[str, object] = {}
    if spot.kind != "point":
        extra["direction"] = tuple(float(x) for x in direction)
    if spot.kind == "area":
        extra["size"] = spot.size
    if spot.kind == "spot":
        extra["cutoff_deg"] = SPOT_CUTOFF_DEG
    return Light(
        kind=spot.kind,
        spectrum=spectrum,
        power=_power(spot, direction, focus, irradiance),
        position=spot.position,
        name=name,
        **extra,  # type: ignore[arg-type]
    )


def _camera(layout: _Layout, view: int, width: int, height: int) -> Camera:
    """The perspective camera of *layout*'s viewpoint *view*, ``width x height`` pixels, z up."""
    origin, target, fov = layout.views[view]
    return Camera(
        origin=tuple(float(x) for x in origin),  # type: ignore[arg-type]
        target=tuple(float(x) for x in target),  # type: ignore[arg-type]
        up=(0.0, 0.0, 1.0),
        fov_deg=fov,
        width=width,
        height=height,
        name=f"view{view}",
    )


def build(
    name: str,
    *,
    view: int = 0,
    condition: str = "white",
    seed: int,
    width: int = 128,
    height: int = 128,
) -> Scene:
    """Build library scene *name* seen from *view* under illumination *condition*.

    Parameters
    ----------
    name
        One of :func:`scene_names`.
    view
        Camera viewpoint, ``0 <= view < n_views(name)``.
    condition
        One of :data:`CONDITIONS`.
    seed
        Root seed of the illuminant draw (see :func:`condition_illuminants`); geometry does not
        depend on it.
    width, height
        Image size in pixels (the horizontal field of view is kept).

    Returns
    -------
    Scene
        With ``metadata`` ``{"library": name, "kind", "view", "condition", "seed",
        "illuminants"}``.
    """
    _check_view(name, view)
    illuminants = condition_illuminants(name, condition, seed=seed)
    layout = _layout(name)
    meshes, materials = g.to_meshes(layout.parts)
    spots = (layout.single,) if len(illuminants) == 1 else layout.pair
    focus = np.asarray(layout.focus, float)
    lights = [
        _light(spot, spectrum, focus, TARGET_IRRADIANCE / len(spots), name=f"light{i}")
        for i, (spot, spectrum) in enumerate(zip(spots, illuminants, strict=True))
    ]
    camera = _camera(layout, int(view), int(width), int(height))
    kind = "object" if name in _OBJECT_SCENES else "complex"
    return Scene(
        name=name,
        meshes=meshes,
        materials=materials,
        lights=tuple(lights),
        camera=camera,
        metadata={
            "library": name,
            "kind": kind,
            "view": int(view),
            "condition": condition,
            "seed": int(seed),
            "illuminants": list(illuminants),
        },
    )


def default_samples() -> list[SampleId]:
    """Every (scene, view, condition) of the library: 8 x 4 + 3 x 3 x 4 = 68 samples."""
    return [
        SampleId(name, view, condition)
        for name in scene_names()
        for view in range(n_views(name))
        for condition in CONDITIONS
    ]
