"""``--out`` as a symbolic link is refused, and ``..`` is resolved before the inside-a-dataset
check (:func:`spectrinsic.gt_export.folders.outfolder.check_out_folder`)."""

from __future__ import annotations

import json

import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export.folders.outfolder import check_output_folder


def _dataset(root):
    root.mkdir()
    (root / ".spectrinsic-dataset").write_text(
        json.dumps({"spectrinsic_dataset": 1, "config_hash": "x"})
    )
    return root


def test_a_symbolic_link_given_as_out_is_refused_and_its_target_untouched(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "link").symlink_to(real, target_is_directory=True)
    with pytest.raises(DatasetError, match="is a symbolic link"):
        check_output_folder(tmp_path / "link")
    assert list(real.iterdir()) == []


def test_dot_dot_out_of_a_dataset_is_beside_it_not_inside(tmp_path):
    ds = _dataset(tmp_path / "ds")
    check_output_folder(ds / ".." / "o")  # resolves to tmp_path/o: allowed
    with pytest.raises(DatasetError, match="inside the dataset"):
        check_output_folder(ds / "sub" / ".." / "o")  # resolves to ds/o: inside
