"""Procedural scene generators: seeded, reproducible scenes for datasets of any size.

:data:`GENERATORS` maps a name to a layout function (``objects-on-ground``, ``rooms``);
:func:`generate` turns (generator, root seed, index, view) into a complete
:class:`~spectrinsic.scenes.model.Scene`. Scene *index* is named ``<generator>-<index:05d>``
and seeded by ``seed_from_key(root_seed, name)``, so a scene does not depend on how many others
are generated, nor on their order or the executor. The per-scene seed is recorded in the
scene's metadata.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ...errors import SceneError, validate_choice
from ...rng import seed_from_key
from ..model import Scene
from .base import GeneratorOptions, Layout, assemble, family_of, scene_rngs
from .gloss import GlossDistribution, apply_gloss
from .ground import objects_on_ground
from .materials import MaterialDistribution
from .rooms import rooms
from .view_rule import FrameProbe

__all__ = [
    "GENERATORS",
    "GeneratorOptions",
    "MaterialDistribution",
    "GlossDistribution",
    "generator_names",
    "generated_scene_name",
    "generated_scene_seed",
    "generated_family",
    "generate",
]

#: Layout functions by generator name.
#: Layouts drawn for one scene before it fails (see :func:`generate`).
LAYOUT_ATTEMPTS = 4

GENERATORS: dict[str, Callable[[np.random.Generator, GeneratorOptions], Layout]] = {
    "objects-on-ground": objects_on_ground,
    "rooms": rooms,
}


def generator_names() -> list[str]:
    """Names of the scene generators."""
    return list(GENERATORS)


def generated_scene_name(generator: str, index: int) -> str:
    """``"<generator>-<index:05d>"``, e.g. ``"rooms-00007"``."""
    return f"{validate_choice(generator, GENERATORS, 'scene generator', error=SceneError)}-{int(index):05d}"


def generated_scene_seed(root_seed: int, generator: str, index: int) -> int:
    """The seed of scene *index*: ``seed_from_key(root_seed, generated_scene_name(...))``."""
    return seed_from_key(root_seed, generated_scene_name(generator, index))


def generated_family(root_seed: int, generator: str, index: int) -> str:
    """The lighting condition family of scene *index* (``white``, ``one-colour``, ``two-colour``)."""
    return family_of(generated_scene_seed(root_seed, generator, index))


def generate(
    generator: str,
    *,
    root_seed: int,
    index: int,
    view: int,
    options: GeneratorOptions,
    probe: FrameProbe | None = None,
) -> Scene:
    """Generate scene *index* of *generator* seen from camera *view*.

    Parameters
    ----------
    generator
        One of :func:`generator_names` (an unknown name raises with a did-you-mean).
    root_seed
        The dataset's root seed.
    index
        Scene number, >= 0.
    view
        Camera number, ``0 <= view < options.views``.
    options
        Image size, views, material distribution, coverage threshold, SFU names.
    probe
        A probe render judging the rendered light of the views of generators with the view
        rule (:func:`~spectrinsic.scenes.generators.view_rule.judge_frame`); None: the rule's
        estimate alone. A build passes one, so its scenes depend on it.

    Returns
    -------
    Scene
        Its metadata records the generator, the scene seed, the draws and the coverage.

    Notes
    -----
    A layout in which no light finds free space, or no camera of some view sees enough of the
    objects, is drawn again from ``seed_from_key(seed, "layout-<k>")``, up to
    :data:`LAYOUT_ATTEMPTS` times (recorded as ``layout_attempt``). Whether a layout passes
    is judged on all ``options.views`` cameras, so every view of a scene shows one layout.
    Scenes whose first layout passes are unchanged by this.
    """
    name = generated_scene_name(generator, index)
    seed = generated_scene_seed(root_seed, generator, index)
    problems = []
    for attempt in range(LAYOUT_ATTEMPTS):
        rngs = scene_rngs(seed if attempt == 0 else seed_from_key(seed, f"layout-{attempt}"))
        layout = GENERATORS[generator](rngs["layout"], options)
        try:
            scene = assemble(name, layout, seed, view, options, rngs, probe)
        except SceneError as exc:  # this layout cannot be lit or seen: draw another
            problems.append(str(exc))
            continue
        scene = apply_gloss(scene, options.gloss, seed)
        if attempt == 0:
            return scene
        return replace(scene, metadata={**scene.metadata, "layout_attempt": attempt})
    raise SceneError(f"{name}: no usable layout in {LAYOUT_ATTEMPTS} draws ({problems[-1]})")
