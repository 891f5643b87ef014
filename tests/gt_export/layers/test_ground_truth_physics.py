"""Irradiance ground truth against physics (issue 8, Done-when (a)–(h)), with real renders.

Independent values: the analytic irradiance of a plane under a distant light, the colour of a
single bounce (ρ_wall · E integrated with the CIE CMFs), material swaps with common random
numbers, and a 16×-spp render of the same scene as the converged reference.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.gt_export.layers import LayerSettings, compute_ground_truth, identities
from spectrinsic.render import RenderSettings, render_batches, render_scene
from spectrinsic.scenes.model import Material, Scene
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as WL
from spectrinsic.spectra import get_sensors, get_spectrum, responses, xyz_to_linear_srgb
from spectrinsic.spectra.working_space import DEFAULT_WORKING_SPACE, working_space
from tests.gt_export.layers._checks import assert_finite_and_light_nonnegative

#: Band integration (31 box bands of 10 nm) against 1 nm integration of smooth spectra.
BAND_RTOL = 5e-3
#: float32 storage of the identity's terms.
FLOAT32_RTOL = 4 * float(np.finfo(np.float32).eps)
#: Issue 8 (f): the illuminant of a grey surface lit by one bounce is the bounce's colour.
BOUNCE_MAX_DEG = 1.0
#: Issue 8 (c): interior shading moves by less than this when the surface's material changes.
SWAP_MAX = 0.01
#: Issue 8 (g): predicted and observed standard errors agree within this factor.
CALIBRATION_FACTOR = 1.5
#: The first wall of the corner scene (tests/conftest.corner_scene): a flat grey, a saturated chip.
GREY = Material("grey", "flat:0.8")
GREEN = Material("grey", "munsell:5G 6/8")


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a, b = np.asarray(a, float), np.asarray(b, float)
    cos = (a * b).sum(-1) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


def _gt(scene: Scene, **render: object):
    settings = RenderSettings(**{"spp": 16, "max_depth": 3, "modes": ("bands31",), **render})
    result = render_scene(scene, settings, seed=3)
    return compute_ground_truth(scene, result), result


def _interior(gt) -> np.ndarray:
    mask = gt.layers["mask"].data > 0
    mask[[0, -1], :] = mask[:, [0, -1]] = False
    return mask


def test_a_plane_under_d65_has_the_analytic_shading_and_no_residual(make_plane):
    """(a) shading = ∫D65 S cosθ/π relative to white; residual ≈ 0."""
    tilt = 30.0
    scene = make_plane("munsell:5B 5/8", "cie:D65", tilt_deg=tilt, size=8)
    gt, _ = _gt(scene, max_depth=2)
    d65 = get_spectrum("cie:D65").on(WL)
    white_xyz = responses(d65, get_sensors("cie1931").on(WL), WL)
    w = xyz_to_linear_srgb(white_xyz) / white_xyz[1]  # sRGB of the perfect white at Y = 1
    expected = xyz_to_linear_srgb(white_xyz) * np.cos(np.radians(tilt)) / np.pi / w
    shading = gt.layers["shading"].data.reshape(-1, 3)
    np.testing.assert_allclose(shading, np.broadcast_to(expected, shading.shape), rtol=BAND_RTOL)
    image = gt.layers["image"].data
    assert np.abs(gt.layers["residual"].data).max() < BAND_RTOL * np.abs(image).max()
    np.testing.assert_allclose(gt.layers["illuminant"].data.reshape(-1, 3), 1.0, atol=BAND_RTOL)


def test_b_f_a_grey_wall_lit_by_a_bounce_carries_the_bounce_colour(make_corner):
    """(f) illuminant = colour of ρ_wall · D65 within 1°; (b) shading is that colour, not white."""
    gt, _ = _gt(make_corner(GREY))
    inside = _interior(gt)
    assert inside.sum() > 100
    rho = get_spectrum("munsell:5R 5/12").on(WL)
    # the layers' working space (ACEScg by default), relative to its D65 white as the shading
    space = working_space(DEFAULT_WORKING_SPACE)
    bounce = space.rgb(
        responses(rho * get_spectrum("cie:D65").on(WL), get_sensors("cie1931").on(WL), WL)
    ) / np.asarray(space.white)
    assert _angle(gt.layers["illuminant"].data[inside], bounce).max() < BOUNCE_MAX_DEG
    shading = gt.layers["shading"].data[inside]
    assert _angle(shading, bounce).max() < BOUNCE_MAX_DEG
    assert _angle(shading, np.ones(3)).min() > 10.0  # a D65-white shading would be (1, 1, 1)
    # with every bounce (depth 6) the light stays the wall's colour, only brighter
    deep, _ = _gt(make_corner(GREY), max_depth=6)
    assert _angle(deep.layers["shading"].data[inside], bounce).max() < 3 * BOUNCE_MAX_DEG
    grey_y = deep.layers["shading_grey"].data[inside]
    assert (grey_y >= gt.layers["shading_grey"].data[inside]).all()


def test_c_swapping_a_material_leaves_its_shading_and_changes_its_image(make_corner):
    """(c) same paths (same seed), other material: shading moves < 1 %, the image a lot."""
    grey, _ = _gt(make_corner(GREY))
    green, _ = _gt(make_corner(GREEN))
    inside = _interior(grey)
    s0, s1 = grey.layers["shading"].data[inside], green.layers["shading"].data[inside]
    change = np.linalg.norm(s1 - s0, axis=-1) / np.linalg.norm(s0, axis=-1)
    assert change.max() < SWAP_MAX
    i0, i1 = grey.layers["image"].data[inside], green.layers["image"].data[inside]
    assert np.median(np.linalg.norm(i1 - i0, axis=-1) / np.linalg.norm(i0, axis=-1)) > 0.5
    # the thesis' ratio shading, by contrast, carries the material (its red channel here)
    r0, r1 = grey.layers["shading_ratio"].data[inside], green.layers["shading_ratio"].data[inside]
    assert np.median(np.linalg.norm(r1 - r0, axis=-1) / np.linalg.norm(r0, axis=-1)) > 10 * SWAP_MAX


def test_d_e_identity_and_shading_sign_in_a_room_with_interreflections(make_room):
    """(d) image = reflectance ∘ shading + residual to float precision; (e) shading ≥ 0, finite."""
    scene = make_room(size=20)
    result = render_batches(
        scene,
        RenderSettings(8, batches=2, modes=("bands31", "rgb3"), per_light=True, share_mode="rgb3"),
        seed=5,
    )
    gt = compute_ground_truth(
        scene, result, LayerSettings(cameras=("camera:Nikon 5100 (NPL)",), denoise=True)
    )
    for ident in identities(gt):
        image, refl, shading, res = (
            gt.layers[ident[k]].data.astype(np.float64)
            for k in ("image", "reflectance", "shading", "residual")
        )
        np.testing.assert_allclose(
            refl * shading + res, image, rtol=FLOAT32_RTOL, atol=FLOAT32_RTOL * np.abs(image).max()
        )
    assert_finite_and_light_nonnegative(gt)
    share = gt.layers["light_share"].data
    lit = gt.layers["shading_grey"].data > 0
    np.testing.assert_allclose(share[lit].sum(axis=-1), 1.0, atol=1e-5)
    assert sum(light.share for light in gt.lights) == pytest.approx(1.0)


@pytest.fixture(scope="module")
def noisy_and_converged(make_room):
    """A room at 2 batches × 8 spp, and the same room at 16× the spp as the reference."""
    scene = make_room(size=40)
    settings = RenderSettings(
        16, batches=2, modes=("bands31",), max_depth=4, per_light=True, share_mode="rgb3"
    )
    noisy = render_batches(scene, settings, seed=11)
    reference = render_batches(scene, settings.with_options(spp=256, batches=4), seed=99)
    return scene, noisy, reference


def _relative_error(estimate: np.ndarray, reference: np.ndarray, valid: np.ndarray) -> np.ndarray:
    return (
        np.linalg.norm(estimate - reference, axis=-1)[valid]
        / np.linalg.norm(reference, axis=-1)[valid]
    )


def test_g_the_noise_estimate_is_calibrated(noisy_and_converged):
    """(g) RMS predicted standard error of the raw shading matches the RMS observed error
    against the 16×-spp render (its own noise, 1/16 of the variance, removed in quadrature)."""
    scene, noisy, reference = noisy_and_converged
    gt = compute_ground_truth(scene, noisy)
    ref = compute_ground_truth(scene, reference)
    valid = (gt.layers["noise_shading_raw"].data > 0) & (ref.layers["shading_grey"].data > 0)
    assert valid.sum() > 500
    observed = _relative_error(gt.layers["shading"].data, ref.layers["shading"].data, valid)
    predicted = gt.layers["noise_shading_raw"].data[valid]
    rms_pred = np.sqrt(np.mean(predicted**2))
    rms_obs = np.sqrt(max(np.mean(observed**2) - rms_pred**2 / 16, 0.0))
    assert 1 / CALIBRATION_FACTOR < rms_obs / rms_pred < CALIBRATION_FACTOR
    assert gt.noise["batches"] == 2 and gt.noise["shading_raw"]["median"] > 0


def test_h_denoised_shading_is_closer_to_the_converged_render(noisy_and_converged):
    """(h) OIDN on the white-surface radiance beats the raw Monte Carlo shading."""
    scene, noisy, reference = noisy_and_converged
    gt = compute_ground_truth(scene, noisy, LayerSettings(denoise=True))
    ref = compute_ground_truth(scene, reference)
    valid = ref.layers["shading_grey"].data > 0
    raw = _relative_error(gt.layers["shading_raw"].data, ref.layers["shading"].data, valid)
    denoised = _relative_error(gt.layers["shading"].data, ref.layers["shading"].data, valid)
    assert np.median(denoised) < 0.7 * np.median(raw)
    assert "shading" in gt.denoised and "shading_raw" not in gt.denoised


def test_residual_vanishes_on_a_flat_grey_and_not_on_a_saturated_chip(make_corner):
    """A flat reflectance commutes with any light, here the red bounce: the residual of the grey
    wall is float32 round-off; the green chip in the same light does not commute."""
    grey, _ = _gt(make_corner(GREY))
    green, _ = _gt(make_corner(GREEN))
    inside = _interior(grey)
    image, residual = grey.layers["image"].data[inside], grey.layers["residual"].data[inside]
    assert np.abs(residual).max() < 1e-5 * np.abs(image).max()
    image, residual = green.layers["image"].data[inside], green.layers["residual"].data[inside]
    assert np.median(np.linalg.norm(residual, axis=-1) / np.linalg.norm(image, axis=-1)) > 0.01
