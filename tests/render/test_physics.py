"""Rendering physics: analytic values, spectral vs band cube, common random numbers, energy.

Tolerances: exact identities are float32 round-off; Monte Carlo checks use bounds in standard
errors estimated from the renders themselves.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.render import (
    RenderSettings,
    channel_values,
    get_mode,
    render_batches,
    render_diagonal,
    render_scene,
    to_xyz_matrix,
)
from spectrinsic.render.settings import PassRequest
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as WL
from spectrinsic.spectra import get_sensors, get_spectrum, responses

#: float32 round-off of a deterministic render against a float64 prediction.
FLOAT32_RTOL = 1e-4
#: Standard errors a Monte Carlo mean may sit from its expectation.
N_SIGMA = 4.0
#: Relative bias allowed on top of the noise bound: Mitsuba integrates the piecewise-linear
#: spectra continuously, we sum them on the 1 nm grid (measured < 5e-5).
GRID_BIAS = 5e-4
#: Scene-mean colour of the 31-band cube vs the spectral reference (relative).
CUBE_VS_SPECTRAL_MEAN = 5e-3
#: Per-pixel check of the cube against the spectral reference: variance of (cube - spectral) over the sum of both noise variances
#: (1 when they differ only by noise); the band-approximation bias would push it above.
NOISE_VARIANCE_RATIO_MAX = 1.3
#: Band-cube error on a flat-reflectance scene: only the integration of the light spectra
#: (smooth Planckian/daylight) against the CMFs, measured < 0.2 %.
FLAT_BANDS_TOL = 5e-3
#: Flat-reflectance scene, 6 Gaussians regressed to XYZ: the regression's error on the lights'
#: own spectra, measured < 1 %.
FLAT_RGB6_TOL = 2e-2


def _plane_prediction(reflectance: str, light: str, tilt_deg: float, sensors: str) -> np.ndarray:
    """Exact ``∫ ρ E S_k cosθ / π dλ`` of a Lambertian plane under a distant light."""
    rho, e = get_spectrum(reflectance).on(WL), get_spectrum(light).on(WL)
    return (
        responses(rho * e, get_sensors(sensors).on(WL), WL) * np.cos(np.radians(tilt_deg)) / np.pi
    )


@pytest.mark.parametrize(
    ("reflectance", "light"), [("munsell:5R 5/12", "planck:2800K"), ("munsell:5B 5/8", "cie:D65")]
)
def test_plane_spectral_reference_is_analytic(make_plane, reflectance, light):
    """A diffuse plane under a directional light renders ∫ρ E S cosθ/π within noise."""
    scene = make_plane(reflectance, light, tilt_deg=30.0, size=16)
    result = render_scene(scene, RenderSettings(256, modes=("spectral",), aovs=False), seed=1)
    pixels = result.images["spectral"].reshape(-1, 3).astype(np.float64)
    expected = _plane_prediction(reflectance, light, 30.0, "cie1931")
    stderr = pixels.std(axis=0, ddof=1) / np.sqrt(len(pixels))
    assert np.all(stderr > 0), "the spectral variant should carry wavelength noise"
    assert np.all(np.abs(pixels.mean(axis=0) - expected) <= N_SIGMA * stderr + GRID_BIAS * expected)


def test_plane_diagonal_renders_are_eq_5_2(make_plane):
    """Diagonal passes on the plane have no noise and equal (∫ρS/∫S)(∫E S) cosθ/π exactly."""
    reflectance, light, tilt = "munsell:5R 5/12", "planck:2800K", 30.0
    scene = make_plane(reflectance, light, tilt_deg=tilt, size=8)
    result = render_scene(scene, RenderSettings(4, modes=("rgb3", "bands31"), aovs=False), seed=1)
    rho, e = get_spectrum(reflectance).on(WL), get_spectrum(light).on(WL)
    for mode in ("rgb3", "bands31"):
        s = get_sensors(get_mode(mode).sensors).on(WL)
        raw = responses(rho, s, WL) / responses(np.ones(WL.size), s, WL) * responses(e, s, WL)
        raw *= np.cos(np.radians(tilt)) / np.pi
        np.testing.assert_allclose(
            result.raw[mode], np.broadcast_to(raw, result.raw[mode].shape), rtol=FLOAT32_RTOL
        )
    # the band cube integrates to nearly the exact colour; the CMF diagonal is far off for a red
    # chip under warm light, because x̄'s blue lobe averages in the chip's low blue reflectance
    exact = _plane_prediction(reflectance, light, tilt, "cie1931")
    cube = result.images["bands31"][0, 0]
    np.testing.assert_allclose(cube, exact, rtol=CUBE_VS_SPECTRAL_MEAN)
    assert abs(result.images["rgb3"][0, 0, 0] / exact[0] - 1) > 0.05


@pytest.mark.slow
def test_cube_agrees_with_spectral_reference(make_room):
    """31-band cube vs spectral reference: mean colour within 0.5 %, pixels within noise."""
    scene = make_room(
        lights=(("point", "planck:3500K", 1.5), ("area", "daylight:6500K", 3.0)), size=24
    )
    # the spectral pass costs about one RGB pass but is much noisier (wavelength sampling, heavy
    # tails): it gets 8x the samples of the 11-pass cube
    spec = [
        render_scene(scene, RenderSettings(2048, modes=("spectral",), aovs=False), seed=s).images[
            "spectral"
        ]
        for s in (1, 2)
    ]
    cube = [
        render_scene(scene, RenderSettings(256, modes=("bands31",), aovs=False), seed=s).images[
            "bands31"
        ]
        for s in (1, 2)
    ]
    spec = [a.astype(np.float64) for a in spec]
    cube = [a.astype(np.float64) for a in cube]
    spec_mean, cube_mean = (spec[0] + spec[1]) / 2, (cube[0] + cube[1]) / 2
    np.testing.assert_allclose(
        spec_mean.mean(axis=(0, 1)), cube_mean.mean(axis=(0, 1)), rtol=CUBE_VS_SPECTRAL_MEAN
    )
    # noise variance of one render from two independent seeds: var(a1 - a2) = 2 var(a)
    noise = (np.var(spec[0] - spec[1], axis=(0, 1)) + np.var(cube[0] - cube[1], axis=(0, 1))) / 2
    ratio = np.var(spec[0] - cube[0], axis=(0, 1)) / noise
    assert np.all(ratio < NOISE_VARIANCE_RATIO_MAX), ratio


def test_common_random_numbers(make_room):
    """Changing one channel's values leaves the pass's other channels bit-identical."""
    scene = make_room(size=16)
    values = channel_values(scene, get_sensors("cie1931"))
    changed_materials = values.materials.copy()
    changed_materials[:, 0] = changed_materials[::-1, 0]
    changed_lights = values.lights.copy()
    changed_lights[:, 0] *= 3.0
    changed = type(values)(materials=changed_materials, lights=changed_lights)
    a, b = render_diagonal(scene, [values, changed], PassRequest(8, 7))
    np.testing.assert_array_equal(a.image[..., 1:], b.image[..., 1:])
    assert not np.allclose(a.image[..., 0], b.image[..., 0])


def test_interreflections_carry_energy(make_room):
    """3(d): in a closed room the full render carries more energy than direct light alone."""
    scene = make_room(size=16)
    result = render_scene(
        scene, RenderSettings(16, modes=("rgb3",), direct=True, aovs=False), seed=3
    )
    full, one = result.images["rgb3"], result.direct["rgb3"]
    r = result.energy_ratio("rgb3")
    assert np.all(full >= one - 1e-6), "with shared paths a longer path depth only adds light"
    assert 0.3 < r < 0.95, r


def test_flat_materials_make_modes_agree(make_room):
    """3(e): all materials spectrally flat -> 3-, 6- and 31-channel renders agree."""
    flat = tuple(f"flat:{v}" for v in (0.2, 0.4, 0.6, 0.8, 0.5, 0.5))
    scene = make_room(wall_spectra=flat, cube_spectrum="flat:0.3", size=16)
    result = render_scene(
        scene, RenderSettings(8, modes=("rgb3", "rgb6", "bands31"), aovs=False), seed=5
    )
    ref = result.images["rgb3"].astype(np.float64)
    for mode, tol in (("bands31", FLAT_BANDS_TOL), ("rgb6", FLAT_RGB6_TOL)):
        err = np.linalg.norm(result.images[mode] - ref, axis=-1) / np.linalg.norm(ref, axis=-1)
        assert float(err.max()) < tol, (mode, float(err.max()))
    # control: coloured materials break the agreement
    coloured = render_scene(
        make_room(size=16), RenderSettings(8, modes=("rgb3", "bands31"), aovs=False), seed=5
    )
    ref = coloured.images["bands31"].astype(np.float64)
    err = np.linalg.norm(coloured.images["rgb3"] - ref, axis=-1) / np.linalg.norm(ref, axis=-1)
    assert float(err.max()) > 10 * FLAT_BANDS_TOL


def test_per_light_renders_sum_to_full_render(make_room):
    """One scene per light; their sum is the image and matches a render of all lights at once."""
    scene = make_room(size=16)
    split = render_scene(
        scene, RenderSettings(128, modes=("rgb3",), per_light=True, aovs=False), seed=11
    )
    whole = render_scene(scene, RenderSettings(128, modes=("rgb3",), aovs=False), seed=12)
    assert len(split.per_light) == 2
    total = split.per_light[0]["rgb3"].astype(np.float64) + split.per_light[1]["rgb3"]
    np.testing.assert_allclose(split.images["rgb3"], total, rtol=FLOAT32_RTOL, atol=1e-6)
    a, b = split.images["rgb3"].astype(np.float64), whole.images["rgb3"].astype(np.float64)
    # each light alone lights the room differently: both parts carry energy
    assert all(float(p["rgb3"].sum()) > 0.1 * float(a.sum()) for p in split.per_light)
    # unbiased estimates of the same image: the means agree within their noise
    diff = (a - b).reshape(-1, 3)
    stderr = diff.std(axis=0, ddof=1) / np.sqrt(len(diff))
    assert np.all(np.abs(diff.mean(axis=0)) <= N_SIGMA * stderr)


def test_to_xyz_uses_the_scene_lights_for_rgb6(make_plane):
    a = to_xyz_matrix(get_mode("rgb6"), make_plane("flat:0.5", "planck:2800K"))
    b = to_xyz_matrix(get_mode("rgb6"), make_plane("flat:0.5", "daylight:6500K"))
    assert a.shape == (3, 6) and not np.allclose(a, b)


def test_adaptive_batches_stop_at_the_target_or_the_cap(make_room):
    """--noise-target: more batches only while the measured noise is above the target."""
    from spectrinsic.render import image_noise

    scene = make_room(size=12)
    settings = RenderSettings(4, modes=("rgb3",), batches=2, aovs=False, max_batches=3)
    capped = render_batches(scene, settings.with_options(noise_target=1e-9), seed=1)
    assert capped.meta["batches"] == 3 and len(capped.batch_raw) == 3
    assert capped.meta["noise_target"]["reached"] > 1e-9
    easy = render_batches(scene, settings.with_options(noise_target=0.99), seed=1)
    assert easy.meta["batches"] == 2
    assert easy.meta["noise_target"]["reached"] == pytest.approx(
        image_noise(
            [
                render_scene(scene, RenderSettings(2, modes=("rgb3",), aovs=False), seed=s)
                for s in easy.meta["batch_seeds"]
            ]
        )
    )
