"""Scene translation (geometry, camera, lights) and the coverage/id/depth/normal maps."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.errors import SceneError
from spectrinsic.render import (
    RenderSettings,
    render_aovs,
    render_scene,
    scene_to_mitsuba,
    variant_scope,
)
from spectrinsic.render.base.geometry import smooth_corner_normals
from spectrinsic.render.base.plugins import hdr_film, path_integrator, rgb_spectrum
from spectrinsic.render.settings import PassRequest
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene

#: float32 round-off.
FLOAT32_ATOL = 1e-5


def test_crease_keeps_box_corners_sharp_and_smooths_shallow_edges():
    # two faces of a cube meeting at 90°: normals stay the face normals
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 0, 1], [1, 0, 1]], float)
    f = np.array([[0, 1, 2], [0, 3, 4], [0, 4, 1]])
    n = smooth_corner_normals(v, f)
    np.testing.assert_allclose(n[0], [[0, 0, 1]] * 3, atol=1e-12)
    np.testing.assert_allclose(np.abs(n[1]), [[0, 1, 0]] * 3, atol=1e-12)
    # a 10° fold is smoothed: the shared corners get the mean direction
    t = np.radians(10)
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0]], float)
    v[3] = [-np.cos(t), 0, np.sin(t)]
    f = np.array([[0, 1, 2], [3, 0, 2]])
    n = smooth_corner_normals(v, f)
    np.testing.assert_allclose(n[0, 0], n[1, 1], atol=1e-12)
    assert 0.0 < np.degrees(np.arccos(n[0, 0] @ [0, 0, 1])) < 10.0


def _corner_normals_by_loop(v: np.ndarray, f: np.ndarray, crease_deg: float) -> np.ndarray:
    """The docstring's definition, corner by corner: an independent reference."""
    cross = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    unit = [c / np.linalg.norm(c) if np.linalg.norm(c) > 0 else np.zeros(3) for c in cross]
    out = np.zeros((len(f), 3, 3))
    for i, face in enumerate(f):
        for k, vertex in enumerate(face):
            around = [j for j in range(len(f)) if vertex in f[j]]
            total = sum(
                (cross[j] for j in around if unit[i] @ unit[j] >= np.cos(np.radians(crease_deg))),
                np.zeros(3),
            )
            out[i, k] = (
                total / np.linalg.norm(total) if np.linalg.norm(total) > 0 else (0.0, 0.0, 1.0)
            )
    return out


def test_corner_normals_match_a_corner_by_corner_reference():
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=1)
    box = trimesh.creation.box()
    v = np.concatenate([sphere.vertices, box.vertices + 3.0, [[9.0, 9.0, 9.0]]])
    f = np.concatenate(
        [sphere.faces, box.faces + len(sphere.vertices), [[len(v) - 1, len(v) - 1, len(v) - 1]]]
    )  # plus a degenerate face
    for crease in (10.0, 30.0, 60.0):
        np.testing.assert_allclose(
            smooth_corner_normals(v, f, crease), _corner_normals_by_loop(v, f, crease), atol=1e-12
        )


def _marker_scene(x_offset: float) -> Scene:
    """A white floor with a small dark patch displaced along the camera's right (+x)."""
    floor_v = np.array([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]], float)
    patch_v = np.array(
        [[-0.3, -0.3, 0.01], [0.3, -0.3, 0.01], [0.3, 0.3, 0.01], [-0.3, 0.3, 0.01]]
    ) + [x_offset, 0, 0]
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    return Scene(
        name="marker",
        meshes=(
            Mesh("floor", floor_v, faces, np.zeros(2, np.int64), 0),
            Mesh("patch", patch_v, faces, np.ones(2, np.int64), 1),
        ),
        materials=(Material("floor", "flat:0.8"), Material("patch", "flat:0.05")),
        lights=(
            Light("area", "cie:D65", 5.0, position=(0, 0, 3), direction=(0, 0, -1), size=(1, 1)),
        ),
        camera=Camera(
            origin=(0, -4, 4), target=(0, 0, 0), up=(0, 0, 1), fov_deg=50, width=32, height=24
        ),
    )


def test_camera_is_not_mirrored_and_area_light_points_down():
    aovs, _ = render_aovs(_marker_scene(1.2), PassRequest(16, 0))
    ys, xs = np.nonzero(aovs["material_id"] == 1)
    assert xs.size > 0 and xs.mean() > 16, (
        "a patch at +x (camera right) must appear in the right half"
    )
    image = render_scene(
        _marker_scene(1.2), RenderSettings(16, modes=("rgb3",), aovs=False), seed=0
    ).images["rgb3"]
    assert float(image[..., 1].mean()) > 0.0, "an area light facing the floor lights it"


def test_wrong_number_of_colours_is_a_scene_error(make_plane):
    scene = make_plane("flat:0.5", "cie:D65")
    with variant_scope("scalar_rgb"), pytest.raises(SceneError, match="1 materials"):
        scene_to_mitsuba(
            scene,
            materials=[],
            lights=[rgb_spectrum([1, 1, 1])],
            film=hdr_film(4, 4),
            integrator=path_integrator(2),
            sample_count=1,
        )


def test_plane_aovs(make_plane):
    scene = make_plane("flat:0.5", "cie:D65", size=9)
    aovs, seconds = render_aovs(scene, PassRequest(16, 0))
    assert len(seconds) == 1
    np.testing.assert_allclose(aovs["coverage"][..., 0], 1.0, atol=FLOAT32_ATOL)
    assert (
        np.all(aovs["material_id"] == 0) and np.all(aovs["object_id"] == 0) and aovs["mask"].all()
    )
    np.testing.assert_allclose(
        aovs["normals"], np.broadcast_to([0, 0, 1], (9, 9, 3)), atol=FLOAT32_ATOL
    )
    # camera 2 above the plane looking straight down: ray distance 2 at the centre, more off-axis
    assert abs(float(aovs["depth"][4, 4]) - 2.0) < 0.01
    assert float(aovs["depth"][0, 0]) > float(aovs["depth"][4, 4])


@pytest.mark.parametrize(("integrator", "coverage_passes"), [("passes", 3), ("single", 0)])
def test_room_coverage_partitions_each_pixel(make_room, integrator, coverage_passes):
    """From the coverage passes (3 for 7 surfaces) or the traversal's first hits (none)."""
    scene = make_room(size=16)
    result = render_scene(scene, RenderSettings(32, modes=("rgb3",), integrator=integrator), seed=2)
    cov = result.aovs["coverage"]
    assert cov.shape == (16, 16, len(scene.materials))
    # a closed room: every sample hits a material or the (black) area light
    assert np.all(cov.sum(axis=-1) <= 1.0 + FLOAT32_ATOL)
    assert float(cov.sum(axis=-1).mean()) > 0.95
    # coverage fractions come in units of 1/spp: the colour passes' own samples
    np.testing.assert_allclose(cov * 32, np.round(cov * 32), atol=1e-3)
    ids = result.aovs["material_id"]
    inside = ids >= 0
    picked = np.take_along_axis(cov, np.maximum(ids, 0)[..., None], axis=-1)[..., 0]
    assert np.all(picked[inside] >= cov.max(axis=-1)[inside] - FLOAT32_ATOL)
    assert set(np.unique(result.aovs["object_id"])) <= {-1, 0, 1} and 1 in result.aovs["object_id"]
    assert result.meta["timings"]["aovs"]["passes"] == coverage_passes


def test_every_light_kind_of_the_scene_model_translates(make_plane, tmp_path):
    """The translator covers exactly the scene model's table of light kinds (an environment
    map with a map file: its red channel light)."""
    import hashlib
    from dataclasses import replace

    from spectrinsic.render.base.translate import emission_key
    from spectrinsic.scenes.envmaps import envmap_lights
    from spectrinsic.scenes.model import LIGHT_KINDS, make_light

    base = make_plane("flat:0.5", "cie:D65")
    with variant_scope("scalar_rgb") as mi:
        path = tmp_path / "map.exr"
        mi.Bitmap(np.full((2, 4, 3), 0.5, np.float32)).write(str(path))
    sha = hashlib.sha256(path.read_bytes()).hexdigest()
    for kind in LIGHT_KINDS:
        light = (
            envmap_lights("light", str(path), sha, 1.0)[0]
            if kind == "envmap"
            else make_light(
                kind, "cie:D65", 1.0, position=(0.0, 0.0, 1.5), direction=(0.0, 0.0, -1.0)
            )
        )
        scene = replace(base, lights=(light,))
        assert emission_key(scene, 0, spectral=True).endswith(".values")
        with variant_scope("scalar_rgb"):
            d = scene_to_mitsuba(
                scene,
                materials=[rgb_spectrum([0.5, 0.5, 0.5])],
                lights=[rgb_spectrum([1, 1, 1])],
                film=hdr_film(4, 4),
                integrator=path_integrator(2),
                sample_count=1,
            )
        assert "light_0" in d
    bogus = replace(base, lights=(replace(base.lights[0], kind="laser"),))
    with (
        variant_scope("scalar_rgb"),
        pytest.raises(
            SceneError,
            match="unknown light kind 'laser'; expected one of point, spot, area, directional",
        ),
    ):
        scene_to_mitsuba(
            bogus,
            materials=[rgb_spectrum([0.5, 0.5, 0.5])],
            lights=[rgb_spectrum([1, 1, 1])],
            film=hdr_film(4, 4),
            integrator=path_integrator(2),
            sample_count=1,
        )
