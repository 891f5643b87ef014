"""The built-in library: counts, reproducible illumination draws, valid and well-lit scenes."""

from __future__ import annotations

import itertools
import math

import colour
import numpy as np
import pytest

from spectrinsic.errors import SceneError, SpectrinsicError
from spectrinsic.scenes import library
from spectrinsic.scenes.validate import validate_scene
from spectrinsic.spectra import get_spectrum, illuminant_set

SEED = 2024
#: Scenes must stay small enough to render quickly on 2 cores.
MAX_TRIANGLES = 25_000
#: Irradiance sums are exact up to floating-point rounding.
EXACT = 1e-9

VIEWS = [(name, view) for name in library.scene_names() for view in range(library.n_views(name))]


def xy(name: str) -> np.ndarray:
    """CIE 1931 xy of an illuminant, computed independently with colour-science."""
    s = get_spectrum(name)
    sd = colour.SpectralDistribution(dict(zip(s.wavelengths, s.values, strict=True)))
    sd = sd.copy().align(colour.SpectralShape(360, 780, 1))
    return np.asarray(colour.XYZ_to_xy(colour.sd_to_XYZ(sd)))


def test_counts_and_names():
    objects, rooms = library.scene_names("object"), library.scene_names("complex")
    assert len(objects) == 8 and all(n.startswith("obj-") for n in objects)
    assert len(rooms) == 3
    assert library.scene_names() == objects + rooms
    assert all(library.n_views(n) == 1 for n in objects)
    assert all(library.n_views(n) == 3 for n in rooms)
    assert library.CONDITIONS == ("white", "one-colour", "two-colour-a", "two-colour-b")


def test_default_samples():
    samples = library.default_samples()
    assert len(samples) == 68 == 8 * 4 + 3 * 3 * 4
    ids = [str(s) for s in samples]
    assert len(set(ids)) == 68
    assert "obj-vase__v0__two-colour-a" in ids
    assert "room-living__v2__white" in ids
    spec = samples[0]
    with pytest.raises(AttributeError):
        spec.view = 3  # frozen


def test_unknown_names_are_one_line_errors():
    with pytest.raises(SpectrinsicError, match="did you mean 'obj-vase'"):
        library.build("obj-vace", seed=SEED)
    with pytest.raises(SpectrinsicError, match="illumination condition"):
        library.build("obj-vase", condition="blue", seed=SEED)
    with pytest.raises(SpectrinsicError, match="view 1"):
        library.build("obj-vase", view=1, seed=SEED)
    with pytest.raises(SpectrinsicError, match="library scene kind"):
        library.scene_names("objects")


@pytest.mark.parametrize(
    "call",
    [
        lambda: library.build("obj-vace", seed=SEED),
        lambda: library.build("obj-vase", condition="x", seed=SEED),
        lambda: library.build("obj-vase", view=1, seed=SEED),
        lambda: library.scene_names("objects"),
        lambda: library.n_views("room"),
        lambda: library.condition_illuminants("obj-vase", "blue", seed=SEED),
    ],
    ids=["name", "condition", "view", "kind", "n_views", "illuminants"],
)
def test_bad_names_are_scene_errors(call):
    """``except SceneError`` catches every bad name given to the scene library."""
    with pytest.raises(SceneError):
        call()


def test_conditions_are_reproducible_and_seed_dependent():
    for name in ("obj-cup", "room-studio"):
        for cond in library.CONDITIONS:
            a = library.build(name, condition=cond, seed=SEED)
            b = library.build(name, condition=cond, seed=SEED)
            assert a == b and a.lights == b.lights
    draws = {
        library.condition_illuminants("obj-cup", "two-colour-a", seed=s)
        + library.condition_illuminants("obj-cup", "two-colour-b", seed=s)
        + library.condition_illuminants("obj-cup", "one-colour", seed=s)
        for s in range(8)
    }
    assert len(draws) > 1, "another seed must give other lights"
    assert (
        library.build("obj-cup", condition="two-colour-a", seed=0).lights
        != library.build("obj-cup", condition="two-colour-a", seed=1).lights
    )


def test_geometry_and_views_do_not_depend_on_seed_or_condition():
    a = library.build("room-corner", view=1, condition="white", seed=1)
    b = library.build("room-corner", view=1, condition="two-colour-b", seed=99)
    assert a.meshes == b.meshes and a.materials == b.materials and a.camera == b.camera


def test_lights_are_drawn_from_the_illuminant_sets():
    planck, other = set(illuminant_set("planckian")), set(illuminant_set("non-planckian"))
    for seed in range(6):
        for name in library.scene_names():
            assert library.condition_illuminants(name, "white", seed=seed) == ("cie:D65",)
            (one,) = library.condition_illuminants(name, "one-colour", seed=seed)
            assert one in planck | other
            a = library.condition_illuminants(name, "two-colour-a", seed=seed)
            b = library.condition_illuminants(name, "two-colour-b", seed=seed)
            assert len(set(a) & planck) == 1 and len(set(a) & other) == 1
            assert set(b) <= planck | other and len(set(b)) == 2
            assert set(a) != set(b)


def test_coloured_conditions_have_distinct_chromaticities():
    pool = illuminant_set("planckian") + illuminant_set("non-planckian")
    chroma = {n: xy(n) for n in (*pool, "cie:D65")}
    # independent check of the threshold's premise: some pairs in the pool are not distinct
    assert (
        min(np.linalg.norm(chroma[p] - chroma[q]) for p, q in itertools.combinations(pool, 2))
        < 0.01
    )
    for seed in range(6):
        for name in library.scene_names():
            for cond in ("two-colour-a", "two-colour-b"):
                p, q = library.condition_illuminants(name, cond, seed=seed)
                assert np.linalg.norm(chroma[p] - chroma[q]) >= library.MIN_XY_DISTANCE * 0.95
            (one,) = library.condition_illuminants(name, "one-colour", seed=seed)
            assert np.linalg.norm(chroma[one] - chroma["cie:D65"]) >= library.MIN_XY_DISTANCE * 0.95


@pytest.mark.parametrize(("name", "view"), VIEWS)
def test_every_library_scene_validates(name, view):
    for cond in ("white", "two-colour-a"):
        scene = library.build(name, view=view, condition=cond, seed=SEED, width=64, height=48)
        validate_scene(scene)
        assert sum(len(m.faces) for m in scene.meshes) < MAX_TRIANGLES
        assert scene.camera.width == 64 and scene.camera.height == 48
        assert scene.metadata["condition"] == cond and scene.metadata["view"] == view
        assert len(scene.lights) == (1 if cond == "white" else 2)
        assert len({m.object_id for m in scene.meshes}) == len(scene.meshes)


def test_conditions_deliver_equal_irradiance_at_the_focus():
    # object scenes use point lights: E = sum(I / d^2) at the focus, the same in every condition
    for name in library.scene_names("object"):
        for cond in library.CONDITIONS:
            scene = library.build(name, condition=cond, seed=SEED)
            focus = np.asarray(scene.camera.target)
            e = sum(
                light.power / np.sum((np.asarray(light.position) - focus) ** 2)
                for light in scene.lights
            )
            assert e == pytest.approx(library.TARGET_IRRADIANCE, rel=EXACT)
            assert all(light.kind == "point" for light in scene.lights)


def test_light_kinds_cover_point_spot_and_area():
    kinds = {
        light.kind
        for name in library.scene_names("complex")
        for cond in library.CONDITIONS
        for light in library.build(name, condition=cond, seed=SEED).lights
    }
    assert kinds == {"point", "spot", "area"}


def test_objects_carry_munsell_colours_on_a_neutral_ground():
    multi = 0
    for name in library.scene_names("object"):
        scene = library.build(name, seed=SEED)
        obj, ground = scene.meshes
        assert ground.name == "ground"
        assert {scene.materials[i].spectrum for i in ground.face_materials} == {"flat:0.5"}
        on_object = {scene.materials[i].spectrum for i in obj.face_materials}
        munsell = {s for s in on_object if s.startswith("munsell:")}
        assert munsell, f"{name} has no Munsell colour"
        # canonical names: the registry returns the very same name
        assert all(get_spectrum(s).name == s for s in munsell)
        multi += len(munsell) >= 2
    assert multi >= 5, "several objects must carry more than one Munsell colour"


def test_rooms_show_colour_bleeding_setups():
    # rooms hold coloured walls and more objects than walls
    for name in library.scene_names("complex"):
        scene = library.build(name, seed=SEED)
        walls = [m for m in scene.meshes if m.name.startswith("wall-")]
        assert len(walls) == 6
        wall_spectra = {scene.materials[m.face_materials[0]].spectrum for m in walls}
        assert any(s.startswith("munsell:") for s in wall_spectra)
        assert len(scene.meshes) - len(walls) >= 5


def test_views_differ_and_look_inside_the_room():
    for name in library.scene_names("complex"):
        cams = [library.build(name, view=v, seed=SEED).camera for v in range(3)]
        assert len({c.origin for c in cams}) == 3
        lo = np.min([m.vertices.min(axis=0) for m in library.build(name, seed=SEED).meshes], axis=0)
        hi = np.max([m.vertices.max(axis=0) for m in library.build(name, seed=SEED).meshes], axis=0)
        for c in cams:
            assert np.all(np.asarray(c.origin) > lo) and np.all(np.asarray(c.origin) < hi)
            assert 0 < c.fov_deg < 90 and not math.isnan(c.fov_deg)
