"""The shading of metals (issue 21): where the diffuse albedo is 0, ``shading`` is the radiance a
white Lambertian surface would reflect there (spectrinsic/render/band_path/kernel.py's second loop), so the layer
stays continuous and finite across a metal.

Independent values: the analytic irradiance of a plane under a distant light, and the same
scene with the metal replaced by a grey Lambertian surface (Mitsuba's ordinary diffuse path)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from spectrinsic.gt_export.layers import compute_ground_truth
from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.scenes.model import Material
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as WL
from spectrinsic.spectra import get_sensors, get_spectrum, responses, xyz_to_linear_srgb

#: Band integration (31 box bands of 10 nm) against 1 nm integration of smooth spectra.
BAND_RTOL = 5e-3
#: Standard errors allowed between two independent Monte Carlo means.
N_SIGMA = 4.0
GOLD = Material("gold", "flat:0", kind="conductor", metal="Au")


def test_a_metal_plane_has_the_analytic_white_surface_shading(make_plane):
    """A gold plane under a distant D65 light 30° off its normal: ``reflectance`` 0 and
    ``shading`` = ∫D65 S cosθ/π relative to white, the shading a Lambertian plane has there
    (was 0: nothing to divide by)."""
    tilt = 30.0
    scene = replace(make_plane("flat:0.5", "cie:D65", tilt_deg=tilt, size=8), materials=(GOLD,))
    gt = compute_ground_truth(
        scene, render_scene(scene, RenderSettings(4, modes=("bands31",), max_depth=2), seed=3)
    )
    d65 = get_spectrum("cie:D65").on(WL)
    white_xyz = responses(d65, get_sensors("cie1931").on(WL), WL)
    expected = white_xyz[1] * np.cos(np.radians(tilt)) / np.pi
    shading = gt.layers["shading"].data.reshape(-1, 3)
    assert np.all(gt.layers["reflectance"].data == 0.0)
    np.testing.assert_allclose(shading, expected, rtol=BAND_RTOL)


def test_a_metal_lit_by_a_bounce_has_the_shading_a_matte_wall_has_there(make_corner):
    """A mirror-like gold wall lit only by light bounced off a red wall: its shading carries
    the bounce's light and equals, within Monte Carlo error, the shading of a grey Lambertian
    wall in its place (paths of depth ≤ 3: the first wall's own reflection never comes back)."""
    settings = RenderSettings(64, modes=("bands31",), max_depth=3)
    shading = {}
    for name, material in (("gold", GOLD), ("grey", Material("grey", "flat:0.8"))):
        scene = make_corner(material)
        gt = compute_ground_truth(scene, render_scene(scene, settings, seed=7))
        inside = gt.layers["mask"].data > 0
        inside[[0, -1], :] = inside[:, [0, -1]] = False
        shading[name] = gt.layers["shading"].data[inside].astype(np.float64)
    gold, grey = shading["gold"], shading["grey"]
    assert len(gold) > 100 and np.all(np.isfinite(gold)) and np.all(gold >= 0)
    rho = get_spectrum("munsell:5R 5/12").on(WL)
    bounce = xyz_to_linear_srgb(
        responses(rho * get_spectrum("cie:D65").on(WL), get_sensors("cie1931").on(WL), WL)
    )
    mean = gold.mean(axis=0)
    assert mean[0] > 2 * mean[2] and bounce[0] > 2 * bounce[2]  # red light, not white
    stderr = np.hypot(gold.std(axis=0), grey.std(axis=0)) / np.sqrt(len(gold))
    assert np.all(np.abs(mean - grey.mean(axis=0)) <= N_SIGMA * stderr), (mean, grey.mean(0))
