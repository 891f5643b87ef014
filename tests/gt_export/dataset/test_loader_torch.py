"""The PyTorch adapters (``make test-torch``, which CI runs: it installs the CPU build of torch
for that step only, so ``make test`` stays light)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import load_sample, torch_dataset

pytestmark = pytest.mark.torch


def test_torch_adapter_yields_channel_first_tensors(built, torch):
    ds = torch_dataset(built, keys=("image", "mask"))
    item = ds[0]
    assert len(ds) == 2 and item["sample_id"] == "a-one"
    assert item["image"].shape == (3, 12, 16) and item["image"].dtype == torch.float32
    assert item["mask"].shape == (1, 12, 16) and item["mask"].dtype == torch.bool


def test_torch_adapter_every_key_crop_transform_exposure_split(built, torch):
    full = torch_dataset(built)[0]
    sample = load_sample(built / "a-one")
    arrays = {k for k, v in sample.items() if isinstance(v, np.ndarray)}
    assert arrays <= set(full) and {"ids", "sample_id", "scene"} <= set(full)
    assert full["depth"].shape == (1, 12, 16) and full["ids"]["object"].dtype == torch.int32
    crops = torch_dataset(
        built,
        keys=("image", "depth"),
        crop=(5, 7),
        seed=1,
        transform=lambda item: {**item, "seen": True},
    )
    a, b = crops[0], crops[0]
    assert a["seen"] and a["image"].shape == (3, 5, 7) and a["depth"].shape == (1, 5, 7)
    assert torch.equal(a["image"], b["image"])  # the crop of item i is fixed by the seed
    bright = torch_dataset(built, keys=("image", "reflectance"), normalize_exposure=True)[0]
    assert torch.allclose(bright["reflectance"], full["reflectance"])
    assert torch.allclose(bright["image"], full["image"] * bright["exposure_scale"])
    manifest = json.loads((built / "manifest.json").read_text())
    for split, ids in manifest["splits"].items():
        if not ids:  # fewer scenes than splits: an empty split is an error naming it
            with pytest.raises(DatasetError, match=f"split '{split}' .* is empty"):
                torch_dataset(built, split=split)
            continue
        assert [
            torch_dataset(built, split=split)[i]["sample_id"] for i in range(len(ids))
        ] == sorted(ids)


def test_shards_feed_a_torch_dataloader(built, torch, tmp_path_factory):
    pytest.importorskip("webdataset", reason="the shards extra is not installed")
    from spectrinsic.gt_export.dataset.shards import shard_dataset, write_shards

    out = tmp_path_factory.mktemp("shards")
    write_shards(built, out)
    loader = torch.utils.data.DataLoader(shard_dataset(out), batch_size=None, num_workers=0)
    items = {item["sample_id"]: item for item in loader}
    assert sorted(items) == ["a-one", "b-two"]
    for sid, item in items.items():
        truth = load_sample(built / sid)
        assert torch.equal(torch.as_tensor(item["image"]), torch.from_numpy(truth["image"]))
