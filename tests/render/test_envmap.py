"""Environment maps (issue 42): one RGB radiance map as three channel lights.

Maps are written as tiny EXR files with Mitsuba's own ``Bitmap`` writer. The rotation turns
the map's +y (Mitsuba's envmap "up") to the scene's +z, so the map's upper half is the sky
above the test plane (``tests/conftest.py``'s ``plane_scene``: z up, seen from above).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spectrinsic.errors import RenderError, SceneError
from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.render.algebra.light_transport import relit_result
from spectrinsic.render.transport_render import render_transport_batches
from spectrinsic.scenes.envmaps import envmap_groups, envmap_lights
from spectrinsic.scenes.model import Light
from spectrinsic.scenes.validate import validate_scene

from ._maps import UP_IS_Z, write_map

N_SIGMA = 4.0


def lit_by_map(plane, path: str, sha: str, scale: float = 1.0):
    scene = dataclasses.replace(plane, lights=envmap_lights("sky", path, sha, scale, UP_IS_Z))
    return validate_scene(scene)


def pixels(result, mode: str) -> tuple[np.ndarray, np.ndarray]:
    px = result.images[mode].reshape(-1, 3).astype(np.float64)
    return px.mean(0), px.std(0, ddof=1) / np.sqrt(len(px))


def test_a_uniform_map_equals_a_d65_sky_of_the_same_radiance(tmp_path, make_plane):
    """A map of v·(1, 1, 1) radiates Σ_c v b_c D65 = v D65 (the basis sums to one within
    1e-5): the same light as a ``sky`` of D65 and power v. Both the band path (rgb3) and the
    per-channel spectral passes must agree with the sky's renders within the Monte Carlo error
    (the samplers differ: the envmap's by luminance over the map, the sky's over the sphere).
    Measured at 64 spp, 16²: rgb3 agrees to 2e-6 relative, spectral to 0.3 stderr."""
    v = 0.7
    plane = make_plane("munsell:5B 5/8", "cie:D65", size=16)
    env = lit_by_map(plane, *write_map(tmp_path / "grey.exr", np.full((16, 32, 3), v)))
    sky = dataclasses.replace(plane, lights=(Light("sky", "cie:D65", v),))
    settings = RenderSettings(64, modes=("spectral", "rgb3"), aovs=False)
    got, want = (render_scene(s, settings, seed=3) for s in (env, sky))
    for mode in ("spectral", "rgb3"):
        (m1, e1), (m2, e2) = pixels(got, mode), pixels(want, mode)
        assert np.all(np.abs(m1 - m2) <= N_SIGMA * np.hypot(e1, e2) + 1e-5 * m2), mode


def test_a_two_colour_map_lights_a_white_plane_with_its_upper_half(tmp_path, make_plane):
    """Red (0.8, 0, 0) above the horizon, blue (0, 0, 0.5) below, over a white Lambertian
    plane: the plane sees only the upper hemisphere, of uniform radiance, so each channel
    light's transport (its shading for unit emission) is that hemisphere's map value: 0.8 for
    the red light, 0 for the green, 0 for the blue, within the Monte Carlo error and the
    bilinear blend of the map's two rows at the horizon: it reaches directions within half a
    row (π/2H) of the horizon, which carry sin²(π/2H) of a cosine-weighted hemisphere."""
    h = 32
    image = np.zeros((h, 2 * h, 3))
    image[: h // 2] = (0.8, 0.0, 0.0)
    image[h // 2 :] = (0.0, 0.0, 0.5)
    plane = make_plane("flat:1", "cie:D65", size=16)
    scene = lit_by_map(plane, *write_map(tmp_path / "two.exr", image))
    result = render_scene(scene, RenderSettings(64, modes=("rgb3",), aovs=False), seed=5)
    transport = result.transport["rgb3"].reshape(3, -1, 3).astype(np.float64)  # (L, px, K)
    horizon = np.sin(np.pi / (2 * h)) ** 2
    mean, err = transport.mean(1), transport.std(1, ddof=1) / np.sqrt(transport.shape[1])
    assert np.all(np.abs(mean[0] - 0.8) <= N_SIGMA * err[0] + horizon * 0.8)
    assert np.all(transport[1] == 0.0)
    assert np.all(mean[2] <= horizon * 0.5) and np.all(mean[2] > 0.0)  # the blend exists


def test_scaling_a_map_by_relighting_equals_rendering_it_scaled(tmp_path, make_plane):
    """The map's scale is its three channel lights' power: relighting the stored transport
    with every channel light's power doubled must equal a direct render of the map at scale 2
    (same seed and spp, same paths) within 1e-5."""
    rng = np.random.default_rng(2)
    image = rng.uniform(0.1, 2.0, (8, 16, 3))
    plane = make_plane("munsell:5R 5/10", "cie:D65", size=12)
    path, sha = write_map(tmp_path / "noise.exr", image)
    settings = RenderSettings(8, modes=("rgb3", "rgb6"), aovs=False)
    transport, _ = render_transport_batches(lit_by_map(plane, path, sha), settings, seed=9)
    scaled = lit_by_map(plane, path, sha, scale=2.0)
    relit = relit_result(transport, scaled)
    direct = render_scene(scaled, settings, seed=9)
    for mode in ("rgb3", "rgb6"):
        want = direct.images[mode].astype(np.float64)
        got = relit.images[mode].astype(np.float64)
        assert np.abs(got - want).max() <= 1e-5 * np.abs(want).max(), mode


def test_the_three_channel_lights_are_one_map(tmp_path, make_plane):
    path, sha = write_map(tmp_path / "m.exr", np.ones((4, 8, 3)))
    scene = lit_by_map(make_plane("flat:0.5", "cie:D65"), path, sha, scale=3.0)
    (env,) = envmap_groups(scene)
    assert env.lights == (0, 1, 2) and env.file == path
    assert [li.name for li in scene.lights] == ["sky.r", "sky.g", "sky.b"]
    assert sum(li.power for li in scene.lights) == pytest.approx(3.0, rel=1e-12)


def test_the_passes_route_refuses_a_map_before_rendering(tmp_path, make_plane):
    path, sha = write_map(tmp_path / "m.exr", np.ones((4, 8, 3)))
    scene = lit_by_map(make_plane("flat:0.5", "cie:D65"), path, sha)
    settings = RenderSettings(4, modes=("rgb3",), aovs=False, integrator="passes")
    with pytest.raises(RenderError, match="environment map"):
        render_scene(scene, settings, seed=1)


def test_a_second_map_is_evaluated_by_the_band_path_itself(tmp_path, make_plane):
    """Mitsuba loads one environment emitter: the first map is loaded and sampled, the second
    is evaluated by the kernel at the same directions over the first map's pdf. Under a
    white plane the second map's channel lights (a uniform (0.2, 0.5, 0.9) above the
    horizon) must each carry their own map value, within the Monte Carlo error, though the
    first map (a bright red upper half, 0 elsewhere) is what the directions are drawn by."""
    h = 16
    first = np.zeros((h, 2 * h, 3))
    first[: h // 2] = (3.0, 0.0, 0.0)
    plane = make_plane("flat:1", "cie:D65", size=12)
    a = envmap_lights("a", *write_map(tmp_path / "a.exr", first), 1.0, UP_IS_Z)
    b = envmap_lights(
        "b", *write_map(tmp_path / "b.exr", np.ones((h, 2 * h, 3)) * (0.2, 0.5, 0.9)), 1.0, UP_IS_Z
    )
    scene = validate_scene(dataclasses.replace(plane, lights=a + b))
    assert len(envmap_groups(scene)) == 2
    result = render_scene(scene, RenderSettings(64, modes=("rgb3",), aovs=False), seed=4)
    transport = result.transport["rgb3"].reshape(6, -1, 3).astype(np.float64)
    mean, err = transport.mean(1), transport.std(1, ddof=1) / np.sqrt(transport.shape[1])
    for light, value in zip((3, 4, 5), (0.2, 0.5, 0.9), strict=True):
        assert np.all(np.abs(mean[light] - value) <= N_SIGMA * err[light] + 1e-4), light


def test_relighting_swaps_one_map_for_another(tmp_path, make_plane):
    """Issue 42's swap: a scene declares maps A and B (their radiances add); relighting its
    stored transport with A's three lights turned down to 1e-20 (the least power a light
    has) and B's kept must equal a direct render of that scene, B alone to 1e-20, within
    1e-5 (same seed and spp: the same paths, sampled by A)."""
    rng = np.random.default_rng(3)
    plane = make_plane("munsell:5G 6/6", "cie:D65", size=12)
    maps = [write_map(tmp_path / f"{n}.exr", rng.uniform(0.0, 2.0, (8, 16, 3))) for n in "ab"]
    a, b = (envmap_lights(n, p, s, 1.0, UP_IS_Z) for n, (p, s) in zip("ab", maps, strict=True))
    both = validate_scene(dataclasses.replace(plane, lights=a + b))
    settings = RenderSettings(8, modes=("rgb3",), aovs=False)
    transport, _ = render_transport_batches(both, settings, seed=6)
    swapped = dataclasses.replace(
        both, lights=tuple(dataclasses.replace(li, power=1e-20) for li in a) + b
    )
    relit = relit_result(transport, swapped).images["rgb3"].astype(np.float64)
    direct = render_scene(swapped, settings, seed=6).images["rgb3"].astype(np.float64)
    assert np.abs(relit - direct).max() <= 1e-5 * np.abs(direct).max()
    only_a = render_scene(both, settings, seed=6).images["rgb3"].astype(np.float64)
    assert np.abs(only_a - direct).max() > 0.1 * np.abs(direct).max()  # the swap changed it


def test_a_map_changed_since_the_scene_was_read_is_refused(tmp_path, make_plane):
    path, sha = write_map(tmp_path / "m.exr", np.ones((4, 8, 3)))
    scene = lit_by_map(make_plane("flat:0.5", "cie:D65"), path, sha)
    write_map(tmp_path / "m.exr", np.full((4, 8, 3), 2.0))
    with pytest.raises(SceneError, match="changed since the scene was read"):
        render_scene(scene, RenderSettings(4, modes=("rgb3",), aovs=False), seed=1)
