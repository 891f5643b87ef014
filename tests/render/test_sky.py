"""A sky light (issue 32): a uniform dome of daylight, Mitsuba's ``constant`` emitter."""

from __future__ import annotations

import dataclasses

import numpy as np

from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.scenes.model import Light, light_power
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as WL
from spectrinsic.spectra import get_sensors, get_spectrum, responses

N_SIGMA = 4.0
GRID_BIAS = 5e-4  # Mitsuba integrates the spectra continuously, we sum them at 1 nm


def test_a_sky_lit_plane_receives_pi_times_the_sky_radiance(make_plane):
    """Closed form: an unoccluded Lambertian plane under a uniform sky of radiance L receives
    E = π L, so it shows radiance ρ E / π = ρ L: pixels ∫ ρ L S dλ (CIE 1931 S)."""
    reflectance, sky, radiance = "munsell:5B 5/8", "daylight:6500K", 0.7
    plane = make_plane(reflectance, "cie:D65", size=8)
    scene = dataclasses.replace(plane, lights=(Light("sky", sky, radiance),))
    result = render_scene(scene, RenderSettings(64, modes=("spectral",), aovs=False), seed=3)
    pixels = result.images["spectral"].reshape(-1, 3).astype(np.float64)
    rho, e = get_spectrum(reflectance).on(WL), get_spectrum(sky).on(WL)
    expected = radiance * responses(rho * e, get_sensors("cie1931").on(WL), WL)
    stderr = pixels.std(axis=0, ddof=1) / np.sqrt(len(pixels))
    assert np.all(np.abs(pixels.mean(0) - expected) <= N_SIGMA * stderr + GRID_BIAS * expected)
    assert light_power("sky", np.zeros(3), np.zeros(3), np.zeros(3), (1, 1), np.pi) == 1.0
