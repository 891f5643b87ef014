"""The single band-path traversal (spectrinsic/render/band_path/integrator.py, spectrinsic/render/band_path/traversal.py) against the passes
it replaces, identities of its per-light split, and closed forms.

Tolerances: the traversal multiplies the same float32 factors as Mitsuba's ``path`` in another
order (unit emission times E afterwards, ρ·(cos/π) instead of (ρ/π)·cos), so equal paths agree
to float32 round-off; Monte Carlo checks use bounds in standard errors from the renders.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.errors import RenderError
from spectrinsic.pipeline.presets import get_preset
from spectrinsic.render import (
    channel_values,
    count_passes,
    get_mode,
    merge_batches,
    render_diagonal,
    render_scene,
)
from spectrinsic.render.band_path.traversal import render_traversal
from spectrinsic.render.settings import RenderSettings
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene
from spectrinsic.spectra import get_sensors

#: float32 round-off of equal paths summed in another order, relative to the image's maximum.
ROUNDING_RTOL = 2e-6
#: Standard errors a Monte Carlo mean may sit from its expectation.
N_SIGMA = 4.0
#: Every diagonal mode of the default preset: K = 3 + 6 + 31 = 40 bands in one traversal.
DIAGONAL = ("rgb3", "rgb6", "bands31")


def _close(a: np.ndarray, b: np.ndarray) -> None:
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    scale = max(float(np.abs(b).max()), 1e-30)
    assert float(np.abs(a - b).max()) <= ROUNDING_RTOL * scale, float(np.abs(a - b).max()) / scale


def test_single_traversal_equals_the_passes(make_room):
    """Same seed and spp: every band of every diagonal mode, full and direct-only, equals the
    ⌈K/3⌉ passes (14 of them) to float rounding; the spectral pass is untouched."""
    scene = make_room(size=24)
    base = RenderSettings(
        4, modes=("spectral", *DIAGONAL), per_light=True, share_mode="rgb3", direct=True
    )
    calls: dict[str, list[int]] = {"passes": [], "single": []}
    settings = {name: base.with_options(integrator=name) for name in calls}
    results = {
        name: render_scene(scene, settings[name], seed=5, progress=calls[name].append)
        for name in calls
    }
    old, new = results["passes"], results["single"]
    for mode in DIAGONAL:
        assert new.raw[mode].shape[-1] == get_sensors(get_mode(mode).sensors).n
        _close(new.raw[mode], old.raw[mode])
        _close(new.direct[mode], old.direct[mode])
        _close(new.images[mode], old.images[mode])
    np.testing.assert_array_equal(new.raw["spectral"], old.raw["spectral"])
    # two traversals (full with the first-hit maps, and direct-only) replace 2 x (1 + 2 + 11)
    # diagonal passes, 2 per-light passes and 3 coverage passes; the spectral reference keeps
    # its 2. The progress calls are what count_passes predicts.
    for name, seen in calls.items():
        assert len(seen) == count_passes(scene, settings[name])
    assert (len(calls["passes"]), len(calls["single"])) == (2 + 2 * 14 + 2 + 3, 2 + 2)
    assert new.meta["integrator"] == "single" and new.meta["timings"]["single"]["passes"] == 2
    # the first-hit maps see the same camera rays as the coverage passes
    for key, ref in old.aovs.items():
        np.testing.assert_allclose(new.aovs[key], ref, rtol=0, atol=1e-6, err_msg=key)
    assert not old.transport


def test_render_traversal_matches_render_diagonal(make_room):
    """Lower level: the transport times the lights' channel values is render_diagonal's image."""
    scene = make_room(size=12)
    values = [channel_values(scene, get_sensors(get_mode(m).sensors)) for m in DIAGONAL]
    outs, aovs, seconds, _ = render_traversal(scene, values, spp=8, seed=9)
    passes = render_diagonal(scene, values, spp=8, seed=9)
    assert len(seconds) == 1 and not aovs
    for out, ref, v in zip(outs, passes, values, strict=True):
        assert out.transport.shape == (2, 12, 12, v.materials.shape[1])
        _close(out.image(), ref.image)


def test_per_light_split_sums_to_the_image(make_room):
    """Each light's image is its share of the one render: the shares sum to the image exactly,
    and each share is an unbiased estimate of the light alone (a separate one-light render)."""
    scene = make_room(size=16)
    new = render_scene(
        scene,
        RenderSettings(64, modes=DIAGONAL, per_light=True, aovs=False, integrator="single"),
        seed=11,
    )
    old = render_scene(
        scene,
        RenderSettings(64, modes=("rgb3",), per_light=True, aovs=False, integrator="passes"),
        seed=12,
    )
    for mode in DIAGONAL:
        total = sum(p[mode].astype(np.float64) for p in new.per_light)
        _close(total, new.images[mode])
        values = channel_values(scene, get_sensors(get_mode(mode).sensors))
        relit = np.einsum("lhwk,lk->hwk", new.transport[mode].astype(np.float64), values.lights)
        _close(relit, new.raw[mode])
    for a, b in zip(new.per_light, old.per_light, strict=True):
        diff = (a["rgb3"].astype(np.float64) - b["rgb3"]).reshape(-1, 3)
        stderr = diff.std(axis=0, ddof=1) / np.sqrt(len(diff))
        assert float(a["rgb3"].sum()) > 0
        assert np.all(np.abs(diff.mean(axis=0)) <= N_SIGMA * stderr)


def test_batches_average_the_transport(make_room):
    scene = make_room(size=8)
    parts = [
        render_scene(
            scene, RenderSettings(2, modes=("rgb3",), aovs=False, integrator="single"), seed=s
        )
        for s in (1, 2)
    ]
    merged = merge_batches(parts)
    np.testing.assert_allclose(
        merged.transport["rgb3"],
        (parts[0].transport["rgb3"].astype(np.float64) + parts[1].transport["rgb3"]) / 2,
        rtol=1e-6,
    )


def test_plane_under_directional_lights_is_exact(make_plane):
    """One bounce under a directional light has no noise: every band is ρ_k E_k cosθ/π."""
    tilt = 30.0
    scene = make_plane("munsell:5R 5/12", "planck:2800K", tilt_deg=tilt, size=8)
    result = render_scene(
        scene, RenderSettings(4, modes=DIAGONAL, aovs=False, integrator="single"), seed=1
    )
    for mode in DIAGONAL:
        v = channel_values(scene, get_sensors(get_mode(mode).sensors))
        expected = v.materials[0] * v.lights[0] * np.cos(np.radians(tilt)) / np.pi
        np.testing.assert_allclose(
            result.raw[mode], np.broadcast_to(expected, result.raw[mode].shape), rtol=1e-5
        )


def _parallel_rectangle_factor(a: float, b: float, height: float) -> float:
    """View factor from a differential area to a parallel a x b rectangle centred above it at
    *height* (four corner rectangles, Howell's catalogue B-3)."""
    x, y = a / 2 / height, b / 2 / height
    sx, sy = np.sqrt(1 + x * x), np.sqrt(1 + y * y)
    quadrant = (x / sx * np.arctan(y / sx) + y / sy * np.arctan(x / sy)) / (2 * np.pi)
    return 4 * float(quadrant)


def test_plane_under_an_area_light_is_the_view_factor():
    """Emitter hits and next-event estimation with MIS: a Lambertian floor under a square area
    light of radiance L reflects ρ L F, F the closed-form view factor of the light."""
    vertices = np.array([[-50, -50, 0], [50, -50, 0], [50, 50, 0], [-50, 50, 0]], float)
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    size, height = 0.8, 0.5
    scene = Scene(
        name="floor-under-area-light",
        meshes=(Mesh("floor", vertices, faces, np.zeros(2, np.int64), object_id=0),),
        materials=(Material("floor", "munsell:5G 6/8"),),
        lights=(
            Light(
                "area",
                "cie:D65",
                2.0,
                position=(0, 0, height),
                direction=(0, 0, -1),
                size=(size, size),
            ),
        ),
        # a narrow view of the point under the light's centre, from beside the light
        camera=Camera(
            origin=(0, -0.6, 0.25), target=(0, 0, 0), up=(0, 0, 1), fov_deg=1.0, width=8, height=8
        ),
    )
    result = render_scene(
        scene, RenderSettings(256, modes=("bands31",), aovs=False, integrator="single"), seed=3
    )
    v = channel_values(scene, get_sensors(get_mode("bands31").sensors))
    expected = v.materials[0] * v.lights[0] * _parallel_rectangle_factor(size, size, height)
    pixels = result.raw["bands31"].reshape(-1, 31).astype(np.float64)
    stderr = pixels.std(axis=0, ddof=1) / np.sqrt(len(pixels))
    assert np.all(stderr > 0), "area-light sampling should carry noise"
    assert np.all(np.abs(pixels.mean(axis=0) - expected) <= N_SIGMA * stderr + 1e-3 * expected)


def test_unknown_integrator_is_one_line():
    with pytest.raises(RenderError, match="integrator='one-pass'; expected one of passes, single"):
        RenderSettings(1, modes=("rgb3",), integrator="one-pass")


def test_integrator_is_a_render_setting_not_hashed():
    """The dataset config carries the choice to every sample's render; both integrators give
    the same pixels to float rounding, so the config hash does not change with it."""
    config = get_preset("preview")
    passes = config.with_options(integrator="passes")
    assert (config.render.integrator, passes.render.integrator) == ("single", "passes")
    assert passes.config_hash() == config.config_hash()


def test_the_spectral_pass_renders_its_own_sample_count(make_room):
    """``spectral_spp`` sets the spectral pass alone: its image is that of a spectral-only render
    at that count (same seed, bit for bit), the diagonal modes those of a render at ``spp``."""
    scene = make_room(size=16)
    both = RenderSettings(8, modes=("spectral", "rgb3"), batches=2, spectral_spp=2)
    got = render_scene(scene, both.with_options(spp=4, batches=1, spectral_spp=1), seed=3)
    spectral = render_scene(scene, RenderSettings(1, modes=("spectral",)), seed=3)
    diagonal = render_scene(scene, RenderSettings(4, modes=("rgb3",)), seed=3)
    assert both.batch_spp == 4 and both.spectral_batch_spp == 1
    np.testing.assert_array_equal(got.raw["spectral"], spectral.raw["spectral"])
    np.testing.assert_array_equal(got.raw["rgb3"], diagonal.raw["rgb3"])
    assert not np.array_equal(
        got.raw["spectral"],
        render_scene(scene, RenderSettings(4, modes=("spectral",)), seed=3).raw["spectral"],
    )
    assert got.meta["spectral_spp"] == 1 and got.meta["spp"] == 4
