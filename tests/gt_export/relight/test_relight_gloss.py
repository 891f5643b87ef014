"""Exact relighting of a glossy sample (issues 20 and 21): the stored transport keeps the
specular part and the white-surface radiance at metals light by light, so every layer of a
glossy sample, ``specular`` and the metals' shading included, follows for new spectra.

The independent reference is Mitsuba itself: the relit scene rendered light by light with the
new spectra (same seed, spp and depth), its ground truth computed by the usual path.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from spectrinsic.gt_export import check_sample, export_sample, load_sample
from spectrinsic.gt_export.layers import LayerSettings
from spectrinsic.gt_export.relight import relight, relit_scene
from spectrinsic.render import RenderSettings, render_batches
from spectrinsic.render.result import METAL_WHITE, SPECULAR
from spectrinsic.scenes.model import Material
from tests.gt_export._builders import render_transport_sample

#: A relit layer and the direct render's agree to float rounding (as tests/gt_export/relight/test_relight.py).
RELIGHT_RTOL = 1e-5
#: The noise layers come from float16 batch deviations (as tests/gt_export/relight/test_relight.py).
NOISE_RTOL = 1e-3
NEW_LIGHTS = {0: "cie:LED-RGB1", 1: "planck:3000K"}
SEED = 13
SETTINGS = RenderSettings(spp=4, modes=("rgb3", "bands31"), batches=2, max_depth=4)
CONFIG = {"test": "relight-gloss"}


def _disagreeing(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> dict[str, float]:
    """The layers of *a* farther from *b*'s (relative to its largest magnitude) than their
    tolerance (:data:`NOISE_RTOL` for the noise estimates, else :data:`RELIGHT_RTOL`)."""
    errors = {
        k: float(np.abs(a[k].astype(np.float64) - b[k]).max())
        / max(float(np.abs(b[k]).max()), 1e-30)
        for k in a
    }
    tolerance = {k: NOISE_RTOL if k.startswith("noise_") else RELIGHT_RTOL for k in a}
    return {k: e for k, e in errors.items() if e > tolerance[k]}


@pytest.fixture(scope="module")
def glossy(tmp_path_factory, make_room):
    """A two-light room with a gold wall, a coated floor and a rough coated cube, stored with
    its transport."""
    scene = make_room(size=12)
    mats = list(scene.materials)
    mats[3] = Material("gold", "flat:0", kind="conductor", metal="Au", roughness=0.1)
    mats[4] = Material("floor", "munsell:5Y 8/2", kind="plastic", ior=1.5)
    mats[6] = Material("cube", "munsell:5P 5/10", kind="plastic", ior=1.5, roughness=0.15)
    scene = replace(scene, materials=tuple(mats))
    out = tmp_path_factory.mktemp("relight-gloss")
    layers = LayerSettings(denoise=True)
    sample, transport, _ = render_transport_sample(
        out, scene, SETTINGS, seed=SEED, sample_id="gloss__v0__two", config=CONFIG, layers=layers
    )
    return out, scene, sample, transport


def _arrays(sample: dict) -> dict[str, np.ndarray]:
    return {k: v for k, v in sample.items() if isinstance(v, np.ndarray)}


def test_the_glossy_transport_holds_the_specular_and_metal_parts_per_light(glossy):
    _, scene, _, transport = glossy
    specular, metal_white = transport.parts[SPECULAR], transport.parts[METAL_WHITE]
    assert len(specular) == len(metal_white) == 2
    for part in (specular, metal_white):
        assert part[0]["bands31"].shape == transport.batches[0]["bands31"].shape
        assert part[0]["bands31"].max() > 0
    # the specular part is a part of the transport; the white-at-metal radiance is not
    s, t = specular[0]["bands31"], transport.batches[0]["bands31"]
    assert np.all(s <= t * (1 + 1e-5) + 1e-7)


def test_relit_glossy_sample_equals_a_direct_render_with_the_new_spectra(glossy):
    out, scene, sample, _ = glossy
    relit = relight(sample, NEW_LIGHTS, out / "relit__v0__two")
    assert check_sample(relit) == []
    new_scene = relit_scene(scene, NEW_LIGHTS)
    direct = render_batches(new_scene, SETTINGS.with_options(per_light=True), seed=SEED)
    reference = export_sample(
        out,
        new_scene,
        direct,
        LayerSettings(denoise=True),
        sample_id="direct__v0__two",
        config=CONFIG,
        seed=SEED,
    )
    a, b = _arrays(load_sample(relit)), _arrays(load_sample(reference))
    assert set(a) == set(b) and {"specular", "metallic", "shading", "image_denoised"} <= set(a)
    assert _disagreeing(a, b) == {}
    metal = a["metallic"] == 1
    assert metal.any() and np.all(a["shading"][metal].mean(axis=-1) > 0)
    before = load_sample(sample, layers=["specular"])["specular"]
    assert float(np.abs(a["specular"] - before).max()) > 0.05 * float(np.abs(before).max())


def test_relighting_a_glossy_sample_with_its_own_spectra_gives_it_back(glossy):
    out, scene, sample, _ = glossy
    same = relight(
        sample, {i: li.spectrum for i, li in enumerate(scene.lights)}, out / "same__v0__two"
    )
    original, again = _arrays(load_sample(sample)), _arrays(load_sample(same))
    assert set(original) == set(again)
    # not bit for bit: the transport holds the batches' float32 mean and float16 deviations
    assert _disagreeing(again, original) == {}
