"""A sample through the camera chain: raw mosaic and DNG (read back by rawpy), the processed
image, and the ground truth in the processed linear space (its identity checked by
``spectrinsic check``'s own code)."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest
from PIL import Image

from spectrinsic.gt_export import export_sample, load_sample
from spectrinsic.gt_export.dataset.check import check_sample
from spectrinsic.gt_export.formats.exr import read_exr
from spectrinsic.gt_export.sample.sensor import model_from_meta
from spectrinsic.spectra.camera_model import camera_model

KEY = "Nikon 5100 (NPL)"
SLUG = "nikon-5100-npl"


def _export(tmp_path, sample, config, *, sample_id="s", seed=1, **changes):
    scene, result = sample
    model = camera_model("nikon-5100-npl").with_options(black_level_dn=600, **changes)
    return export_sample(
        tmp_path, scene, result, sample_id=sample_id, config=config, seed=seed, camera=model
    )


@pytest.fixture
def big_sample(synth, monkeypatch):
    """The synthetic one-light sample at 32 x 48: LibRaw reads no image under 22 pixels."""
    module = sys.modules[synth.make_scene.__module__]
    monkeypatch.setattr(module, "H", 32)
    monkeypatch.setattr(module, "W", 48)
    scene = synth.make_scene(("planck:2800K",))
    return scene, synth.make_result(scene)


def _layers(folder):
    return read_exr(folder / f"sensor-{SLUG}.exr")


def test_sensor_sample_is_complete_and_its_identity_holds(tmp_path, two_light_sample, config):
    folder = _export(tmp_path, two_light_sample, config)
    assert check_sample(folder) == []  # hashes, units, and every identity, the sensor's too
    meta = json.loads((folder / "meta.json").read_text())
    assert {
        "image": f"image_sensor/{KEY}",
        "reflectance": f"reflectance_sensor/{KEY}",
        "shading": f"shading_sensor/{KEY}",
        "residual": f"residual_sensor/{KEY}",
    } in meta["identities"]
    stages = meta["sensor"]["stages"]
    assert stages["tone_curve"]["applied_to_ground_truth"] is False
    assert model_from_meta(meta) == camera_model("nikon-5100-npl").with_options(black_level_dn=600)
    assert (folder / f"sensor-{SLUG}.png").is_file()
    loaded = load_sample(folder)  # the loader returns the raw and processed images too
    assert loaded[f"raw_sensor/{KEY}"].shape == loaded["image"].shape[:2]
    assert loaded[f"processed_sensor/{KEY}"].max() <= 255
    png = np.asarray(Image.open(folder / f"sensor-{SLUG}.png"))
    np.testing.assert_array_equal(png, loaded[f"processed_sensor/{KEY}"])


def test_dng_read_back_by_rawpy_equals_the_raw_mosaic(tmp_path, big_sample, config):
    import rawpy  # a dev dependency, as pytest is

    folder = _export(tmp_path, big_sample, config)
    raw = _layers(folder)["raw_sensor"]
    with rawpy.imread(str(folder / f"sensor-{SLUG}.dng")) as dng:
        np.testing.assert_array_equal(
            dng.raw_image_visible, raw.reshape(dng.raw_image_visible.shape)
        )
        assert dng.raw_pattern.tolist() == [[0, 1], [3, 2]]  # RGGB (rawpy numbers G2 as 3)
        assert dng.black_level_per_channel == [600] * 4
    assert raw.min() >= 0 and np.all(raw == np.rint(raw))


def test_same_sample_same_noise_other_sample_other_noise(tmp_path, one_light_sample, config):
    a = _layers(_export(tmp_path / "a", one_light_sample, config))["raw_sensor"]
    b = _layers(_export(tmp_path / "b", one_light_sample, config))["raw_sensor"]
    c = _layers(_export(tmp_path / "c", one_light_sample, config, sample_id="t"))["raw_sensor"]
    assert a.tobytes() == b.tobytes()
    assert not np.array_equal(a, c)


def test_raw_scatters_around_the_exposed_camera_image_with_the_stored_variance(
    tmp_path, big_sample, config
):
    """Closed form at the sample level: E[raw] = black + mosaic(camera image) x exposure / gain,
    E[(raw - E raw)^2] = the stored variance (no fixed pattern in the preset)."""
    from spectrinsic.spectra.camera_isp import mosaic

    folder = _export(tmp_path, big_sample, config)
    meta = json.loads((folder / "meta.json").read_text())
    scale = meta["sensor"]["stages"]["exposure"]["electrons_per_unit"]
    gain = meta["sensor"]["model"]["gain_e_per_dn"]
    camera = read_exr(folder / f"camera-{SLUG}.exr")["image_camera"]
    expected = 600 + mosaic(camera, "RGGB") * scale / gain
    layers = _layers(folder)
    raw, var = layers["raw_sensor"].astype(np.float64), layers["raw_variance_sensor"]
    # lit, and below the full well: metered on the median, highlights saturate (issue 47)
    full = meta["sensor"]["model"]["full_well_e"] / gain
    lit = (expected > 600 + 100) & (expected < 600 + 0.8 * full)
    n = int(lit.sum())
    assert n > 100
    z = (raw - expected)[lit] / np.sqrt(var[lit])
    # 4 standard errors: the mean of n unit normals is known to 1/sqrt(n), their variance to
    # sqrt(2/n)
    assert abs(z.mean()) < 4 / np.sqrt(n)
    assert z.var() == pytest.approx(1.0, abs=4 * np.sqrt(2 / n))


def test_evaluate_scores_the_processed_image_against_the_carried_ground_truth(
    tmp_path, one_light_sample, config
):
    """An oracle returning the carried ground truth scores zero on the processed image's
    scenario; the same estimates scored against the sRGB truth do not."""
    from spectrinsic.decompose.decomposition import Decomposition
    from spectrinsic.decompose.evaluation.evaluate import evaluate_sample

    sample = load_sample(_export(tmp_path, one_light_sample, config))
    refl, shading = sample[f"reflectance_sensor/{KEY}"], sample[f"shading_sensor/{KEY}"]

    def oracle(image, mask):
        return Decomposition(refl * mask[..., None], shading)

    scores = evaluate_sample(sample, {"oracle": oracle}, seed=0, n_judgements=50, figure=False)
    by = {(s.scenario, s.layer, s.metric): s.value for s in scores}
    scenario = f"sensor_{SLUG}"
    assert by[(scenario, "reflectance", "si_mse")] == pytest.approx(0.0, abs=1e-10)
    assert by[(scenario, "shading", "si_mse")] == pytest.approx(0.0, abs=1e-10)
    assert by[("srgb", "reflectance", "si_mse")] > 1e-6
