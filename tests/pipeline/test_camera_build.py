"""``dataset --camera NAME``: the config (hash, refusal), and a real rendered sample through the
camera chain, relit too (the chain re-runs on the relit image).

24 x 24 pixels (LibRaw reads no DNG under 22 pixels) at 4 spp: these check the bookkeeping and
the identity in the processed linear space on a rendered sample; the noise physics is tested in
``tests/spectra/test_camera_chain.py``.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from spectrinsic.errors import DatasetError, SpectrinsicError
from spectrinsic.gt_export import check_dataset
from spectrinsic.gt_export.formats.exr import read_exr
from spectrinsic.pipeline.dataset import build_dataset
from spectrinsic.pipeline.presets import DatasetConfig, get_preset

SETTINGS = dict(
    width=24,
    height=24,
    spp=4,
    max_depth=3,
    batches=2,
    modes=("spectral", "rgb3", "bands31"),
    denoise=True,
    seed=5,
    store_transport=True,
    relight=1,
)
CAMERA = "nikon-5100-npl"
SAMPLE = "room-living__v0__two-colour-a"
RELIT = SAMPLE + "-relit1"
KEY = "Nikon 5100 (NPL)"


def test_camera_enters_the_config_hash_and_its_sensitivities_the_cameras():
    plain = DatasetConfig.from_settings("t", **SETTINGS)
    cam = plain.with_options(camera=CAMERA)
    assert cam.config_hash() != plain.config_hash()
    assert cam.settings()["camera"]["gain_e_per_dn"] == 3.46
    assert "camera" not in plain.settings()  # configs without a camera keep their hash
    other = plain.with_options(camera="camera:Sigma SDMerill (NPL)", cameras=("srgb",))
    assert other.resolved_cameras() == ("srgb", "camera:Sigma SDMerill (NPL)")


def test_camera_without_bands31_or_unknown_is_refused_in_one_line():
    with pytest.raises(DatasetError, match="needs the 'bands31' mode") as err:
        get_preset("preview").with_options(camera=CAMERA)
    assert "\n" not in str(err.value)
    with pytest.raises(SpectrinsicError, match="did you mean 'nikon-5100-npl'"):
        get_preset("default").with_options(camera="nikon-d5100")


@pytest.mark.slow
def test_a_rendered_sample_and_its_relit_variant_go_through_the_camera(tmp_path):
    out = tmp_path / "dataset"
    cfg = DatasetConfig.from_settings("camera-test", **SETTINGS, camera=CAMERA)
    report = build_dataset(out, cfg, only=SAMPLE)
    assert report.ok, report.failed
    assert check_dataset(out) == []  # every identity, the processed linear space's included
    for sample in (SAMPLE, RELIT):
        meta = json.loads((out / sample / "meta.json").read_text())
        assert meta["sensor"]["camera"] == CAMERA
        assert "sensor-nikon-5100-npl.dng" in meta["files"]
        ident = {
            "image": f"image_sensor/{KEY}",
            "reflectance": f"reflectance_sensor/{KEY}",
            "shading": f"shading_sensor/{KEY}",
            "residual": f"residual_sensor/{KEY}",
        }
        assert ident in meta["identities"]
    source = read_exr(out / SAMPLE / "sensor-nikon-5100-npl.exr")
    relit = read_exr(out / RELIT / "sensor-nikon-5100-npl.exr")
    assert not np.array_equal(source["raw_sensor"], relit["raw_sensor"])  # relit: re-run
    # identity by hand, to float rounding, in the processed linear space
    rebuilt = source["reflectance_sensor"].astype(np.float64) * source["shading_sensor"]
    rebuilt += source["residual_sensor"]
    np.testing.assert_allclose(rebuilt, source["image_sensor"], rtol=1e-6, atol=1e-7)


def test_a_camera_whose_curves_are_missing_is_refused_before_any_work(tmp_path, monkeypatch):
    from spectrinsic.errors import SpectrumNotFoundError

    monkeypatch.delenv("SPECTRINSIC_DATA", raising=False)  # the Jiang curves need a data dir
    cfg = DatasetConfig.from_settings("t", **SETTINGS, camera="nikon-d3")
    with pytest.raises(SpectrumNotFoundError, match="unknown camera 'Nikon D3'"):
        build_dataset(tmp_path / "out", cfg, only=SAMPLE)
    assert not (tmp_path / "out").exists()
