"""DataLoader(batch_size=8) over both loaders (``make test-torch``): issue 19 found
"stack expects each tensor to be equal size" on ``light_share``."""

from __future__ import annotations

import pytest

from spectrinsic.gt_export import load_sample, torch_dataset
from spectrinsic.gt_export.dataset.collate import collate

pytestmark = pytest.mark.torch


def test_the_default_collate_cannot_batch_a_one_and_a_two_light_sample(built, torch):
    with pytest.raises(RuntimeError, match="equal size"):
        next(iter(torch.utils.data.DataLoader(torch_dataset(built), batch_size=8)))


def test_torch_dataset_batches_of_8_with_a_light_mask(built, torch):
    ds = torch_dataset(built)
    batch = next(iter(torch.utils.data.DataLoader(ds, batch_size=8, collate_fn=collate)))
    assert batch["sample_id"] == ["a-one", "b-two"]
    assert batch["image"].shape == (2, 3, 12, 16) and batch["image"].dtype == torch.float32
    assert batch["light_share"].shape == (2, 2, 12, 16)
    assert batch["light_mask"].tolist() == [[True, False], [True, True]]
    assert (
        batch["ids"]["object"].shape == (2, 1, 12, 16)
        and batch["ids"]["object"].dtype == torch.int32
    )
    for i in range(2):
        item = ds[i]
        assert torch.equal(batch["image"][i], item["image"])
        n = item["light_share"].shape[0]
        assert torch.equal(batch["light_share"][i, :n], item["light_share"])
        assert not batch["light_share"][i, n:].any()


def test_shard_dataset_batches_of_8(built, torch, tmp_path_factory):
    pytest.importorskip("webdataset", reason="the shards extra is not installed")
    from spectrinsic.gt_export.dataset.shards import shard_dataset, write_shards

    out = tmp_path_factory.mktemp("shards")
    write_shards(built, out)
    loader = torch.utils.data.DataLoader(shard_dataset(out), batch_size=8, collate_fn=collate)
    batches = list(loader)
    ids = [sid for b in batches for sid in b["sample_id"]]
    assert sorted(ids) == ["a-one", "b-two"]
    batch = batches[0]
    assert batch["light_share"].shape[-1] == 2 and batch["light_mask"].shape[1] == 2
    for i, sid in enumerate(batch["sample_id"]):
        truth = load_sample(built / sid)
        assert torch.equal(batch["image"][i], torch.from_numpy(truth["image"]))
        assert batch["meta"][i]["sample_id"] == sid
