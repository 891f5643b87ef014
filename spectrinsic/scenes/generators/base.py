"""What every scene generator shares: its options, the layout it returns, and the assembly of
a layout, lights and a camera into a :class:`~spectrinsic.scenes.model.Scene`.

A generator is ``layout(rng, options) -> Layout``; it places painted parts and says where
lights may go and how to propose cameras. :func:`assemble` draws the condition's lights and a
camera that passes the coverage check, each from its own child of the scene's seed, so the
lights do not change when a geometry parameter is added, and vice versa.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..model import Camera, Light, Mesh, Scene
from ..parts import Part, to_meshes
from .camera import is_free, sample_camera
from .gloss import GlossDistribution
from .lights import FAMILIES, LightVolume, draw_lights
from .materials import MaterialDistribution
from .view_rule import FrameProbe, judge_frame, judge_view

__all__ = ["GeneratorOptions", "Layout", "assemble", "family_of", "scene_rngs"]

#: Mesh names that are not "objects" for the coverage check.
_BACKGROUND = ("wall-", "floor", "ceiling", "ground", "partition")


@dataclass(frozen=True)
class GeneratorOptions:
    """Settings of a generator run (every field is recorded with the scene).

    Attributes
    ----------
    width, height
        Image size in pixels.
    views
        Cameras per generated layout (each a sample; all views share geometry and lights).
    materials
        Distribution of the reflectances drawn.
    min_coverage
        Least fraction of the camera's ray grid that must hit non-background objects.
    max_lights
        Most lights per scene (1-4).
    sfu_reflectances, sfu_illuminants
        SFU names to draw from (empty when no data directory is configured).
    gloss
        Fractions of glossy and metal materials and their roughness range (default: none).
    data_dir
        Spectral data directory (for ``sfu`` chromaticities).
    light_saturation
        ``(lo, hi)``: |Duv| range (Ohno 2013) of the coloured families' lights; None: any.
    daylight_share
        Fraction of ``rooms`` lit also by sun and sky through a window, 0..1
        (:mod:`~spectrinsic.scenes.generators.daylight`); 0 leaves every room as before.
    daylight_only
        Whether those rooms are lit by sun and sky alone (no lamps); otherwise sun and sky
        carry a drawn share of the room's flux (``daylight.FLUX_SHARE``).
    """

    width: int
    height: int
    views: int = 1
    materials: MaterialDistribution = field(default_factory=MaterialDistribution)
    min_coverage: float = 0.15
    max_lights: int = 4
    sfu_reflectances: tuple[str, ...] = ()
    sfu_illuminants: tuple[str, ...] = ()
    data_dir: str | None = None
    gloss: GlossDistribution = field(default_factory=GlossDistribution)
    light_saturation: tuple[float, float] | None = None
    daylight_share: float = 0.0
    daylight_only: bool = False


@dataclass(frozen=True)
class Layout:
    """Geometry of one generated scene before lights and camera.

    Attributes
    ----------
    parts
        Named painted parts (walls named ``wall-*``, ``floor``, ``ceiling`` or ``ground``).
    lights
        Where lights may go and where they aim.
    propose_camera
        ``rng -> (origin, target, fov_deg)``: one camera proposal.
    info
        What the generator drew (recorded in the scene's metadata).
    min_coverage
        The generator's own least object coverage of a view (rooms frame furniture); the
        camera must pass the larger of this and ``options.min_coverage``.
    view_rule
        Cameras must also pass :func:`~spectrinsic.scenes.generators.view_rule.judge_view`
        (rooms: several materials, no surface filling the frame, enough light). Objects on a
        ground are MIT-like: the ground fills most of the frame by design.
    room_lights
        ``drawn -> lights``: the layout's own lights joined to the condition's drawn lights
        (a daylight room's sun and sky, with the lamps scaled to the daylight's flux share or
        dropped, :meth:`~spectrinsic.scenes.generators.daylight.Daylight.room_lights`); None
        keeps the drawn lights.
    flux_density
        Flux per m² of the room's surfaces that the layout's own lights send in through its
        openings (a daylight room's window), for the view rule's interreflection estimate.
    """

    parts: tuple[tuple[str, Part], ...]
    lights: LightVolume
    propose_camera: Callable[[np.random.Generator], tuple[np.ndarray, np.ndarray, float]]
    info: dict[str, Any]
    min_coverage: float = 0.0
    view_rule: bool = False
    room_lights: Callable[[tuple[Light, ...]], tuple[Light, ...]] | None = None
    flux_density: float = 0.0


def scene_rngs(seed: int) -> dict[str, np.random.Generator]:
    """Independent generators for ``layout``, ``lights``, ``camera`` from the scene seed."""
    children = np.random.SeedSequence(seed).spawn(3)
    return {
        k: np.random.default_rng(c)
        for k, c in zip(("layout", "lights", "camera"), children, strict=True)
    }


def family_of(seed: int) -> str:
    """The condition family of the scene with *seed* (cheap: planning needs it for sample ids)."""
    return FAMILIES[int(np.random.default_rng([seed, 1]).integers(len(FAMILIES)))]


def _is_object(mesh: Mesh) -> bool:
    return not mesh.name.startswith(_BACKGROUND)


def assemble(
    name: str,
    layout: Layout,
    seed: int,
    view: int,
    options: GeneratorOptions,
    rngs: dict[str, np.random.Generator],
    probe: FrameProbe | None = None,
) -> Scene:
    """The scene of *layout* seen from camera *view*, with the lights of its family.

    With a *probe* render, a camera that passes the view rule must also pass
    :func:`~spectrinsic.scenes.generators.view_rule.judge_frame` on the probe of the matte
    scene (the gloss is drawn afterwards; light, not sheen, is judged)."""
    meshes, materials = to_meshes(layout.parts)
    family = family_of(seed)
    lamps = draw_lights(
        rngs["lights"],
        family,
        layout.lights,
        free=lambda p: is_free(meshes, p),
        sfu=options.sfu_illuminants,
        data_dir=options.data_dir,
        max_lights=options.max_lights,
        saturation=options.light_saturation,
    )
    lights = lamps if layout.room_lights is None else layout.room_lights(lamps)
    if not {light.name for light in lamps} & {light.name for light in lights}:
        family = "daylight"  # the drawn lights (and their condition) were dropped
    draws = [0, 0]  # cameras judged by the view rule, and passed

    def judged(cam: Camera) -> bool:
        # a view worth learning from
        ok = judge_view(meshes, lights, cam, flux_density=layout.flux_density).ok
        if ok and probe is not None:  # and lit so, once rendered
            seen = Scene(name=name, meshes=meshes, materials=materials, lights=lights, camera=cam)
            ok = judge_frame(probe(seen)).ok
        draws[0], draws[1] = draws[0] + 1, draws[1] + ok
        return ok

    # Views 0..views-1 are drawn in order, so view k is the same in any build, and all of them
    # must pass for the layout to be used (every view of a scene shows one layout).
    for k in range(max(view + 1, options.views)):
        drawn = sample_camera(
            rngs["camera"],
            meshes,
            layout.propose_camera,
            width=options.width,
            height=options.height,
            is_object=_is_object,
            min_coverage=max(options.min_coverage, layout.min_coverage),
            name=f"view{k}",
            accept=judged if layout.view_rule else None,
        )
        if k == view:
            camera, cov = drawn
    meta = {
        **layout.info,
        "generator_seed": int(seed),
        "view": int(view),
        "condition": family,
        "object_coverage": cov,
        "illuminants": [light.spectrum for light in lights],
        "light_kinds": [light.kind for light in lights],
    }
    if layout.view_rule:  # how many cameras the rule judged for this scene's views
        meta["view_rule"] = {"judged": draws[0], "passed": draws[1]}
    return Scene(
        name=name, meshes=meshes, materials=materials, lights=lights, camera=camera, metadata=meta
    )
