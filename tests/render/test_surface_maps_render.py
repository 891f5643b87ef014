"""Opacity masks and bump/normal maps rendered with exact ground truth (issue 42, item 1).

Independent values: which pixels look through a hole is geometry (a quad facing the camera,
its checker mask laid out by hand); ray distances are the camera's distances to two planes; a
normal map of one constant tilt gives a world normal rotated by hand, a height ramp the
analytic bump normal ``normalize(−s ∂p/∂v × …)``; under a directional light a Lambertian
plane's radiance is ``ρ E cos θ / π`` with θ the angle to the *perturbed* normal, so its ratio
to the unperturbed plane is ``n'·z`` exactly (direct light through next-event estimation only:
no Monte Carlo noise). The image against Mitsuba's own spectral ``path`` of the same scene
(its ``mask`` BSDF) is compared per 8 × 8 block within the Monte Carlo error measured here.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from spectrinsic.gt_export import check_dataset, export_sample, write_manifest
from spectrinsic.gt_export.layers import LayerSettings, compute_ground_truth
from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.scenes.image_textures import ImageTexture
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene
from spectrinsic.scenes.surface_maps import MeshMaps
from spectrinsic.spectra.working_space import working_space

SIZE, FOV, DISTANCE = 32, 30.0, 3.0
#: The mask's checker: TEXELS × TEXELS, 1 = opaque (row 0 at v = 0).
TEXELS = 4
QUAD, WALL = Material("red", "munsell:5R 4/14"), Material("blue", "munsell:5PB 4/10")
SKY = (Light("sky", "cie:D65", 1.0),)


def _quad(z: float, half: float, material: int, oid: int, name: str, maps=None) -> Mesh:
    v = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    mesh = Mesh(name, v, f, np.full(2, material), oid)
    if maps is None:
        return mesh
    uv = ((v[:, :2] / half + 1.0) / 2.0)[f]  # u along +x, v along +y
    return replace(mesh, maps=maps(uv))


def _checker() -> np.ndarray:
    index = (np.add.outer(np.arange(TEXELS), np.arange(TEXELS)) % 2).astype(float)
    index[0, 0] = 0.0 if index[0, 0] else 1.0  # break the symmetry: a flip would fail
    return index


def _scene(maps, lights=SKY, wall: bool = True) -> Scene:
    meshes = (_quad(0.0, 1.0, 0, 0, "quad", maps),) + (
        (_quad(-1.0, 3.0, 1, 1, "wall"),) if wall else ()
    )
    camera = Camera((0, 0, DISTANCE), (0, 0, 0), (0, 1, 0), FOV, SIZE, SIZE)
    return Scene("maps", meshes, (QUAD, WALL), tuple(lights), camera)


def _pixels_in_texels() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Texel row (v = 0 at the bottom) and column under each pixel, whether the pixel lies in
    one texel, and each pixel centre's ray direction cosine to the axis (row 0 at the top)."""
    half = DISTANCE * math.tan(math.radians(FOV / 2))  # the quad at z = 0 spans [-1, 1]
    edges = np.linspace(-half, half, SIZE + 1)
    texel = np.floor((edges + 1.0) / 2.0 * TEXELS)
    inside = (texel[:-1] == texel[1:])[:, None] & (texel[:-1] == texel[1:])[None, :]
    cols = np.broadcast_to(texel[None, :-1], (SIZE, SIZE)).astype(int)
    rows = np.broadcast_to(texel[::-1][1:][:, None], (SIZE, SIZE)).astype(int)
    centres = (edges[:-1] + edges[1:]) / 2 / DISTANCE
    cos = 1.0 / np.sqrt(1.0 + centres[None, :] ** 2 + centres[::-1, None] ** 2)
    return rows, cols, inside, cos


@pytest.fixture(scope="module")
def checker():
    """The checker-masked quad before the wall under a sky: scene, render (bands and Mitsuba's
    spectral path) and ground truth."""
    image = ImageTexture("", "", np.repeat(_checker()[..., None], 3, -1), "clamp", "nearest")
    scene = _scene(lambda uv: MeshMaps(uv, opacity_image=image))
    result = render_scene(
        scene, RenderSettings(64, max_depth=3, modes=("spectral", "bands31")), seed=1
    )
    return (
        scene,
        result,
        compute_ground_truth(
            scene, result, LayerSettings(spectral_layers=True, working_space=working_space("srgb"))
        ),
    )


def _plain_reflectance(material: int) -> np.ndarray:
    """The reflectance layer's value of *material* on an unmasked quad filling the view."""
    scene = _scene(None, wall=False)
    scene = replace(scene, meshes=(replace(scene.meshes[0], face_materials=np.full(2, material)),))
    result = render_scene(scene, RenderSettings(1, max_depth=1, modes=("bands31",)), seed=1)
    gt = compute_ground_truth(
        scene, result, LayerSettings(spectral_layers=True, working_space=working_space("srgb"))
    )
    return gt.layers["reflectance"].data[SIZE // 2, SIZE // 2]


def test_checker_mask_first_hits_show_the_wall_through_the_holes(checker):
    scene, result, gt = checker
    rows, cols, inside, cos = _pixels_in_texels()
    opaque = _checker()[rows, cols] == 1.0
    hole, solid = inside & ~opaque, inside & opaque
    assert hole.sum() > 200 and solid.sum() > 200
    cover = result.aovs["coverage"]  # (H, W, surfaces): the quad, then the wall
    np.testing.assert_array_equal(cover[solid][:, :2], [[1.0, 0.0]] * solid.sum())
    np.testing.assert_array_equal(cover[hole][:, :2], [[0.0, 1.0]] * hole.sum())
    np.testing.assert_array_equal(gt.layers["object_id"].data.reshape(SIZE, SIZE)[hole], 1)
    # the ray distance adds up through the null event: the camera to the wall, not the quad
    # (Mitsuba's camera rays start at its near clip plane, 0.01 ahead: atol 0.03)
    depth = result.aovs["depth"].reshape(SIZE, SIZE)
    np.testing.assert_allclose(depth[solid], (DISTANCE / cos)[solid], atol=0.03)
    np.testing.assert_allclose(depth[hole], ((DISTANCE + 1.0) / cos)[hole], atol=0.03)
    refl = gt.layers["reflectance"].data
    np.testing.assert_allclose(
        refl[solid], np.broadcast_to(_plain_reflectance(0), refl[solid].shape), atol=1e-6
    )
    np.testing.assert_allclose(
        refl[hole], np.broadcast_to(_plain_reflectance(1), refl[hole].shape), atol=1e-6
    )


def test_checker_mask_identity_and_check(checker, tmp_path):
    scene, result, gt = checker
    image = gt.layers["image_bands"].data
    composed = (
        gt.layers["reflectance_bands"].data * gt.layers["shading_bands"].data
        + gt.layers["residual_bands"].data
    )
    np.testing.assert_allclose(composed, image, atol=1e-5 * image.max())
    config = {"preset": "test", "width": SIZE, "height": SIZE, "spp": 64, "seed": 1}
    export_sample(tmp_path, scene, result, sample_id="mask", config=config, seed=1)
    write_manifest(tmp_path, config)
    assert check_dataset(tmp_path) == []


def test_checker_mask_image_agrees_with_mitsuba_path_per_block(checker):
    """Per 8 × 8 block and band, the band path's image against Mitsuba's spectral ``path`` of
    the same scene (its own mask BSDF): the difference within 4 standard errors of the two
    renders (the per-pixel spread over the block estimates each block mean's error)."""
    _, result, _ = checker
    a, b = result.images["spectral"], result.images["bands31"]
    blocks = lambda x: x.reshape(4, 8, 4, 8, -1).transpose(0, 2, 1, 3, 4).reshape(16, 64, -1)  # noqa: E731
    ba, bb = blocks(a.sum(-1, keepdims=True)), blocks(b.sum(-1, keepdims=True))
    err = np.sqrt(ba.var(axis=1) / 64 + bb.var(axis=1) / 64)
    diff = np.abs(ba.mean(axis=1) - bb.mean(axis=1))
    assert np.all(diff < 4 * err + 1e-3 * bb.mean()), (diff / err).max()


def test_half_opacity_plane_mixes_reflectance_by_coverage():
    scene = _scene(lambda uv: MeshMaps(uv, opacity=0.5))
    spp = 64
    result = render_scene(scene, RenderSettings(spp, max_depth=2, modes=("bands31",)), seed=3)
    gt = compute_ground_truth(
        scene, result, LayerSettings(spectral_layers=True, working_space=working_space("srgb"))
    )
    cover = result.aovs["coverage"][..., 0]
    sigma = math.sqrt(0.25 / spp)  # a binomial coverage of p = 1/2 over spp samples
    assert abs(cover.mean() - 0.5) < 4 * sigma / SIZE
    assert np.abs(cover - 0.5).max() < 5 * sigma
    rq, rw = _plain_reflectance(0), _plain_reflectance(1)
    expected = cover[..., None] * rq + (1 - cover[..., None]) * rw  # the mix by coverage
    np.testing.assert_allclose(gt.layers["reflectance"].data, expected, atol=1e-5)
    mean = gt.layers["reflectance"].data.reshape(-1, 3).mean(axis=0)
    np.testing.assert_allclose(
        mean, 0.5 * (rq + rw), atol=4 * sigma / SIZE * np.abs(rq - rw).max() + 1e-6
    )


def _lit_plane(maps) -> tuple[np.ndarray, np.ndarray]:
    """The image and the first-hit normals of the quad alone under a directional light."""
    light = Light("directional", "cie:D65", 2.0, direction=(0.0, 0.0, -1.0))
    scene = _scene(maps, lights=(light,), wall=False)
    result = render_scene(scene, RenderSettings(4, max_depth=2, modes=("bands31",)), seed=1)
    return result.images["bands31"], result.aovs["normals"]


def _assert_lambert(maps, expected: np.ndarray, where: np.ndarray) -> None:
    flat, flat_normals = _lit_plane(None)
    image, normals = _lit_plane(maps)
    np.testing.assert_allclose(
        flat_normals[where], np.broadcast_to([0, 0, 1.0], normals[where].shape), atol=1e-6
    )
    np.testing.assert_allclose(
        normals[where], np.broadcast_to(expected, normals[where].shape), atol=1e-4
    )
    ratio = image[where].sum(-1) / flat[where].sum(-1)  # ρ E cos θ' / π over ρ E / π
    np.testing.assert_allclose(ratio, expected[2], rtol=1e-4)


def test_normal_map_of_one_tilt_gives_that_normal_and_lambert_shading():
    tilt = np.array([0.4, -0.3, 0.0])
    tilt[2] = math.sqrt(1 - tilt @ tilt)
    texels = np.broadcast_to((tilt + 1.0) / 2.0, (2, 2, 3)).copy()
    image = ImageTexture("", "", texels, "repeat", "nearest")
    everywhere = np.ones((SIZE, SIZE), bool)
    # the quad's shading frame: s along ∂p/∂u = +x, t = n × s = +y, n = +z
    _assert_lambert(lambda uv: MeshMaps(uv, normal_image=image), tilt, everywhere)


def test_bump_map_height_ramp_gives_the_analytic_tilt():
    width, scale = 8, 0.5
    ramp = (np.arange(width) + 0.5) / width  # bilinear between texel centres: h(u) = u
    texels = np.broadcast_to(ramp[None, :, None], (2, width, 3)).copy()
    image = ImageTexture("", "", texels, "clamp", "bilinear")
    # ∂p/∂u = (2, 0, 0) (u spans the quad's 2 units), ∂p/∂v = (0, 2, 0), ∂h/∂u = 1:
    # n' ∝ (∂p/∂u + scale n) × ∂p/∂v = (−2 scale, 0, 4)
    expected = np.array([-2 * scale, 0.0, 4.0]) / math.hypot(2 * scale, 4.0)
    _assert_lambert(
        lambda uv: MeshMaps(uv, bump_image=image, bump_scale=scale),
        expected,
        np.ones((SIZE, SIZE), bool),
    )


@pytest.mark.parametrize("wall", [True, False])
def test_specular_starts_at_the_first_vertex_that_is_no_null_event(wall):
    """A checker-masked glossy plastic before a matte wall or the sky: the holes show only the
    wall or the sky, so their specular layer is exactly 0 (a null event is no first vertex and
    its band factor is 1, not the (G1) factor of a delta lobe); the plastic's texels have a
    coat highlight. The identity holds with the specular part."""
    image = ImageTexture("", "", np.repeat(_checker()[..., None], 3, -1), "clamp", "nearest")
    scene = _scene(lambda uv: MeshMaps(uv, opacity_image=image), wall=wall)
    coat = Material("coat", "munsell:5R 4/14", kind="plastic", roughness=0.2, ior=1.5)
    scene = replace(scene, materials=(coat, WALL))
    result = render_scene(scene, RenderSettings(16, max_depth=3, modes=("bands31",)), seed=2)
    gt = compute_ground_truth(
        scene, result, LayerSettings(spectral_layers=True, working_space=working_space("srgb"))
    )
    rows, cols, inside, _ = _pixels_in_texels()
    opaque = _checker()[rows, cols] == 1.0
    specular = gt.layers["specular"].data
    assert np.all(specular[inside & ~opaque] == 0.0)
    assert np.all(specular[inside & opaque].sum(-1) > 0.0)
    composed = (
        gt.layers["reflectance"].data * gt.layers["shading"].data
        + gt.layers["specular"].data
        + gt.layers["residual"].data
    )
    np.testing.assert_allclose(composed, gt.layers["image"].data, atol=1e-5)


def test_a_metal_seen_through_a_hole_has_its_white_surface_shading():
    """The white-at-metal loop's first vertex is also the first that is no null event: a
    gold wall seen through the checker's holes gets the white-surface shading ``E / π`` there
    (0 if the loop stopped at the mask), about that of the wall seen directly beside the
    quad (the quad shades part of the holes' sky: within a factor of 3)."""
    image = ImageTexture("", "", np.repeat(_checker()[..., None], 3, -1), "clamp", "nearest")
    scene = _scene(lambda uv: MeshMaps(uv, opacity_image=image))
    gold = Material("gold", "flat:0", kind="conductor", roughness=0.3, metal="Au")
    quad = replace(scene.meshes[0], vertices=scene.meshes[0].vertices * [0.5, 0.5, 1.0])
    scene = replace(scene, meshes=(quad, scene.meshes[1]), materials=(QUAD, gold))
    result = render_scene(scene, RenderSettings(16, max_depth=3, modes=("bands31",)), seed=4)
    gt = compute_ground_truth(
        scene, result, LayerSettings(spectral_layers=True, working_space=working_space("srgb"))
    )
    cover = result.aovs["coverage"]
    shading = gt.layers["shading"].data.sum(-1)
    through = cover[..., 1] == 1.0  # gold first hit: through a hole or beside the quad
    centre = np.zeros((SIZE, SIZE), bool)
    centre[SIZE // 4 : 3 * SIZE // 4, SIZE // 4 : 3 * SIZE // 4] = True  # the quad's footprint
    holes, beside = through & centre, through & ~centre
    assert holes.sum() > 50 and beside.sum() > 50
    assert np.all(shading[holes] > 0.0)
    ratio = shading[holes].mean() / shading[beside].mean()
    assert 1 / 3 < ratio <= 1.05, ratio


def test_a_three_row_map_renders_without_a_word_on_stderr(capfd):
    """A mask whose image has three rows: its texels reach Mitsuba as a Bitmap, so nanobind
    prints no failed colour conversion (a ``(3, …)`` TensorXf printed three lines per load)."""
    image = ImageTexture("", "", np.ones((3, 3, 3)), "clamp", "nearest")
    scene = _scene(lambda uv: MeshMaps(uv, opacity_image=image))
    capfd.readouterr()
    render_scene(scene, RenderSettings(1, modes=("rgb3",), aovs=False), seed=1)
    assert "nanobind" not in capfd.readouterr().err
