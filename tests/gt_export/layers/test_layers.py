"""Ground-truth layers against independent computations (colour-science, analytic identities)."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.gt_export.layers import REFLECTANCE_FLOOR, LayerSettings, compute_ground_truth
from spectrinsic.spectra.working_space import DEFAULT_WORKING_SPACE, WORKING_SPACES

#: The issue's bound for reflectance against colour-science.
REFLECTANCE_TOL = 1e-4
#: The issue's bound for the illuminant map's colour where one light shines.
ILLUMINANT_MAX_DEG = 0.5
#: float32 storage of reflectance and shading and their product: a few ulps.
FLOAT32_RTOL = 4 * float(np.finfo(np.float32).eps)
#: Camera images come from 31 box bands (10 nm, 395-705 nm) instead of the full spectrum:
#: measured here at < 1 % for smooth reflectances and Planckian light.
CUBE_BAND_RTOL = 0.02
CAMERA = "camera:Nikon 5100 (NPL)"


#: colour-science's name of the layers' default working space (ACEScg).
CS_SPACE = WORKING_SPACES[DEFAULT_WORKING_SPACE]


def _cs_absolute_reflectance(spectrum: np.ndarray) -> np.ndarray:
    """Working-space RGB (ACEScg, no chromatic adaptation) of a reflectance under D65, by
    colour-science alone (white Y = 1).

    *spectrum* is given on the 1 nm CIE grid 360-830 nm, so colour-science interpolates
    nothing: resampling of coarser data (linear in spectrinsic, Sprague in colour-science,
    which differ by ~1e-4 for 5-10 nm ColorChecker data) is not what this test checks.
    """
    import colour

    sd = colour.SpectralDistribution(dict(zip(np.arange(360.0, 831.0), spectrum)))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(cmfs.shape)  # Sprague, edge held
    xyz = colour.sd_to_XYZ(sd, cmfs, d65, method="Integration") / 100
    return colour.XYZ_to_RGB(xyz, CS_SPACE, apply_cctf_encoding=False)


def _cs_unit_rgb(spd: np.ndarray) -> np.ndarray:
    """Working-space RGB of an SPD on the 1 nm grid at unit luminance, by colour-science."""
    import colour

    sd = colour.SpectralDistribution(dict(zip(np.arange(360.0, 831.0), spd)))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    xyz = colour.sd_to_XYZ(sd, cmfs, method="Integration")
    return colour.XYZ_to_RGB(xyz / xyz[1], CS_SPACE, apply_cctf_encoding=False)


def _cs_light_rgb(name: str) -> np.ndarray:
    """A light's colour at unit luminance in the working space relative to the space's D65
    white (the ``illuminant`` layer's units, D65 = (1, 1, 1)), by colour-science."""
    from spectrinsic.spectra import get_spectrum

    wl = np.arange(360.0, 831.0)
    return _cs_unit_rgb(get_spectrum(name).on(wl)) / _cs_unit_rgb(get_spectrum("cie:D65").on(wl))


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a, b = np.asarray(a, float), np.asarray(b, float)
    cos = (a * b).sum(-1) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


def test_interior_and_edge_reflectance_match_colour_science(one_light_sample, synth):
    from spectrinsic.spectra import get_spectrum

    scene, result = one_light_sample
    gt = compute_ground_truth(scene, result, LayerSettings(cameras=()))
    refl = gt.layers["reflectance"].data
    wl = np.arange(360.0, 831.0)
    spectra = [get_spectrum(m).on(wl) for m in synth.MATERIALS]
    for (row, col), m in (((3, 3), 0), ((3, 10), 1), ((8, 3), 2), ((8, 10), 3)):
        expected = _cs_absolute_reflectance(spectra[m])
        np.testing.assert_allclose(refl[row, col], expected, atol=REFLECTANCE_TOL)
    # the anti-aliased edge pixel is 25 % material 0 and 75 % material 1; reflectance is linear
    # in the spectrum, so it equals the colour of the mixed spectrum
    mixed = 0.25 * spectra[0] + 0.75 * spectra[1]
    np.testing.assert_allclose(refl[3, 7], _cs_absolute_reflectance(mixed), atol=REFLECTANCE_TOL)
    # half over background: half the reflectance; background itself: none
    np.testing.assert_allclose(refl[8, 15], 0.5 * refl[8, 10], rtol=1e-6)
    assert (refl[0] == 0).all()
    assert gt.materials == {str(i): m for i, m in enumerate(synth.MATERIALS)}


def test_image_equals_reflectance_times_shading_plus_residual(two_light_sample):
    """(d) of the issue: the identity holds to float32 precision on every pixel, per space."""
    from spectrinsic.gt_export.layers import identities

    scene, result = two_light_sample
    gt = compute_ground_truth(scene, result, LayerSettings(cameras=(CAMERA,)))
    assert len(identities(gt)) == 2
    for ident in identities(gt):
        image, refl, shading, res = (
            gt.layers[ident[k]].data for k in ("image", "reflectance", "shading", "residual")
        )
        assert image.dtype == refl.dtype == shading.dtype == res.dtype == np.float32
        rebuilt = refl.astype(np.float64) * shading + res
        scale = np.abs(image).max()
        np.testing.assert_allclose(rebuilt, image, rtol=FLOAT32_RTOL, atol=FLOAT32_RTOL * scale)
        assert np.isfinite(shading).all() and (shading >= 0).all()  # (e)
    # the thesis' per-channel ratio is kept, with its own exact identity
    image, refl = gt.layers["image"].data, gt.layers["reflectance"].data
    ratio = gt.layers["shading_ratio"].data
    valid = np.abs(refl) > REFLECTANCE_FLOOR
    assert valid.sum() > 0.5 * valid.size
    np.testing.assert_allclose(
        refl[valid].astype(np.float64) * ratio[valid], image[valid], rtol=FLOAT32_RTOL, atol=0
    )
    assert (ratio[~valid] == 0).all()


def test_shading_of_a_flat_grey_is_geometry_times_light_colour(one_light_sample):
    scene, result = one_light_sample
    gt = compute_ground_truth(scene, result, LayerSettings(cameras=()))
    block = (slice(6, 11), slice(8, 15))  # material 3 = flat:0.8
    shading = gt.layers["shading"].data[block]
    light = _cs_light_rgb(scene.lights[0].spectrum)
    assert _angle(shading, light).max() < 0.05
    # grey shading is proportional to the geometric factor there (the ramp of the fixture)
    yy, xx = np.mgrid[0:12, 0:16] / 16
    geometry = (0.2 + 0.8 * xx * (0.5 + yy))[block]
    ratio = gt.layers["shading_grey"].data[block] / geometry
    np.testing.assert_allclose(ratio, ratio.mean(), rtol=1e-5)


def test_one_light_illuminant_map_has_the_light_chromaticity(synth):
    import colour

    scene = synth.make_scene(("planck:2800K",))
    geometry = np.ones((1, synth.H, synth.W))
    geometry[0, :, :5] = 0.0  # a shadow: no light arrives there
    result = synth.make_result(scene, geometry)
    gt = compute_ground_truth(scene, result, LayerSettings(cameras=()))
    illum = gt.layers["illuminant"].data
    lit = result.aovs["mask"] & (geometry[0] > 0)
    expected = _cs_light_rgb("planck:2800K")
    assert _angle(illum[lit], expected).max() < ILLUMINANT_MAX_DEG
    assert (illum[:, :5] == 0).all()
    # and the chromaticity recorded for the light agrees with colour-science's xy
    from spectrinsic.spectra import get_spectrum

    wl = np.arange(360.0, 831.0)
    sd = colour.SpectralDistribution(dict(zip(wl, get_spectrum("planck:2800K").on(wl))))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    xy = colour.XYZ_to_xy(colour.sd_to_XYZ(sd, cmfs, method="Integration"))
    np.testing.assert_allclose(gt.lights[0].xy, xy, atol=1e-4)


def test_two_lights_mix_by_their_share_of_the_light(synth):
    scene = synth.make_scene(("planck:2800K", "cie:FL11"))
    geometry = np.zeros((2, synth.H, synth.W))
    geometry[0, :, :6] = 1.0  # light 0 only on the left
    geometry[1, :, 10:] = 1.0  # light 1 only on the right
    geometry[:, :, 6:10] = 1.0  # both in the middle, equal unit-luminance power
    result = synth.make_result(scene, geometry)
    gt = compute_ground_truth(scene, result, LayerSettings(cameras=()))
    illum = gt.layers["illuminant"].data
    mask = result.aovs["mask"]
    c0, c1 = _cs_light_rgb("planck:2800K"), _cs_light_rgb("cie:FL11")
    left, right = mask.copy(), mask.copy()
    left[:, 6:] = right[:, :10] = False
    assert _angle(illum[left], c0).max() < ILLUMINANT_MAX_DEG
    assert _angle(illum[right], c1).max() < ILLUMINANT_MAX_DEG
    # both lights on the flat grey (rows 6-10, columns 8-9): a spectrally flat surface reflects
    # the same luminance of each unit-luminance light, so the light there is their mean colour
    middle_grey = illum[6:11, 8:10].reshape(-1, 3)
    assert _angle(middle_grey, 0.5 * (c0 + c1)).max() < ILLUMINANT_MAX_DEG
    import colour

    from spectrinsic.spectra import get_spectrum

    # unit luminance: Y of the light (the illuminant times the space's D65 white) is 1
    white = _cs_unit_rgb(get_spectrum("cie:D65").on(np.arange(360.0, 831.0)))
    to_y = np.asarray(colour.RGB_COLOURSPACES[CS_SPACE].matrix_RGB_to_XYZ)[1]
    y = (illum[mask] * white) @ to_y
    np.testing.assert_allclose(y, 1.0, atol=1e-3)
    assert gt.lights[0].share + gt.lights[1].share == pytest.approx(1.0)


def test_camera_image_from_the_cube_matches_spectral_integration(one_light_sample, synth):
    from spectrinsic.spectra import get_sensors, get_spectrum

    scene, result = one_light_sample
    gt = compute_ground_truth(scene, result, LayerSettings(cameras=(CAMERA,)))
    wl = np.arange(360.0, 831.0)
    curves = get_sensors(CAMERA).on(wl)
    d65 = get_spectrum("cie:D65").on(wl)
    ybar = get_sensors("cie1931").on(wl)[1]
    scale = (d65 @ ybar) / (curves @ d65).mean()  # perfect white under D65: mean channel 1
    rho = np.stack([get_spectrum(m).on(wl) for m in synth.MATERIALS])
    spd = get_spectrum(scene.lights[0].spectrum).on(wl)
    yy, xx = np.mgrid[0:12, 0:16] / 16
    g = 0.2 + 0.8 * xx * (0.5 + yy)
    radiance = (synth.coverage_map() @ rho) * g[..., None] * spd
    expected = radiance @ curves.T * scale
    image = gt.layers["image_camera/Nikon 5100 (NPL)"].data
    lit = result.aovs["mask"]
    np.testing.assert_allclose(image[lit], expected[lit], rtol=CUBE_BAND_RTOL)
    # relative reflectance of the flat grey: 0.8 × the camera's white, which has mean 1
    refl = gt.layers["reflectance_camera/Nikon 5100 (NPL)"].data
    white = (curves * d65).sum(axis=1) / (d65 @ ybar) * scale
    np.testing.assert_allclose(refl[8, 10], 0.8 * white, rtol=1e-5)
    assert white.mean() == pytest.approx(1.0)


def test_photometric_matrices(synth):
    from spectrinsic.spectra import absolute_reflectance, angular_error

    scene = synth.make_scene(("cie:D65", "planck:2800K"))
    gt = compute_ground_truth(scene, synth.make_result(scene), LayerSettings(cameras=(CAMERA,)))
    m = gt.matrices
    # D65 is the canonical light: L_CLig is the identity in every sensor space
    for space in ("srgb", "Nikon 5100 (NPL)"):
        np.testing.assert_allclose(m["L_CLig"][space]["light 0"], np.eye(3), atol=1e-9)
        assert len(m["L_CLig_diagonal"][space]["light 1"]) == 3
    # under 2800K, L_CLig (full 3x3) predicts the sRGB colour of a chip far better than
    # assuming D65 (thesis Fig. 4.3: SC1 vs SC4)
    from spectrinsic.gt_export.layers import canonical_responses
    from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as wl
    from spectrinsic.spectra import get_sensors, get_spectrum

    chips = [
        "munsell:5R 4/14",
        "munsell:5PB 4/10",
        "colorchecker:dark skin",
        "colorchecker:foliage",
    ]
    canonical = absolute_reflectance(chips)
    rho = np.stack([get_spectrum(c).on(wl) for c in chips])
    under = canonical_responses(
        rho, get_spectrum("planck:2800K").on(wl), get_sensors("srgb").on(wl), wl
    )
    predicted = canonical @ np.asarray(m["L_CLig"]["srgb"]["light 1"]).T
    fitted, assumed = angular_error(predicted, under), angular_error(canonical, under)
    assert fitted.mean() < 2.0
    assert (fitted < 0.5 * assumed).all()
    assert fitted.mean() < 0.15 * assumed.mean()
    assert np.asarray(m["S_Sen"]["Nikon 5100 (NPL)"]).shape == (3, 3)


def test_error_maps_measure_the_relative_difference(two_light_sample):
    scene, result = two_light_sample
    gt = compute_ground_truth(scene, result, LayerSettings(cameras=()))
    err = gt.layers["error_rgb3"].data  # the fixture's rgb3 image is the reference × 1.02
    lit = result.aovs["mask"]
    np.testing.assert_allclose(err[lit], 0.02, rtol=1e-4)
    assert (err[0] == 0).all()
    # The spectral render traces independent paths: its difference would be noise, not error.
    assert "error_spectral" not in gt.layers and "image_spectral" in gt.layers
    assert gt.reference_mode == "bands31"


def test_camera_illuminant_is_relative_to_the_cameras_d65_white(synth):
    scene = synth.make_scene(("cie:D65",))
    result = synth.make_result(scene, modes=("bands31",))
    gt = compute_ground_truth(scene, result, LayerSettings(cameras=(CAMERA,)))
    lit = gt.layers["mask"].data > 0
    illum = gt.layers[f"illuminant_camera/{CAMERA.removeprefix('camera:')}"].data[lit]
    # D65 light is the camera's own white; 1.3e-4 is the 10 nm band integration of D65's spikes
    np.testing.assert_allclose(illum, 1.0, atol=5e-4)


def test_missing_inputs_raise_clear_errors(synth):
    from spectrinsic.errors import DatasetError

    scene = synth.make_scene(("planck:2800K", "cie:FL11"))
    result = synth.make_result(scene, modes=("spectral",))
    no_split = synth.RenderResult(images=result.images, raw={}, aovs=result.aovs)
    with pytest.raises(DatasetError, match="per_light=True"):
        compute_ground_truth(scene, no_split, LayerSettings(cameras=()))
    with pytest.raises(DatasetError, match="bands31"):
        compute_ground_truth(scene, result, LayerSettings(cameras=(CAMERA,)))
