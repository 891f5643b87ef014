"""``read_splits`` of a folder that is no dataset (task r5-probe2): ``train`` on an empty folder
said "manifest.json has no splits; rebuild the dataset", as if a manifest were there."""

from __future__ import annotations

import json

import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export.dataset.manifest import read_splits


def test_no_manifest_is_said_to_be_missing(tmp_path):
    with pytest.raises(DatasetError, match="no manifest.json; expected a built dataset folder"):
        read_splits(tmp_path)


def test_a_manifest_without_splits_still_asks_for_a_rebuild(tmp_path):
    (tmp_path / "manifest.json").write_text(json.dumps({"samples": {}}))
    with pytest.raises(DatasetError, match="has no splits; rebuild the dataset"):
        read_splits(tmp_path)
