"""``dataset --store-transport --relight N``: a real two-light sample, its relit variant, resume.

12 x 12 pixels at 2 spp: these check the bookkeeping (files, manifest, check, resume, config
hash); exactness against direct renders is tested in ``tests/gt_export/relight/test_relight.py``.
"""

from __future__ import annotations

import json
import shutil

import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import check_dataset
from spectrinsic.pipeline.dataset import build_dataset
from spectrinsic.pipeline.presets import DatasetConfig

TINY = DatasetConfig.from_settings(
    "tiny-test",
    width=12,
    height=12,
    spp=4,
    max_depth=3,
    batches=2,
    modes=("spectral", "rgb3", "bands31"),
    denoise=True,
    seed=5,
    write_cube=True,
    store_transport=True,
    relight=1,
)
SAMPLE = "room-living__v0__two-colour-a"
RELIT = SAMPLE + "-relit1"


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    out = tmp_path_factory.mktemp("transport") / "dataset"
    report = build_dataset(out, TINY, only=SAMPLE)
    return out, report


@pytest.mark.slow
def test_store_transport_and_relit_variants_make_a_sound_dataset(built):
    out, report = built
    assert report.ok, report.failed
    assert check_dataset(out) == []
    manifest = json.loads((out / "manifest.json").read_text())
    assert sorted(manifest["samples"]) == [SAMPLE, RELIT]
    assert any(RELIT in ids for ids in manifest["splits"].values())
    source = json.loads((out / SAMPLE / "meta.json").read_text())
    relit = json.loads((out / RELIT / "meta.json").read_text())
    assert "transport.exr" in source["files"] and "transport.exr" not in relit["files"]
    assert relit["scene"] == source["scene"]  # same scene: same split
    assert relit["render"]["relit"]["from"] == SAMPLE
    assert [li["spectrum"] for li in relit["lights"]] != [li["spectrum"] for li in source["lights"]]
    assert "noise" in relit and relit["noise"]["batches"] == 2
    assert "cube" in relit["layers"]  # the relit 31-band cube is written as the source's was


@pytest.mark.slow
def test_a_missing_relit_variant_is_rebuilt_on_resume(built, tmp_path):
    out, _ = built
    copy = tmp_path / "dataset"
    shutil.copytree(out, copy)
    before = (copy / RELIT / "image.exr").read_bytes()
    shutil.rmtree(copy / RELIT)
    report = build_dataset(copy, TINY, only=SAMPLE)
    assert [o.sample_id for o in report.built] == [SAMPLE]
    assert (copy / RELIT / "image.exr").read_bytes() == before  # seeded: the same variant again
    assert check_dataset(copy) == []


def test_transport_settings_leave_other_configs_hash_alone():
    plain = DatasetConfig.from_settings("p", width=8, height=8, spp=2)
    assert "store_transport" not in plain.settings() and "relight" not in plain.settings()
    assert plain.with_options(store_transport=False, relight=0).config_hash() == plain.config_hash()
    assert plain.with_options(store_transport=True).config_hash() != plain.config_hash()
    with pytest.raises(DatasetError, match="needs --store-transport"):
        plain.with_options(relight=2)
    with pytest.raises(DatasetError, match="diagonal mode"):
        plain.with_options(modes=("spectral",), store_transport=True)


@pytest.mark.slow
def test_rebuild_without_relight_removes_the_old_relit_variants(built, tmp_path):
    out, _ = built
    copy = tmp_path / "dataset"
    shutil.copytree(out, copy)
    plain = TINY.with_options(relight=0)
    report = build_dataset(copy, plain, only=SAMPLE, rebuild=True)
    assert [o.sample_id for o in report.built] == [SAMPLE]
    assert not (copy / RELIT).exists()  # made from the old config's render
    assert check_dataset(copy) == []
