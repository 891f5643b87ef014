"""Camera layer keys (issue 44): a sensor CSV is keyed by its file name, so no layer or file
name holds the builder's path, and two sensor CSVs of one file name are refused up front."""

from __future__ import annotations

import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export.formats.names import camera_slug
from spectrinsic.gt_export.layers import LayerSettings
from spectrinsic.gt_export.layers.records import camera_key


def test_a_sensor_csv_is_keyed_by_its_file_name():
    assert camera_key("csv:/home/u/sensors/cam.csv") == "csv:cam.csv"
    assert camera_slug(camera_key("csv:/home/u/sensors/cam.csv")) == "cam-csv"
    assert camera_key("csv:sub/cam.csv") == "csv:sub/cam.csv"  # relative: as given
    assert camera_key("camera:Nikon D50") == "Nikon D50"
    assert camera_key("srgb") == "srgb"


def test_two_sensor_csvs_of_one_file_name_are_refused_in_one_line():
    with pytest.raises(DatasetError, match="two name the same layers 'csv:cam.csv'"):
        LayerSettings(cameras=("csv:/a/cam.csv", "csv:/b/cam.csv"))
    same = LayerSettings(cameras=("csv:/a/cam.csv", "csv:/a/cam.csv", "camera:Nikon D50"))
    assert same.cameras is not None and len(same.cameras) == 3  # one file twice: no clash
