"""Denoised shading beside an outline against its closed form (issue 20, part 3: the edges).

The scene: a grey card 1 unit above a grey floor, both facing the camera straight above them
(the same normal: only the depth tells the surfaces apart), lit by a square area light to one
side. With direct light only (``max_depth=2``) the irradiance at an unshadowed point is Lambert's
polygon formula ``E = L/2 Σ_i θ_i (n · ĝ_i)`` over the light's corners (θ_i the angle the edge
i subtends, ĝ_i the unit normal of the plane through the point and that edge), so the grey
shading ``Y(W) = L_Y E / π`` is known at every pixel centre: 2.1× brighter on the card's edge
than on the floor beside it. Area-light sampling makes the render noisy (2 batches of 2 spp: the
raw shading is 11–13 % off per pixel, median), and the denoiser must not blur the card's light
over the floor nor the floor's over the card.

Measured on five seeds (pixels 2–3 px from the outline, lit floor and card): the round-3
denoiser (every band through OIDN ``fast``, normals only, not marked clean) is off by a median
2.4–3.0 % and a 95th percentile of 9.9–12.1 %; the default (broad bands through ``high``, a
depth grey as the edge guide, clean guides) by 1.6–2.1 % and 6.3–8.7 %.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest

from spectrinsic.gt_export.layers import compute_ground_truth
from spectrinsic.gt_export.layers.denoise import Guides, denoise_blocks
from spectrinsic.gt_export.layers.irradiance import WhiteRadiance
from spectrinsic.render import RenderSettings, render_batches
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as WL
from spectrinsic.spectra import get_sensors, get_spectrum, responses
from tests.conftest import quad

SIZE = 64
LIGHT = np.array([1.4, 0.0, 1.8])  # centre of the 1 × 1 light, which faces the origin
CARD_Z, HALF = 1.0, 0.6  # the card: z = 1, |x|, |y| < 0.6
EYE, FOV = np.array([0.0, 0.01, 4.0]), 36.0
#: The denoised grey shading beside the outline: median and 95th percentile relative error.
MEDIAN_MAX, P95_MAX = 0.0225, 0.095


def _scene() -> Scene:
    floor_v, floor_f = quad((-4, -4, 0), (8, 0, 0), (0, 8, 0))
    card_v, card_f = quad((-HALF, -HALF, CARD_Z), (2 * HALF, 0, 0), (0, 2 * HALF, 0))
    aim = -LIGHT / np.linalg.norm(LIGHT)
    return Scene(
        name="card",
        meshes=(
            Mesh("floor", floor_v, floor_f, np.zeros(2, np.int64), object_id=0),
            Mesh("card", card_v, card_f, np.zeros(2, np.int64), object_id=1),
        ),
        materials=(Material("grey", "flat:0.5"),),
        lights=(
            Light("area", "cie:D65", 1.0, position=tuple(LIGHT), direction=tuple(aim), size=(1, 1)),
        ),
        camera=Camera(
            origin=tuple(EYE), target=(0, 0, 0), up=(0, 0, 1), fov_deg=FOV, width=SIZE, height=SIZE
        ),
    )


def _light_corners(light: np.ndarray = LIGHT, target: Sequence[float] = (0, 0, 0)) -> list:
    """Corners of the 1 × 1 light at *light* facing *target*, placed as the renderer places it
    (look-at frame with world z as up; spectrinsic/render/base/translate.py)."""
    aim = np.asarray(target, float) - light
    aim /= np.linalg.norm(aim)
    left = np.cross([0.0, 0.0, 1.0], aim)
    left /= np.linalg.norm(left)
    up = np.cross(aim, left)
    return [light + 0.5 * (sx * left + sy * up) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]


def _lambert(points: np.ndarray, normals: np.ndarray, corners: list) -> np.ndarray:
    """``∫ cos θ dω`` over the polygon *corners* seen from *points* with unit *normals*."""
    a = [(c - points) / np.linalg.norm(c - points, axis=-1, keepdims=True) for c in corners]
    total = np.zeros(points.shape[:-1])
    for u, v in zip(a, a[1:] + a[:1]):
        cross = np.cross(u, v)
        theta = np.arccos(np.clip((u * v).sum(-1), -1.0, 1.0))
        total += theta * (cross * normals).sum(-1) / np.linalg.norm(cross, axis=-1)
    return np.abs(total) / 2


def _rays(eye: np.ndarray, target: Sequence[float], fov: float) -> np.ndarray:
    """``(SIZE, SIZE, 3)`` direction through each pixel centre of a pinhole camera (up +z)."""
    forward = (np.asarray(target, float) - eye) / np.linalg.norm(np.asarray(target, float) - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    t = np.tan(np.radians(fov) / 2)
    col, row = np.meshgrid(np.arange(SIZE), np.arange(SIZE))
    x, y = ((col + 0.5) / SIZE * 2 - 1) * t, (1 - (row + 0.5) / SIZE * 2) * t
    return forward + x[..., None] * right + y[..., None] * up


def _hit(eye: np.ndarray, ray: np.ndarray, axis: int, value: float) -> np.ndarray:
    """Where each ray meets the plane ``coordinate[axis] = value``."""
    return eye + ((value - eye[axis]) / ray[..., axis])[..., None] * ray


def _pixel_points() -> tuple[np.ndarray, np.ndarray]:
    """World point seen through each pixel centre, and whether it is on the card."""
    ray = _rays(EYE, (0, 0, 0), FOV)
    card_hit = _hit(EYE, ray, 2, CARD_Z)
    on_card = (np.abs(card_hit[..., :2]) < HALF).all(axis=-1)
    return np.where(on_card[..., None], card_hit, _hit(EYE, ray, 2, 0.0)), on_card


def _unshadowed(points: np.ndarray, on_card: np.ndarray) -> np.ndarray:
    """Floor points whose segments to every light corner miss the card (with a margin)."""
    free = np.ones(on_card.shape, bool)
    for corner in _light_corners():
        t = (CARD_Z - points[..., 2]) / (corner[2] - points[..., 2])
        hit = points + t[..., None] * (corner - points)
        inside = (np.abs(hit[..., :2]) < HALF + 0.02).all(axis=-1)
        free &= on_card | ~((t > 0) & (t < 1) & inside)
    return free


def _near_outline(side: np.ndarray, inner: int = 1, outer: int = 3) -> np.ndarray:
    """Pixels whose (2·outer+1)² neighbourhood crosses the boundary of *side* but whose
    (2·inner+1)² one does not: 2–3 px from it, never a pixel the two surfaces share."""

    def crosses(r: int) -> np.ndarray:
        pad = np.pad(side, r, mode="edge")
        out = np.zeros_like(side)
        for dy in range(2 * r + 1):
            for dx in range(2 * r + 1):
                out |= pad[dy : dy + SIZE, dx : dx + SIZE] != side
        return out

    return crosses(outer) & ~crosses(inner)


@pytest.fixture(scope="module")
def card():
    scene = _scene()
    points, on_card = _pixel_points()
    y_d65 = responses(get_spectrum("cie:D65").on(WL), get_sensors("cie1931").on(WL), WL)[1]
    expected = y_d65 * _lambert(points, np.array([0.0, 0.0, 1.0]), _light_corners()) / np.pi
    settings = RenderSettings(spp=4, batches=2, max_depth=2, modes=("bands31",))
    result = render_batches(scene, settings, seed=1)
    lit = _unshadowed(points, on_card)
    return scene, result, expected, lit, _near_outline(on_card) & lit


def _errors(gt, expected: np.ndarray, where: np.ndarray) -> np.ndarray:
    return np.abs(gt.layers["shading_grey"].data / expected - 1)[where]


def test_the_closed_form_is_the_renders_expectation(card):
    """The raw (undenoised) shading is unbiased against Lambert's formula: its mean ratio over
    the lit pixels is 1 within the Monte Carlo error of that mean (~0.4 %)."""
    scene, result, expected, lit, _ = card
    gt = compute_ground_truth(scene, result)
    ratio = gt.layers["shading_grey"].data[lit] / expected[lit]
    assert lit.sum() > 1500
    assert ratio.mean() == pytest.approx(1.0, abs=0.015)


def test_denoised_shading_beside_an_outline_stays_near_the_closed_form(card):
    """The stored (denoised) grey shading 2–3 px from the card's outline is within a few % of
    the closed form; the raw one is not."""
    scene, result, expected, _, near = card
    raw = _errors(compute_ground_truth(scene, result), expected, near)
    stored = _errors(compute_ground_truth(scene, result, denoise=True), expected, near)
    assert near.sum() > 300
    assert np.median(raw) > 0.08  # the render is noisy there
    assert np.median(stored) < MEDIAN_MAX
    assert np.percentile(stored, 95) < P95_MAX


def test_the_previous_denoiser_blurred_the_outline(card):
    """The same scene through the round-3 denoiser (every band through OIDN ``fast``, normals
    only, not marked clean) misses the bounds above: what the default fixed."""
    scene, result, expected, _, near = card

    def previous(radiance: WhiteRadiance, guides: Guides) -> WhiteRadiance:
        bands = denoise_blocks(radiance.bands, guides.normals, quality="fast", clean_aux=False)
        return radiance.with_bands(bands)

    gt = compute_ground_truth(scene, result, denoise=True, denoiser=previous)
    old = _errors(gt, expected, near)
    assert np.median(old) > MEDIAN_MAX or np.percentile(old, 95) > P95_MAX


def test_denoised_bands_of_a_third_sum_to_its_denoised_broad_band(card):
    """W = share · broad: the shares of a third sum to 1, so the stored bands of a third sum to
    the broad band OIDN denoised; W ≥ 0 everywhere."""
    from spectrinsic.gt_export.layers import denoise as dn

    scene, result, *_ = card
    seen = {}

    def spy(radiance: WhiteRadiance, guides: Guides) -> WhiteRadiance:
        seen["raw"] = radiance
        seen["out"] = dn.denoise_white_radiance(radiance, guides)
        return seen["out"]

    compute_ground_truth(scene, result, denoise=True, denoiser=spy)
    raw, out = seen["raw"], seen["out"]
    thirds = dn.band_thirds(raw.bands.shape[-1])
    broad = dn.denoise_rgb(
        raw.bands @ thirds,
        result.aovs["normals"],
        albedo=dn.depth_guide(result.aovs["depth"], raw.bands.shape[:-1] + (3,)),
        quality=dn.BROAD_QUALITY,
    )
    valid = raw.valid
    np.testing.assert_allclose((out.bands @ thirds)[valid], broad[valid], rtol=1e-6, atol=1e-9)
    assert (out.bands >= 0).all()


#: The crease: a floor (z = 0, x ≥ 0) meeting a wall (x = 0) at a right angle, the light in
#: front of both (no shadow), the camera looking into the corner.
CREASE_LIGHT, CREASE_AIM = np.array([1.5, -2.5, 3.0]), (0.5, 0.0, 0.0)
CREASE_EYE, CREASE_TARGET, CREASE_FOV = np.array([3.0, 0.8, 2.0]), (0.0, 0.0, 0.4), 40.0


def test_denoised_shading_beside_a_crease_stays_near_the_closed_form():
    """The normals guide keeps a crease: 2–3 px from it the denoised grey shading is within
    1.5 % (median) and 5 % (p95) of Lambert's formula on each plane (the wall gets half the
    floor's irradiance at the crease). Measured on three seeds: 0.8–1.0 % / 2.5–3.3 %; the
    round-3 denoiser kept it too (0.9–1.2 % / 3.7–4.4 %), so this one guards, it does not
    separate them."""
    floor_v, floor_f = quad((0, -3, 0), (4, 0, 0), (0, 6, 0))
    wall_v, wall_f = quad((0, -3, 0), (0, 6, 0), (0, 0, 4))
    aim = np.asarray(CREASE_AIM) - CREASE_LIGHT
    scene = Scene(
        name="crease",
        meshes=(
            Mesh("floor", floor_v, floor_f, np.zeros(2, np.int64), object_id=0),
            Mesh("wall", wall_v, wall_f, np.zeros(2, np.int64), object_id=1),
        ),
        materials=(Material("grey", "flat:0.5"),),
        lights=(
            Light(
                "area",
                "cie:D65",
                1.0,
                position=tuple(CREASE_LIGHT),
                direction=tuple(aim / np.linalg.norm(aim)),
                size=(1, 1),
            ),
        ),
        camera=Camera(
            origin=tuple(CREASE_EYE),
            target=CREASE_TARGET,
            up=(0, 0, 1),
            fov_deg=CREASE_FOV,
            width=SIZE,
            height=SIZE,
        ),
    )
    ray = _rays(CREASE_EYE, CREASE_TARGET, CREASE_FOV)
    floor_hit = _hit(CREASE_EYE, ray, 2, 0.0)
    on_floor = floor_hit[..., 0] >= 0
    points = np.where(on_floor[..., None], floor_hit, _hit(CREASE_EYE, ray, 0, 0.0))
    normals = np.where(on_floor[..., None], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    corners = _light_corners(CREASE_LIGHT, CREASE_AIM)
    y_d65 = responses(get_spectrum("cie:D65").on(WL), get_sensors("cie1931").on(WL), WL)[1]
    expected = y_d65 * _lambert(points, normals, corners) / np.pi
    inside = (np.abs(points[..., 1]) < 2.8) & (points[..., 0] < 3.8) & (points[..., 2] < 3.8)
    near = _near_outline(on_floor) & inside
    settings = RenderSettings(spp=4, batches=2, max_depth=2, modes=("bands31",))
    result = render_batches(scene, settings, seed=1)
    raw = compute_ground_truth(scene, result)
    ratio = raw.layers["shading_grey"].data[inside] / expected[inside]
    assert ratio.mean() == pytest.approx(1.0, abs=0.015)  # the closed form is the expectation
    stored = _errors(compute_ground_truth(scene, result, denoise=True), expected, near)
    assert near.sum() > 250
    assert np.median(stored) < 0.015 and np.percentile(stored, 95) < 0.05
