"""Batching without torch: per-light layers padded to one light count, with a light mask
(issue 19: a DataLoader with batch_size > 1 failed on ``light_share``)."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import load_sample
from spectrinsic.gt_export.dataset.collate import LIGHT_MASK, collate_arrays, pad_lights
from spectrinsic.gt_export.dataset.loader import prepare_item


def test_pad_lights_keeps_the_real_channels_and_zeroes_the_rest():
    share = np.arange(2 * 3 * 4, dtype=np.float32).reshape(2, 3, 4) + 1
    padded = pad_lights(share, 4, channel_first=True)
    assert padded.shape == (4, 3, 4) and padded.dtype == np.float32
    assert np.array_equal(padded[:2], share) and not padded[2:].any()
    one = pad_lights(share[0], 3, channel_first=False)  # (H, W) is one light
    assert (
        one.shape == (3, 4, 3) and np.array_equal(one[..., 0], share[0]) and not one[..., 1:].any()
    )
    with pytest.raises(DatasetError, match="2 lights"):
        pad_lights(share, 1, channel_first=True)


@pytest.mark.parametrize("layout", ["prepare_item", "load_sample"])
def test_a_one_light_and_a_two_light_sample_batch_together(built, layout):
    samples = [load_sample(built / sid) for sid in ("a-one", "b-two")]
    items = [prepare_item(s) for s in samples] if layout == "prepare_item" else samples
    first = layout == "prepare_item"
    batch = collate_arrays(items)
    h, w = samples[0]["image"].shape[:2]
    assert batch["light_share"].shape == ((2, 2, h, w) if first else (2, h, w, 2))
    assert batch[LIGHT_MASK].tolist() == [[True, False], [True, True]]
    share = batch["light_share"] if first else np.moveaxis(batch["light_share"], -1, 1)
    assert np.array_equal(share[1], np.moveaxis(samples[1]["light_share"], -1, 0))
    assert np.array_equal(share[0, 0], samples[0]["light_share"]) and not share[0, 1].any()
    # each pixel's shares still sum to 1 over the real lights wherever a surface is seen
    lit = batch["mask"].reshape(2, h, w) & (share.sum(axis=1) > 0)
    assert lit.any() and np.allclose(share.sum(axis=1)[lit], 1.0, atol=1e-5)
    ids = batch["sample_id"] if first else [m["sample_id"] for m in batch["meta"]]
    assert ids == ["a-one", "b-two"]  # the other values become lists, in batch order
    assert np.array_equal(batch["image"][1], items[1]["image"])
    assert batch["ids"]["material"].dtype == np.int32


def test_a_fixed_light_count_and_shapes_that_cannot_batch(built):
    items = [prepare_item(load_sample(built / sid)) for sid in ("a-one", "b-two")]
    batch = collate_arrays(items, max_lights=4)
    assert batch["light_share"].shape[1] == 4 and batch[LIGHT_MASK].sum(axis=1).tolist() == [1, 2]
    assert batch["exposure_scale"].shape == (2,)
    cropped = prepare_item(load_sample(built / "b-two"), crop=(5, 7), rng=np.random.default_rng(0))
    with pytest.raises(DatasetError, match="cannot batch layer .* crop"):
        collate_arrays([items[1], cropped])
