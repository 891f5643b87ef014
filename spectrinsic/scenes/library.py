"""The built-in scene library (thesis Figs. 5.6-5.7 and Appendix C.2).

- 8 single-object scenes (``obj-apple`` ... ``obj-deer``, :data:`spectrinsic.scenes.objects.OBJECTS`):
  one MIT-like object on a neutral, spectrally flat ground (reflectance 0.5), one view;
- 3 complex scenes (``room-living``, ``room-corner``, ``room-studio``): closed rooms with
  coloured walls, furniture and several objects, with concave arrangements (wall corners,
  shelf compartments, cup and vase cavities) so interreflections and colour bleeding show;
  3 camera viewpoints each (geometry, views and light positions:
  :mod:`spectrinsic.scenes.layouts`);
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
from collections.abc import Sequence

import numpy as np

from ..errors import SceneError, validate_choice
from ..rng import generator, seed_from_key
from ..spectra import get_sensors, get_spectrum, illuminant_set, responses, xyz_to_xy
from .layouts import ROOM_LAYOUTS, Layout, LightSpot, object_layout
from .library_gloss import GLOSSY_SUFFIX, base_name, glossy_variant
from .model import Camera, Light, Scene, light_power
from .objects import OBJECTS
from .parts import to_meshes
from .sample_id import SampleId

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
    "check_sample",
    "default_samples",
    "glossy_samples",
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

_OBJECT_SCENES = {f"obj-{key}": key for key in OBJECTS}


# --- public API -----------------------------------------------------------------------------


def scene_names(kind: str | None = None) -> list[str]:
    """Library scene names: ``kind`` None (the thesis' 11), ``"object"`` (8), ``"complex"`` (3)
    or ``"glossy"`` (the 11 glossy variants, :mod:`~spectrinsic.scenes.library_gloss`)."""
    if kind is None:
        return [*_OBJECT_SCENES, *ROOM_LAYOUTS]
    validate_choice(kind, ("object", "complex", "glossy"), "library scene kind", error=SceneError)
    if kind == "glossy":
        return [n + GLOSSY_SUFFIX for n in scene_names()]
    return list(_OBJECT_SCENES) if kind == "object" else list(ROOM_LAYOUTS)


def _check_name(name: str) -> str:
    return validate_choice(
        name, scene_names() + scene_names("glossy"), "library scene", error=SceneError
    )


def n_views(name: str) -> int:
    """Number of camera viewpoints of scene *name*: 1 for objects, 3 for complex scenes."""
    return 1 if base_name(_check_name(name)) in _OBJECT_SCENES else 3


def _layout(name: str) -> Layout:
    return object_layout(_OBJECT_SCENES[name]) if name in _OBJECT_SCENES else ROOM_LAYOUTS[name]()


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


def _power(spot: LightSpot, direction: np.ndarray, focus: np.ndarray, irradiance: float) -> float:
    """Power giving *irradiance* at *focus* on a surface facing the light
    (:func:`spectrinsic.scenes.model.light_power`)."""
    return light_power(
        spot.kind, np.asarray(spot.position, float), direction, focus, spot.size, irradiance
    )


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


def check_sample(name: str, view: int, condition: str) -> None:
    """Raise :class:`SceneError` unless scene *name*, *view* and *condition* name a library
    sample (``render --ground-truth`` checks before it plans its one-sample build, which would
    otherwise find no sample of that id)."""
    _check_view(name, view)
    validate_choice(condition, CONDITIONS, "illumination condition", error=SceneError)


def _light(
    spot: LightSpot, spectrum: str, focus: np.ndarray, irradiance: float, *, name: str
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


def _camera(layout: Layout, view: int, width: int, height: int) -> Camera:
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
    if name != base_name(name):  # a glossy variant: its matte scene, lights and draws included
        return glossy_variant(
            build(
                base_name(name),
                view=view,
                condition=condition,
                seed=seed,
                width=width,
                height=height,
            ),
            base_name(name),
        )
    illuminants = condition_illuminants(name, condition, seed=seed)
    layout = _layout(name)
    meshes, materials = to_meshes(layout.parts)
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


def glossy_samples() -> list[SampleId]:
    """Every (scene, view, condition) of the glossy variants (``<scene>-glossy``), not part of
    the thesis layout: 68 more samples, each the glossy twin of a default one."""
    return [SampleId(s.scene + GLOSSY_SUFFIX, s.view, s.condition) for s in default_samples()]
