"""Spectral intrinsic layers (issue 30, Done-when), with real renders kept tiny.

Independent values: the Munsell chip integrated over each 10 nm band by colour-science, the
closed-form irradiance of a plane lit by one bounce off a perpendicular half-plane (form factor
1/2), a recomputation of the residual share from the stored files, and a direct render of a
relit scene.
"""

from __future__ import annotations

import dataclasses
import json

import colour
import numpy as np
import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import check_sample, export_sample, load_sample
from spectrinsic.gt_export.dataset.loader import filter_residual_share, working_space_view
from spectrinsic.gt_export.layers import LayerSettings, compute_ground_truth, identities
from spectrinsic.gt_export.relight import relight, relit_scene
from spectrinsic.render import RenderSettings, render_batches, render_scene
from spectrinsic.scenes.model import Material
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as WL
from spectrinsic.spectra import get_sensors, get_spectrum, responses
from tests.conftest import corner_scene
from tests.gt_export._builders import render_transport_sample

#: Issue 30: the per-band identity and the band reflectance, within 1e-5.
TOL = 1e-5
#: Band centres of ``bands:31@400-700``.
CENTRES = np.arange(400.0, 701.0, 10.0)
CHIP = "munsell:5G 6/8"
SPECTRAL = ("image_bands", "reflectance_bands", "shading_bands", "residual_bands")


def _band_means_by_colour(name: str) -> np.ndarray:
    """``(31,)`` mean of a measured spectrum over each 10 nm band, by colour-science: the
    distribution trimmed to ``[c − 5, c + 5]`` nm and integrated by the trapezoid rule."""
    spectrum = get_spectrum(name)
    sd = colour.SpectralDistribution(dict(zip(spectrum.wavelengths, spectrum.values, strict=True)))
    out = []
    for c in CENTRES:
        band = sd.copy().trim(colour.SpectralShape(c - 5, c + 5, 1))
        v = np.asarray(band.values, float)
        out.append((v.sum() - 0.5 * (v[0] + v[-1])) / (len(v) - 1))  # trapezoid rule, 1 nm
    return np.array(out)


def test_a_plane_under_a_narrow_led_has_the_exact_band_identity_and_reflectance(make_plane):
    scene = make_plane(CHIP, "led:540/31", size=8)
    settings = RenderSettings(spp=4, max_depth=2, modes=("spectral", "bands31"))
    gt = compute_ground_truth(
        scene, render_scene(scene, settings, seed=1), LayerSettings(spectral_layers=True)
    )
    # Mitsuba's spectral image keeps its own name beside the band layers
    assert (
        gt.layers["image_spectral"].group == "image"
        and gt.layers["image_bands"].group == "spectral"
    )
    image, refl, shading, res = (gt.layers[k].data.astype(np.float64) for k in SPECTRAL)
    assert image.shape == (8, 8, 31) and gt.layers["image_bands"].data.dtype == np.float32
    scale = np.abs(image).max()
    # the identity holds per band, with a residual of float32 rounding: the product explains it
    assert np.abs(refl * shading + res - image).max() <= TOL * scale
    assert np.abs(res).max() <= TOL * scale
    expected = _band_means_by_colour(CHIP)
    np.testing.assert_allclose(refl.reshape(-1, 31), np.broadcast_to(expected, (64, 31)), atol=TOL)
    # the RGB layers of the same pixels do not multiply out under this light
    assert gt.residual_share["image"] > 0.05 > 1e-4 > gt.residual_share["image_bands"]
    spectral = [i for i in identities(gt) if i["image"] == "image_bands"]
    assert spectral == [dict(zip(("image", "reflectance", "shading", "residual"), SPECTRAL))]


def test_b_band_shading_of_one_bounce_between_coloured_planes_is_the_closed_form():
    """Seen from a point of the first plane, the half-plane covers every direction with
    d_x > 0 and d_y > 0: half the cosine-weighted hemisphere, form factor F = 1/2 (the finite
    plane misses < 1e-3 of it). With depth 3 the first plane receives only that bounce:
    ``E_k = ρ_second,k · P ∫ L B_k dλ · F`` per band and ``W_k = E_k / π``."""
    light, power = "cie:FL11", 3.0
    # the corner's coloured wall far larger (|z| ≤ 2000): the form factor is 1/2 to < 1e-3
    first = Material("first", "munsell:5PB 4/10")
    scene = corner_scene(first, "munsell:5R 5/12", light=light, power=power, wall_half=2000)
    settings = RenderSettings(spp=64, max_depth=3, modes=("bands31",))
    gt = compute_ground_truth(
        scene, render_scene(scene, settings, seed=7), LayerSettings(spectral_layers=True)
    )
    inside = gt.layers["mask"].data > 0
    inside[[0, -1], :] = inside[:, [0, -1]] = False
    assert inside.sum() > 150
    bands = get_sensors("bands:31@400-700").on(WL)
    e_light = responses(power * get_spectrum(light).on(WL), bands, WL)
    rho = _band_means_by_colour("munsell:5R 5/12")
    expected = rho * e_light * 0.5 / np.pi
    shading = gt.layers["shading_bands"].data[inside].astype(np.float64)
    ratio = shading / expected
    # every band traces the same paths: per pixel, one geometric factor for all 31 bands
    spread = np.abs(ratio / ratio.mean(axis=-1, keepdims=True) - 1).max()
    assert spread < TOL, spread
    # and that factor is the closed form's, within the Monte Carlo error of the mean
    # (Bernoulli p = 1/2 per cosine-weighted sample: ~1 % at 64 spp over 200 pixels)
    assert ratio.mean() == pytest.approx(1.0, abs=0.04)
    # the plane's own colour does not enter its shading; its image is ρ_first,k · W_k
    np.testing.assert_allclose(
        gt.layers["reflectance_bands"].data[inside],
        np.broadcast_to(_band_means_by_colour("munsell:5PB 4/10"), shading.shape),
        atol=TOL,
    )


@pytest.fixture(scope="module")
def room_sample(tmp_path_factory, make_room):
    """A two-light room with its transport, denoised, with spectral layers."""
    out = tmp_path_factory.mktemp("spectral")
    scene = make_room(size=12)
    settings = RenderSettings(spp=4, modes=("rgb3", "bands31"), batches=2, max_depth=4)
    sample, _, _ = render_transport_sample(
        out, scene, settings, seed=5, sample_id="room__v0__two", config={"test": "spectral"},
        layers=LayerSettings(denoise=True, spectral_layers=True),
    )  # fmt: skip
    return out, scene, sample, settings


def test_c_residual_share_in_meta_equals_a_recomputation_from_the_stored_layers(room_sample):
    _, _, sample, _ = room_sample
    assert check_sample(sample) == []  # every identity, the per-band one included, holds
    loaded = load_sample(sample)
    meta = json.loads((sample / "meta.json").read_text())
    assert "spectral.exr" in meta["files"]
    shares = meta["residual_share"]
    assert set(shares) >= {"image_denoised", "image", "image_bands"}
    mask = loaded["mask"]
    for ident in meta["identities"]:
        image = loaded[ident["image"]][mask].astype(np.float64)
        residual = loaded[ident["residual"]][mask].astype(np.float64)
        recomputed = np.abs(residual).sum() / np.abs(image).sum()
        assert shares[ident["image"]] == pytest.approx(recomputed, rel=1e-9)
    assert shares["image_bands"] < 1e-3 < shares["image_denoised"]
    # the RGB view from the band layers reproduces the stored layers (default working space
    # ACEScg, shading unclipped) and their residual share (the reflectance integrated from the
    # bands rather than at 1 nm), and holds in other spaces
    assert meta["working_space"]["name"] == "acescg"
    aces = working_space_view(loaded, "acescg")
    np.testing.assert_allclose(aces["image"], loaded["image_denoised"], rtol=1e-4, atol=1e-6)
    view_share = np.abs(aces["residual"][mask]).sum() / np.abs(aces["image"][mask]).sum()
    assert view_share == pytest.approx(shares["image_denoised"], rel=0.1)
    rebuilt = aces["reflectance"] * aces["shading"] + aces["residual"]
    np.testing.assert_allclose(rebuilt, aces["image"], atol=1e-9 * np.abs(aces["image"]).max())
    # the loader's sRGB view of the stored layers is the band layers' sRGB view
    srgb = working_space_view(loaded, "srgb")
    view = load_sample(sample, space="srgb")
    scale = np.abs(srgb["image"]).max()
    np.testing.assert_allclose(view["image_denoised"], srgb["image"], rtol=1e-4, atol=1e-6 * scale)
    # the loader's filter reads the same figure
    rgb = shares["image_denoised"]
    assert filter_residual_share([sample], rgb) == [sample]
    assert filter_residual_share([sample], rgb * 0.99) == []
    with pytest.raises(DatasetError, match="max_residual_share"):
        filter_residual_share([sample], -1.0)


def test_d_relit_spectral_layers_equal_a_direct_render(room_sample):
    out, scene, sample, settings = room_sample
    lights = {0: "led:540/31", 1: "planck:3000K"}
    relit = load_sample(relight(sample, lights, out / "relit__v0__two"))
    new_scene = relit_scene(scene, lights)
    direct = render_batches(new_scene, settings.with_options(per_light=True), seed=5)
    reference = load_sample(
        export_sample(
            out,
            new_scene,
            direct,
            LayerSettings(denoise=True, spectral_layers=True),
            sample_id="direct__v0__two",
            config={"test": "spectral"},
            seed=5,
        )
    )
    before = load_sample(sample, layers=["image_bands"])["image_bands"]
    for name in [*SPECTRAL, "image_bands_raw"]:
        a, b = relit[name].astype(np.float64), reference[name].astype(np.float64)
        assert a.shape == b.shape == before.shape
        # the residual is float32 rounding of the image here: measured on the image's scale
        scale = reference["image_bands" if name == "residual_bands" else name]
        assert np.abs(a - b).max() <= TOL * np.abs(scale).max(), name
    assert np.abs(relit["image_bands"] - before).max() > 0.05 * np.abs(before).max()


def test_spectral_layers_without_the_cube_are_refused(make_plane):
    scene = make_plane(CHIP, "cie:D65", size=4)
    result = render_scene(scene, RenderSettings(spp=1, max_depth=2, modes=("rgb3",)), seed=1)
    with pytest.raises(DatasetError, match="31-band cube"):
        compute_ground_truth(scene, result, LayerSettings(spectral_layers=True))


def test_glossy_band_layers_take_the_specular_term(make_room):
    """A silver wall and a coated floor: ``specular_bands`` is a term of the per-band identity,
    so the residual stays float rounding on glossy and metal surfaces."""
    scene = make_room(size=12)
    mats = list(scene.materials)
    mats[3] = Material("mirror", "flat:0", kind="conductor", metal="Ag")
    mats[4] = Material("floor", "munsell:5Y 8/2", kind="plastic", ior=1.5)
    scene = dataclasses.replace(scene, materials=tuple(mats))
    settings = RenderSettings(4, modes=("bands31", "rgb3"), per_light=True, share_mode="rgb3")
    gt = compute_ground_truth(
        scene, render_scene(scene, settings, seed=5), LayerSettings(spectral_layers=True)
    )
    spec = gt.layers["specular_bands"].data
    assert np.abs(spec).max() > 0
    ident = [i for i in identities(gt) if i["image"] == "image_bands"][0]
    assert ident["specular"] == "specular_bands"
    image, refl, shading, res = (gt.layers[k].data.astype(np.float64) for k in SPECTRAL)
    assert np.abs(refl * shading + spec + res - image).max() <= TOL * np.abs(image).max()
    # zero on pixels of one kind of surface; the rest sits where a metal and a diffuse surface
    # share a pixel (their white-surface radiances are averaged there)
    metallic = gt.layers["metallic"].data
    pure = (metallic == 0) | (metallic == 1)
    assert np.abs(res[pure]).max() <= TOL * np.abs(image).max()
    assert np.abs(res[~pure]).max() > TOL * np.abs(image).max()
