"""Scene generators: reproducible, varied, placed without interpenetration, cameras that see
objects from free space. No rendering here."""

import numpy as np
import pytest

from spectrinsic.errors import SpectrinsicError
from spectrinsic.scenes import save_scene, scene_hash, validate_scene
from spectrinsic.scenes.generators import (
    GeneratorOptions,
    MaterialDistribution,
    generate,
    generator_names,
)
from spectrinsic.scenes.generators.camera import coverage, is_free
from spectrinsic.scenes.generators.materials import munsell_chips

OPTS = GeneratorOptions(width=24, height=24, views=2)
GENS = generator_names()
#: Tolerance on "rests on": exact placement up to float round-off, m.
REST_EPS = 1e-9


def _scene(gen, seed, index=0, view=0, options=OPTS):
    return generate(gen, root_seed=seed, index=index, view=view, options=options)


@pytest.mark.parametrize("gen", GENS)
def test_same_seed_gives_identical_scene_files(gen, tmp_path):
    a, b = _scene(gen, 3), _scene(gen, 3)
    assert scene_hash(a) == scene_hash(b)
    pa, pb = save_scene(a, tmp_path / "a" / "s.yaml"), save_scene(b, tmp_path / "b" / "s.yaml")
    files_a = sorted(p.relative_to(pa.parent) for p in pa.parent.rglob("*") if p.is_file())
    assert files_a and files_a == sorted(
        p.relative_to(pb.parent) for p in pb.parent.rglob("*") if p.is_file()
    )
    for rel in files_a:
        assert (pa.parent / rel).read_bytes() == (pb.parent / rel).read_bytes()


@pytest.mark.parametrize("gen", GENS)
def test_different_seeds_change_geometry_materials_lights_camera(gen):
    scenes = [_scene(gen, s) for s in range(4)]
    geometry = {tuple(len(m.faces) for m in s.meshes) for s in scenes}
    materials = {tuple(m.spectrum for m in s.materials) for s in scenes}
    lights = {
        tuple((light.kind, light.spectrum, light.position) for light in s.lights) for s in scenes
    }
    cameras = {s.camera.origin for s in scenes}
    assert len(geometry) == len(materials) == len(lights) == len(cameras) == 4


@pytest.mark.parametrize("gen", GENS)
def test_views_share_geometry_and_lights_but_not_the_camera(gen):
    v0, v1 = _scene(gen, 1, view=0), _scene(gen, 1, view=1)
    assert v0.meshes == v1.meshes and v0.lights == v1.lights
    assert v0.camera.origin != v1.camera.origin


@pytest.mark.parametrize("gen", GENS)
@pytest.mark.parametrize("index", range(3))
def test_scene_is_valid_camera_free_and_sees_objects(gen, index):
    scene = validate_scene(_scene(gen, 7, index))
    assert is_free(scene.meshes, scene.camera.origin)
    background = ("wall-", "floor", "ceiling", "ground")
    cov = coverage(scene.meshes, scene.camera, lambda m: not m.name.startswith(background))
    assert cov >= OPTS.min_coverage
    assert 1 <= len(scene.lights) <= 4
    if scene.metadata["condition"] == "two-colour":
        assert len({light.spectrum for light in scene.lights}) == 2


_SUPPORTS = ("table", "round-table", "cabinet", "shelf")


def _upward_face_heights(mesh):
    """z of every face of *mesh* that faces straight up (table tops, shelf boards)."""
    tri = mesh.vertices[mesh.faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    up = n[:, 2] > 0.999 * np.linalg.norm(n, axis=1)
    return {float(z) for z in tri[up][:, :, 2].ravel()}


@pytest.mark.parametrize("index", range(4))
def test_objects_rest_on_supports_without_overlapping(index):
    scene = _scene("rooms", 11, index)
    solids = [m for m in scene.meshes if not m.name.startswith(("wall-", "floor", "ceiling"))]
    tops = {0.0}.union(*(_upward_face_heights(m) for m in solids if m.name.startswith(_SUPPORTS)))
    boxes = []
    for m in solids:
        z0 = float(m.vertices[:, 2].min())
        assert min(abs(z0 - t) for t in tops) < REST_EPS, m.name
        lo, hi = m.vertices.min(axis=0), m.vertices.max(axis=0)
        boxes.append((m.name, lo, hi))
    for i, (na, la, ha) in enumerate(boxes):
        for nb, lb, hb in boxes[i + 1 :]:
            # two objects on one support must not overlap in their 3-D bounding boxes; an
            # object may stand on (or in) one piece of furniture
            overlap = np.all(la < hb) and np.all(lb < ha)
            stacked = abs(la[2] - hb[2]) < 1e-6 or abs(lb[2] - ha[2]) < 1e-6
            supported = na.startswith(_SUPPORTS) ^ nb.startswith(_SUPPORTS)
            assert not overlap or stacked or supported, (na, nb)


def test_material_distribution_bounds_value_and_chroma():
    dist = MaterialDistribution(
        value_range=(7.0, 9.0), chroma_range=(0.0, 2.0), pattern_probability=0.0
    )
    scene = _scene(
        "objects-on-ground", 2, options=GeneratorOptions(width=16, height=16, materials=dist)
    )
    chips = {n: (v, c) for n, v, c in munsell_chips()}
    objects = [m for m in scene.meshes if m.name != "ground" and not m.name.startswith("lib-")]
    used = {scene.materials[k].spectrum for m in objects for k in np.unique(m.face_materials)}
    assert used and all(7.0 <= chips[n][0] <= 9.0 and chips[n][1] <= 2.0 for n in used)


def test_patterns_give_several_exact_spectra_on_one_object():
    dist = MaterialDistribution(pattern_probability=1.0)
    opts = GeneratorOptions(width=16, height=16, materials=dist)
    counts = [
        len(np.unique(m.face_materials))
        for s in range(3)
        for m in _scene("objects-on-ground", s, options=opts).meshes
        if m.name != "ground" and not m.name.startswith("lib-")
    ]
    assert counts and max(counts) >= 2


def test_rooms_vary_in_openness():
    infos = [_scene("rooms", 0, i).metadata for i in range(8)]
    assert any(i["missing_walls"] or not i["ceiling"] for i in infos)
    assert len({tuple(i["room_size"]) for i in infos}) == 8


def test_unknown_generator_is_a_one_line_error_with_a_suggestion():
    with pytest.raises(SpectrinsicError, match="did you mean 'rooms'") as info:
        _scene("room", 0)
    assert "\n" not in str(info.value)


def test_rooms_with_a_ceiling_get_no_directional_light():
    scenes = [_scene("rooms", 9, i) for i in range(8)]
    roofed = [s for s in scenes if s.metadata["ceiling"]]
    assert roofed and all(light.kind != "directional" for s in roofed for light in s.lights)


@pytest.mark.slow
def test_rooms_are_lit_directly_and_indirectly():
    """Low energy ratios r need rooms lit after a bounce: their lights sit below a ceiling and
    aim up at it, in closed-ceiling rooms with light walls (measured r 0.30-0.36 at the preview
    preset; the closing note of issue 10 has the distribution)."""
    scenes = [_scene("rooms", 3, index=i) for i in range(40)]
    lighting = {s.metadata["lighting"] for s in scenes}
    assert lighting == {"direct", "indirect"}
    for s in scenes:
        if s.metadata["lighting"] != "indirect":
            continue
        assert s.metadata["ceiling"] and s.metadata["light_walls"]
        height = float(s.metadata["room_size"][2])
        for light in s.lights:
            assert light.kind in ("spot", "area") and light.direction[2] > 0
            assert light.position[2] < 0.6 * height + 1e-9


def test_a_layout_no_camera_can_see_is_drawn_again(monkeypatch):
    """The first layout's cameras all fail: the scene is the next layout, the same in every view
    and every build; when every layout fails, the error names the scene and the reason."""
    import spectrinsic.scenes.generators.base as base

    real, calls = base.sample_camera, {"n": 0}

    from spectrinsic.errors import SceneError

    def blind_once(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 1:
            raise SceneError("no camera of 40 draws saw >= 15.0% objects (best 14.9%)")
        return real(*args, **kwargs)

    plain = _scene("objects-on-ground", 5, view=1)
    monkeypatch.setattr(base, "sample_camera", blind_once)
    redrawn = _scene("objects-on-ground", 5, view=1)
    assert redrawn.metadata["layout_attempt"] == 1 and "layout_attempt" not in plain.metadata
    assert scene_hash(redrawn) != scene_hash(plain)
    calls["n"] = 0
    view0 = _scene("objects-on-ground", 5, view=0)
    assert [m.name for m in view0.meshes] == [m.name for m in redrawn.meshes]
    assert all(np.array_equal(a.vertices, b.vertices) for a, b in zip(view0.meshes, redrawn.meshes))

    def always_blind(*args, **kwargs):
        raise SceneError("no camera saw the objects")

    monkeypatch.setattr(base, "sample_camera", always_blind)
    with pytest.raises(SceneError, match="objects-on-ground-00000: no usable layout in 4 draws"):
        _scene("objects-on-ground", 5)
