"""The cube of a sample stored with its transport, defined as the stored transport's sum and
rebuilt from ``transport.exr`` bit for bit (issue 45).

Independent values: the sum over lights written out here in a plain loop from the float32
means read back from ``transport.exr`` and the lights' band means recomputed from the scene
(not the header's copy); the renderer's own cube (the batches' mean of per-batch sums), which
must agree to float32 rounding; and a direct render of the relit scene.
"""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from spectrinsic.gt_export import check_sample, export_sample, load_sample
from spectrinsic.gt_export.formats.exr import read_exr, read_exr_attributes, write_exr
from spectrinsic.gt_export.layers import LayerSettings
from spectrinsic.gt_export.relight import relight, relit_scene
from spectrinsic.gt_export.sample.meta import read_meta
from spectrinsic.gt_export.sample.transport_cube import CUBE_MODE, MEANS_ATTRIBUTE
from spectrinsic.gt_export.sample.transport_exr import TRANSPORT_NAME, transport_layer
from spectrinsic.render import RenderSettings
from spectrinsic.render.algebra.light_transport import light_band_means
from spectrinsic.render.transport_render import render_transport_batches
from tests.gt_export._builders import renew_seal

pytestmark = pytest.mark.render

SETTINGS = RenderSettings(spp=4, modes=("rgb3", "bands31"), batches=2, max_depth=3)
SEED = 7
NEW_LIGHTS = {0: "cie:LED-RGB1", 1: "planck:3000K"}


def _write(out, scene, transport, result, denoise: bool, name: str):
    settings = LayerSettings(cameras=(), denoise=denoise, spectral_layers=True, write_cube=True)
    return export_sample(
        out,
        scene,
        result,
        settings,
        sample_id=name,
        config={"test": "transport_cube"},
        seed=SEED,
        transport=transport,
    )


@pytest.fixture(scope="module")
def written(tmp_path_factory, make_room):
    """A two-light room stored with its transport, denoised and not, with spectral layers."""
    out = tmp_path_factory.mktemp("cube")
    scene = make_room(size=12)
    transport, result = render_transport_batches(scene, SETTINGS, seed=SEED)
    denoised = _write(out, scene, transport, result, True, "room__v0__denoised")
    raw = _write(out, scene, transport, result, False, "room__v0__raw")
    return out, scene, result, denoised, raw


def _plain_sum(sample, scene) -> np.ndarray:
    """``Σ_l float32(T̄_l · float32(ē_l))``, lights summed in float64 in order, from the file."""
    lights = len(scene.lights)
    stored = read_exr(sample / TRANSPORT_NAME)
    e = light_band_means(scene, "bands:31@400-700").astype(np.float32)
    total = np.zeros(stored[transport_layer(0, None, CUBE_MODE)].shape, np.float64)
    for j in range(lights):
        total += stored[transport_layer(j, None, CUBE_MODE)] * e[j]
    return total.astype(np.float32)


def test_the_cube_is_not_stored_and_is_the_stored_transports_sum_bit_for_bit(written):
    _, scene, result, denoised, raw = written
    for sample, keys in ((denoised, ("image_bands_raw", "cube")), (raw, ("image_bands", "cube"))):
        forms = read_meta(sample).raw["storage"]["layers"]
        assert forms[keys[0]] == "transport_sum"
        assert "cube" not in forms  # alone in cube.exr: stored (its header would need a file)
        names = set(read_exr(sample / "spectral.exr"))
        assert keys[0] not in names and "image_bands" in forms
        header = read_exr_attributes(sample / "spectral.exr")
        assert MEANS_ATTRIBUTE.format(layer=keys[0]) in header
        want = _plain_sum(sample, scene)
        got = load_sample(sample, layers=list(keys))
        for key in keys:
            np.testing.assert_array_equal(got[key], want, err_msg=key)
    # against the renderer's own cube (the batches' mean of each batch's sum): float32 rounding
    own = np.asarray(result.raw[CUBE_MODE], np.float64)
    gap = float(np.abs(want - own).max()) / float(np.abs(own).max())
    assert 0 < gap < 1e-6, gap


def test_check_passes_and_finds_a_tampered_transport(written, tmp_path):
    _, _, _, denoised, _ = written
    assert check_sample(denoised) == []  # the identities hold on the rebuilt cube
    copy = tmp_path / denoised.name
    shutil.copytree(denoised, copy)
    path = copy / TRANSPORT_NAME
    arrays = read_exr(path)
    header = read_exr_attributes(path)
    key = transport_layer(1, None, CUBE_MODE)
    arrays[key] = arrays[key].copy()
    arrays[key][3, 4, 10] *= 1.01  # one band of one pixel of one light, 1 % brighter
    order = json.loads(str(header["spectrinsic.channels"]))
    write_exr(path, arrays, channel_names=order, attributes={"spectrinsic.sample": copy.name})
    assert any(TRANSPORT_NAME in p and "SHA-256" in p for p in check_sample(copy))
    renew_seal(copy)  # the file's hash renewed too: the rebuilt cube's own hash differs
    problems = check_sample(copy)
    assert any("'image_bands_raw'" in p and "SHA-256" in p for p in problems), problems


def test_relight_of_such_a_sample_equals_a_direct_render(written):
    out, scene, _, _, raw = written
    relit = relight(raw, NEW_LIGHTS, out / "relit__v0__raw", keep_transport=True)
    assert check_sample(relit) == []
    new_scene = relit_scene(scene, NEW_LIGHTS)
    transport, result = render_transport_batches(new_scene, SETTINGS, seed=SEED)
    direct = _write(out, new_scene, transport, result, False, "direct__v0__raw")
    a, b = load_sample(relit), load_sample(direct)
    for key in ("image_bands", "cube", "residual_bands", "shading_bands", "image"):
        # a residual is float32 rounding of the image: measured on the image's scale
        scale = float(np.abs(b[key.replace("residual", "image")]).max())
        assert float(np.abs(a[key] - b[key]).max()) <= 1e-5 * scale, key
