"""The view rule of generated scenes (issue 31): close-ups of one surface, views dominated by
one material and dark views fail; the generators' views all pass it."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.scenes.generators import GeneratorOptions, generate
from spectrinsic.scenes.generators.view_rule import MAX_SHARE, judge_view
from spectrinsic.scenes.model import Camera, Mesh, make_light


def _quad(name, z, half, material, object_id):
    """A horizontal square at height *z*, facing up."""
    v = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]], float)
    return Mesh(name, v, np.array([[0, 1, 2], [0, 2, 3]]), np.full(2, material), object_id)


def _floor_with_tiles():
    """A grey floor with three coloured tiles on it (4 materials), seen from above."""
    meshes = [_quad("floor", 0.0, 2.0, 0, 0)]
    for i, x in enumerate((-0.65, 0.0, 0.65)):
        m = _quad(f"tile{i}", 0.01, 0.3, i + 1, i + 1)
        meshes.append(Mesh(m.name, m.vertices + [x, 0, 0], m.faces, m.face_materials, i + 1))
    return meshes


def _camera(origin, target=(0, 0, 0), fov=50.0):
    return Camera(origin=origin, target=target, up=(0, 1, 0), fov_deg=fov, width=64, height=48)


LAMP = make_light("point", "cie:D65", 4 * np.pi, position=(0.0, 0.0, 2.0))


def test_a_view_of_several_lit_materials_passes():
    j = judge_view(_floor_with_tiles(), [LAMP], _camera((0, 0, 1.5), fov=60))
    assert j.ok, j.reasons
    assert j.n_materials == 4 and j.lit_share > 0.9


def test_a_close_up_of_one_surface_fails():
    j = judge_view(_floor_with_tiles(), [LAMP], _camera((0.6, 0, 0.2), target=(0.6, 0, 0)))
    assert not j.ok and j.max_material_share > MAX_SHARE
    assert any("fills" in r for r in j.reasons)


def test_a_view_without_light_fails():
    below = make_light("point", "cie:D65", 4 * np.pi, position=(0.0, 0.0, -1.0))  # under the floor
    j = judge_view(_floor_with_tiles(), [below], _camera((0, 0, 2.5)))
    assert not j.ok and j.lit_share == 0.0
    assert any("lit" in r for r in j.reasons)


def test_an_occluded_light_does_not_count():
    roof = _quad("roof", 1.5, 3.0, 5, 9)  # between the lamp and the floor
    j = judge_view([*_floor_with_tiles(), roof], [LAMP], _camera((0, 0, 1.2), fov=60))
    assert j.median_light < 0.05


@pytest.mark.slow
def test_fifty_generated_rooms_all_pass_the_view_rule(capsys):
    options = GeneratorOptions(width=64, height=48)
    n = 50
    scenes = [generate("rooms", root_seed=11, index=i, view=0, options=options) for i in range(n)]
    verdicts = [judge_view(s.meshes, s.lights, s.camera) for s in scenes]
    assert all(v.ok for v in verdicts), [v.reasons for v in verdicts if not v.ok]
    judged = sum(s.metadata["view_rule"]["judged"] for s in scenes)
    passed = sum(s.metadata["view_rule"]["passed"] for s in scenes)
    assert passed == n and judged >= passed
    with capsys.disabled():
        print(f"\nview rule: acceptance {passed / judged:.0%} ({passed} of {judged} cameras)")


def _rect(name, x0, x1, material, object_id, z=0.0):
    v = np.array([[x0, -2, z], [x1, -2, z], [x1, 2, z], [x0, 2, z]], float)
    return Mesh(name, v, np.array([[0, 1, 2], [0, 2, 3]]), np.full(2, material), object_id)


def test_an_object_of_several_meshes_is_judged_whole():
    """Two halves of one table top (one object_id, two meshes and materials) fill the frame:
    each mesh and material stays under the limit, the object does not (issue 47)."""
    halves = [_rect("top-a", -2, 0, 1, 7), _rect("top-b", 0, 2, 2, 7)]
    tiles = [_rect(f"tile{i}", x, x + 0.3, 3 + i, 20 + i, z=0.01) for i, x in enumerate((-1, 0.5))]
    cam = _camera((0, 0, 1.5), fov=60)
    split = judge_view([*halves, *tiles], [LAMP], cam)
    assert split.max_mesh_share <= MAX_SHARE and split.max_material_share <= MAX_SHARE
    assert split.max_object_share > MAX_SHARE and not split.ok
    assert any("one object fills" in r for r in split.reasons)
    b = halves[1]
    apart = [halves[0], Mesh("top-b", b.vertices, b.faces, b.face_materials, 8)]  # two objects
    assert judge_view([*apart, *tiles], [LAMP], cam).ok


def test_window_flux_is_spread_over_the_room_by_the_split_flux_law():
    """With no lights, a view's only light is the interreflected window flux: the median
    irradiance is ρ/(1 - ρ) Φ/A (integrating-sphere law, ρ the rule's bounce albedo) on every
    visible point, relative to the target irradiance; 0 without it."""
    from spectrinsic.scenes.generators.view_rule import BOUNCE_ALBEDO
    from spectrinsic.scenes.library import TARGET_IRRADIANCE

    cam = _camera((0, 0, 1.5), fov=60)
    dark = judge_view(_floor_with_tiles(), [], cam)
    lit = judge_view(_floor_with_tiles(), [], cam, flux_density=0.3)
    assert dark.median_light == 0.0 and not dark.ok
    rho = BOUNCE_ALBEDO
    assert lit.median_light == pytest.approx(rho / (1 - rho) * 0.3 / TARGET_IRRADIANCE)
    assert lit.lit_share == 1.0
