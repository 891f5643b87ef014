"""A relit sample's camera noise is seeded from its source sample, not from the ``--out``
folder's name: its raw mosaic then carries the noise a direct render of the source under the
new lights carries (it differed, as the folder name entered the seed)."""

from __future__ import annotations

import numpy as np

from spectrinsic.gt_export import export_sample
from spectrinsic.gt_export.formats.exr import read_exr
from spectrinsic.spectra.camera_model import camera_model

RAW = "raw_sensor/nikon-5100-npl"


def _raw(tmp_path, one_light_sample, config, sample_id, noise_id=None):
    scene, result = one_light_sample
    folder = export_sample(
        tmp_path, scene, result, sample_id=sample_id, config=config, seed=1,
        camera=camera_model("nikon-d5100-npl"), noise_id=noise_id,
    )  # fmt: skip
    layers = read_exr(folder / "sensor-nikon-5100-npl.exr")
    return np.asarray(layers[RAW.split("/")[0]] if RAW not in layers else layers[RAW])


def test_the_noise_follows_the_noise_id_not_the_folder_name(tmp_path, one_light_sample, config):
    direct = _raw(tmp_path, one_light_sample, config, "src")
    relit = _raw(tmp_path, one_light_sample, config, "relit-out", noise_id="src")
    renamed = _raw(tmp_path, one_light_sample, config, "other-out")
    np.testing.assert_array_equal(relit, direct)
    assert not np.array_equal(renamed, direct)  # the id does enter the seed


def test_relight_seeds_the_noise_from_the_source_sample(monkeypatch, tmp_path):
    """``relight`` hands the source's id to the writer (captured, nothing rendered)."""
    import importlib

    relight_module = importlib.import_module("spectrinsic.gt_export.relight")

    seen = {}

    class Relit:
        scene = result = transport = None
        meta = {"transport": {}, "config_hash": "h", "seed": 3, "sample_id": "room__v0__two"}

    monkeypatch.setattr(relight_module, "relit_render", lambda *a, **k: Relit())
    monkeypatch.setattr(relight_module, "check_finite_result", lambda *a: None)
    monkeypatch.setattr(relight_module, "model_from_meta", lambda meta: None)
    monkeypatch.setattr(relight_module, "export_sample", lambda *a, **k: seen.update(k))
    relight_module.relight(tmp_path / "src", {0: "planck:3000K"}, tmp_path / "any-name")
    assert seen["noise_id"] == "room__v0__two" and seen["sample_id"] == "any-name"
