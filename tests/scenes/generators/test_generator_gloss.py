"""Glossy and metal surfaces in generated scenes (spectrinsic/scenes/generators/gloss.py)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from spectrinsic.errors import SceneError
from spectrinsic.scenes import scene_hash, validate_scene
from spectrinsic.scenes.generators import GeneratorOptions, GlossDistribution, generate
from spectrinsic.scenes.generators.gloss import METALS

OPTS = GeneratorOptions(width=24, height=24)


def _materials(options: GeneratorOptions, index: int) -> tuple:
    return generate("rooms", root_seed=11, index=index, view=0, options=options).materials


def test_fractions_and_roughness_range_are_followed():
    gloss = GlossDistribution(glossy_fraction=0.5, metal_fraction=0.25, roughness_range=(0.05, 0.2))
    mats = [m for i in range(6) for m in _materials(replace(OPTS, gloss=gloss), i)]
    n = len(mats)
    plastic = [m for m in mats if m.kind == "plastic"]
    metal = [m for m in mats if m.kind == "conductor"]
    # binomial draws: within 4 standard deviations of the asked fractions
    for got, p in ((len(plastic), 0.5), (len(metal), 0.25)):
        assert abs(got - p * n) <= 4 * (n * p * (1 - p)) ** 0.5, (got, p, n)
    assert all(0.05 <= m.roughness <= 0.2 for m in plastic + metal)
    assert {m.metal for m in metal} <= set(METALS) and all(m.spectrum == "flat:0" for m in metal)


def test_glossy_scenes_are_valid_and_keep_the_matte_draws():
    """Only the materials change: geometry, lights and camera are the matte scene's, and a
    plastic keeps its drawn base spectrum."""
    gloss = GlossDistribution(glossy_fraction=0.6, metal_fraction=0.2)
    matte = generate("rooms", root_seed=11, index=2, view=0, options=OPTS)
    shiny = generate("rooms", root_seed=11, index=2, view=0, options=replace(OPTS, gloss=gloss))
    validate_scene(shiny)
    assert shiny.camera == matte.camera and shiny.lights == matte.lights
    assert any(m.glossy for m in shiny.materials)
    for a, b in zip(matte.materials, shiny.materials, strict=True):
        assert b.kind == "conductor" or b.spectrum == a.spectrum
    assert scene_hash(shiny) != scene_hash(matte)


def test_default_options_change_nothing():
    a = generate("objects-on-ground", root_seed=3, index=0, view=0, options=OPTS)
    b = generate(
        "objects-on-ground",
        root_seed=3,
        index=0,
        view=0,
        options=replace(OPTS, gloss=GlossDistribution(0.0, 0.0, (0.1, 0.5))),
    )
    assert scene_hash(a) == scene_hash(b) and a.metadata == b.metadata
    assert not any(m.glossy for m in a.materials)


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        ((0.8, 0.4), "summing to <= 1"),
        ((-0.1, 0.0), "fractions in [0, 1]"),
        ((0.1, 0.1, (0.5, 0.2)), "roughness range"),
        ((0.0, 0.0, (0.0, 0.3), (1.4, 1.6), 0.7, 0.5), "glass fraction 0.7, mirror fraction 0.5"),
    ],
)
def test_bad_distributions_are_one_line_errors(args, expected):
    with pytest.raises(SceneError, match=expected.replace("[", r"\[").replace("]", r"\]")):
        GlossDistribution(*args)


def test_glass_and_mirrors_go_to_object_materials_only_and_change_no_other_draw():
    """With every object material made glass or a mirror, walls, floors and furniture keep
    their materials, and the scene is the one without them but for those materials."""
    base = GlossDistribution(glossy_fraction=0.3, metal_fraction=0.1)
    glassy = replace(base, glass_fraction=0.5, mirror_fraction=0.5)
    for index in range(3):
        a = generate("rooms", root_seed=11, index=index, view=0, options=replace(OPTS, gloss=base))
        b = generate(
            "rooms", root_seed=11, index=index, view=0, options=replace(OPTS, gloss=glassy)
        )
        validate_scene(b)
        assert a.camera == b.camera and a.lights == b.lights
        changed = {i for i, (x, y) in enumerate(zip(a.materials, b.materials)) if x != y}
        for mesh in b.meshes:
            used = set(mesh.face_materials.tolist())
            if mesh.semantic != "object" or len(used) > 1:
                assert not used & changed, mesh.name
        new = [b.materials[i] for i in changed]
        assert new and all(m.transmissive or m.metal == "none" for m in new)
        assert b.metadata["glass_materials"] + b.metadata["mirror_materials"] == len(new)
        assert "glass_materials" not in a.metadata
