"""Procedural geometry: closed outward meshes with analytic volumes; exact painted regions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spectrinsic.errors import SceneError
from spectrinsic.scenes.furniture import chair, room, shelf, table
from spectrinsic.scenes.geometry import is_closed
from spectrinsic.scenes.objects import OBJECTS
from spectrinsic.scenes.painting import bands, patches, printed, stripes
from spectrinsic.scenes.parts import Part, moved, to_meshes
from spectrinsic.scenes.primitives import (
    box,
    capsule,
    cone,
    cylinder,
    ellipsoid,
    revolve,
    sphere,
    torus,
)

#: Volumes of exact polyhedra (boxes, prisms) agree to rounding only.
EXACT = 1e-12


def volume(part: Part) -> float:
    """Signed volume by the divergence theorem: positive iff the normals point outwards."""
    tri = part.vertices[part.faces]
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6)


def test_box_is_closed_with_exact_volume_and_grid_faces():
    part = box((1.0, 2.0, 3.0), "flat:0.5", center=(1, 1, 1), divisions=(2, 3, 4))
    assert is_closed(part.faces)
    assert volume(part) == pytest.approx(6.0, rel=EXACT)
    # 2 triangles per grid cell on each pair of opposite faces
    assert len(part.faces) == 2 * 2 * (2 * 3 + 3 * 4 + 4 * 2)
    np.testing.assert_allclose(part.vertices.min(axis=0), [0.5, 0.0, -0.5])


@pytest.mark.parametrize("sections", [6, 24])
def test_cylinder_volume_is_the_prism_volume(sections):
    # a revolved rectangle is a prism over a regular polygon of area n/2 r^2 sin(2 pi / n)
    r, h = 0.3, 1.2
    part = cylinder(r, h, "flat:0.5", sections=sections, rings=3)
    assert is_closed(part.faces)
    assert volume(part) == pytest.approx(
        sections / 2 * r**2 * math.sin(2 * math.pi / sections) * h, rel=EXACT
    )


def test_primitives_are_closed_and_outward():
    parts = [
        sphere(0.5, "flat:0.5"),
        ellipsoid((0.5, 0.2, 0.1), "flat:0.5"),
        cone(0.3, 0.5, "flat:0.5"),
        capsule(0.2, 0.5, "flat:0.5"),
        torus(0.5, 0.1, "flat:0.5"),
        table(1.0, 0.6, 0.7, "flat:0.5"),
        shelf(1.0, 0.4, 1.5, "flat:0.5"),
        chair(0.45, 0.45, "flat:0.5", facing_deg=30),
    ]
    for part in parts:
        assert is_closed(part.faces)
        assert volume(part) > 0


def test_sphere_volume_approaches_analytic():
    # an inscribed icosphere of 5120 faces loses < 0.5 % of the ball's volume
    assert volume(sphere(1.0, "flat:0.5", subdivisions=4)) == pytest.approx(
        4 / 3 * math.pi, rel=5e-3
    )


def test_revolve_paints_profile_segments_exactly():
    profile = [(0, 0), (1, 0), (1, 1), (1, 2), (0, 2)]
    part = revolve(profile, ["flat:0.1", "flat:0.2", "flat:0.3", "flat:0.4"], sections=8)
    z = part.centroids[:, 2]
    spectra = part.face_spectra
    assert set(spectra[z == 0]) == {"flat:0.1"}
    assert set(spectra[(z > 0) & (z < 1)]) == {"flat:0.2"}
    assert set(spectra[(z > 1) & (z < 2)]) == {"flat:0.3"}
    assert set(spectra[z == 2]) == {"flat:0.4"}


def test_revolve_rejects_profiles_off_the_axis():
    with pytest.raises(SceneError, match="axis"):
        revolve([(0.1, 0), (1, 0), (0, 1)], "flat:0.5")


def test_bands_stripes_patches_and_print_follow_centroids():
    part = box((1, 1, 1), "flat:0.5", divisions=(4, 4, 4))
    c = part.centroids
    banded = bands(part, ["flat:0.1", None, "flat:0.9"], axis=2, edges=[-0.25, 0.25])
    s = banded.face_spectra
    assert set(s[c[:, 2] < -0.25]) == {"flat:0.1"}
    assert set(s[(c[:, 2] > -0.25) & (c[:, 2] < 0.25)]) == {"flat:0.5"}
    assert set(s[c[:, 2] > 0.25]) == {"flat:0.9"}

    striped = stripes(part, ["flat:0.1", "flat:0.2"], axis=0, width=0.25, offset=-0.5)
    k = np.floor((c[:, 0] + 0.5) / 0.25).astype(int) % 2
    assert np.array_equal(striped.face_spectra == "flat:0.2", k == 1)

    patched = patches(part, "flat:0.1", [(0.5, 0.0, 0.0)], 0.2)
    near = np.linalg.norm(c - [0.5, 0, 0], axis=1) <= 0.2
    assert near.any() and np.array_equal(patched.face_spectra == "flat:0.1", near)

    inked = printed(part, ["X.", ".X"], {"X": "flat:0.1"}, origin=(-0.5, -0.5), cell=0.25)
    top = part.normals[:, 2] > 0.9
    col = np.floor((c[:, 0] + 0.5) / 0.25)
    row = 1 - np.floor((c[:, 1] + 0.5) / 0.25)
    expected = top & (((row == 0) & (col == 0)) | ((row == 1) & (col == 1)))
    assert expected.sum() == 4  # two cells of two triangles
    assert np.array_equal(inked.face_spectra == "flat:0.1", expected)


def test_moved_applies_scale_rotation_translation_in_order():
    part = box((1, 1, 1), "flat:0.5")
    out = moved(part, scale=(2, 1, 1), rotate_deg=(0, 0, 90), translate=(1, 2, 3))
    # x-extent 2 becomes the y-extent after a quarter turn about z
    np.testing.assert_allclose(out.vertices.min(axis=0), [0.5, 1.0, 2.5], atol=1e-12)
    np.testing.assert_allclose(out.vertices.max(axis=0), [1.5, 3.0, 3.5], atol=1e-12)
    assert volume(out) == pytest.approx(2.0, rel=EXACT)


def test_merge_and_to_meshes_share_one_material_table():
    a = box((1, 1, 1), "flat:0.1")
    b = bands(
        box((1, 1, 1), "flat:0.2", divisions=(1, 1, 2)), ["flat:0.1", None], axis=2, edges=[0.0]
    )
    meshes, materials = to_meshes([("a", a), ("b", b)], first_object_id=5)
    assert [m.spectrum for m in materials] == ["flat:0.1", "flat:0.2"]
    assert [m.object_id for m in meshes] == [5, 6]
    assert set(meshes[0].face_materials) == {0}
    assert set(meshes[1].face_materials) == {0, 1}
    names = np.array([materials[i].spectrum for i in meshes[1].face_materials])
    np.testing.assert_array_equal(names, b.face_spectra)


def test_room_walls_enclose_free_air():
    shell = room(
        (4, 3, 2.5),
        dict.fromkeys(("floor", "ceiling", "left", "right", "back", "front"), "flat:0.5"),
    )
    from spectrinsic.scenes.geometry import winding_numbers

    inside_air = np.array([[2.0, 1.5, 1.2], [0.05, 0.05, 0.05]])
    for part in shell.values():
        assert is_closed(part.faces)
        np.testing.assert_allclose(
            winding_numbers(inside_air, part.vertices, part.faces), 0, atol=1e-9
        )


@pytest.mark.parametrize("name", sorted(OBJECTS))
def test_objects_rest_on_the_ground_and_are_modest(name):
    part = OBJECTS[name]()
    assert part.vertices[:, 2].min() == pytest.approx(0.0, abs=1e-9)
    assert len(part.faces) < 12_000
    assert volume(part) > 0
