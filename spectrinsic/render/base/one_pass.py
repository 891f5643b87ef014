"""One Mitsuba pass, shared by every pass and the band-path traversal: its record
(:class:`PassOutput`), its timed render call, and the checks every pass makes first."""

from __future__ import annotations

import time
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import RenderError, SceneError
from ...interrupts import raise_if_requested
from ...scenes.model import Scene
from ..settings import PassRequest
from .plugins import hdr_film, rgb_spectrum
from .sample_split import split_render
from .translate import scene_to_mitsuba

__all__ = [
    "DIRECT_DEPTH",
    "PassProgress",
    "PassOutput",
    "check_scene_lights",
    "refuse_surface_detail",
    "active_light_set",
    "timed_render",
    "timing",
    "load_rgb_scene",
    "set_rgb",
]

#: Path depth of a direct-light-only render (camera -> surface -> light).
DIRECT_DEPTH = 2
#: Called with 1 after each Mitsuba pass (e.g. ``tqdm.update``).
PassProgress = Callable[[int], Any]


@dataclass(frozen=True, eq=False)
class PassOutput:
    """Raw images of one set of channel values.

    Attributes
    ----------
    image
        ``(H, W, K)`` float32 full render (all bounces up to ``max_depth``).
    direct
        ``(H, W, K)`` float32 direct-light-only render, or ``None`` when not asked for.
    seconds
        Wall-clock seconds of each Mitsuba pass, in order (full passes, then direct ones).
    variant
        The Mitsuba variant used.
    """

    image: np.ndarray
    direct: np.ndarray | None
    seconds: tuple[float, ...]
    variant: str


def check_scene_lights(scene: Scene) -> None:
    """A pass needs a light (its samples and depth are checked once, by its
    :class:`~spectrinsic.render.settings.PassRequest`)."""
    if not scene.lights:
        raise SceneError(f"scene {scene.name!r} has no lights: nothing to render")


def refuse_surface_detail(scene: Scene, what: str) -> None:
    """Raise a one-line :class:`RenderError` if *scene* has spectral textures, or opacity masks
    or bump or normal maps, which *what* (passes of Mitsuba's own BSDFs and AOVs) cannot
    render exactly; the band-path traversal renders them."""
    textured = [m.name for m in scene.meshes if m.texture is not None]
    mapped = [m.name for m in scene.meshes if m.maps is not None]
    for detail, names in (
        ("spectral textures", textured),
        ("opacity masks or bump or normal maps", mapped),
    ):
        if names:
            raise RenderError(
                f"scene {scene.name!r}: {what} cannot render {detail} (mesh {names[0]!r}); "
                "use the single band-path traversal (integrator 'single')"
            )


def active_light_set(scene: Scene, active_lights: Sequence[int] | None) -> set[int]:
    """The lights a pass renders (*active_lights*, default all), checked (and that there are any)."""
    check_scene_lights(scene)
    active = (
        set(range(len(scene.lights))) if active_lights is None else {int(i) for i in active_lights}
    )
    bad = sorted(i for i in active if not 0 <= i < len(scene.lights))
    if bad or not active:
        raise SceneError(
            f"scene {scene.name!r}: active lights {sorted(active)} must be a non-empty subset of "
            f"0..{len(scene.lights) - 1}"
        )
    return active


def timed_render(
    mi: Any, loaded: Any, request: PassRequest, integrator: Any = None
) -> tuple[np.ndarray, float]:
    """One ``mi.render`` of *request*'s samples and seed as float32 and its seconds, reported
    to its progress, its samples split so that its bits do not follow the thread schedule
    (:func:`~.sample_split.split_render`); a Ctrl-C stops the build within it."""
    raise_if_requested()
    start = time.perf_counter()
    try:
        spp, seed = int(request.batch_spp), int(request.seed)
        image = split_render(mi, loaded, spp=spp, seed=seed, integrator=integrator)
    except RuntimeError as exc:
        raise_if_requested()  # Dr.Jit re-raises a Ctrl-C inside the render as RuntimeError
        raise RenderError(f"Mitsuba render failed: {exc}") from exc
    raise_if_requested()  # Mitsuba's own SIGINT handler may have cut the pass short
    seconds = time.perf_counter() - start
    request.tick()
    return image, seconds


def timing(seconds: Sequence[float]) -> dict[str, Any]:
    """The ``meta["timings"]`` record of some Mitsuba passes: their number, total and each (s)."""
    total = float(sum(seconds))
    return {"passes": len(seconds), "seconds": total, "per_pass": [float(x) for x in seconds]}


def load_rgb_scene(
    mi: Any,
    scene: Scene,
    request: PassRequest,
    integrator: Mapping[str, Any],
    active: Collection[int],
    keys: Sequence[str],
) -> tuple[Any, Any]:
    """*scene* loaded in the active RGB variant for passes that set their own values (black
    materials; the *active* lights with placeholders, the others left out), an ``hdrfilm``,
    *integrator* and *request*'s samples and geometry; and its ``mi.traverse`` parameters,
    checked to hold the *keys* the passes update."""
    mitsuba_dict = scene_to_mitsuba(
        scene,
        materials=[rgb_spectrum([0.0, 0.0, 0.0])] * len(scene.materials),
        # distinct emission per light (identical dicts could be merged into one shared object)
        lights=[
            rgb_spectrum([1.0 + j, 1.0, 1.0]) if j in active else None
            for j in range(len(scene.lights))
        ],
        film=hdr_film(scene.camera.width, scene.camera.height),
        integrator=integrator,
        sample_count=request.batch_spp,
        geometry=request.geometry,
    )
    loaded = mi.load_dict(mitsuba_dict)
    params = mi.traverse(loaded)
    missing = [k for k in keys if k not in params]
    if missing:
        raise RenderError(f"Mitsuba scene lacks the parameters {missing[:3]} the passes update")
    return loaded, params


def set_rgb(mi: Any, params: Any, key: str, values: np.ndarray) -> None:
    params[key] = mi.Color3f(*(float(v) for v in values))
