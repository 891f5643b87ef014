"""EXR files: float32 only, named channels, bit-exact round trip."""

from __future__ import annotations

import re

import numpy as np
import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export.formats.exr import (
    read_exr,
    read_exr_attributes,
    read_exr_stacks,
    write_exr,
)


def _random_layers(rng: np.random.Generator) -> dict[str, np.ndarray]:
    big = rng.standard_normal((9, 7, 3)).astype(np.float32) * 1e6
    big[0, 0] = (np.finfo(np.float32).tiny / 4, -0.0, np.finfo(np.float32).max)  # denormal, -0, max
    cube = rng.random((9, 7, 31), dtype=np.float32)
    return {
        "reflectance": big,
        # channel slices of a larger array are not C-contiguous: the writer must not scramble them
        "shading": cube[..., 3:6],
        "depth": rng.random((9, 7), dtype=np.float32),
        "cube": cube,
        "material_id": rng.integers(-1, 1000, (9, 7)).astype(np.int32),
    }


def test_round_trip_is_bit_exact(tmp_path):
    layers = _random_layers(np.random.default_rng(0))
    path = write_exr(
        tmp_path / "a.exr",
        layers,
        channel_names={"depth": ("Z",)},
        attributes={"spectrinsic.sample": "s1"},
    )
    back = read_exr(path)
    assert set(back) == set(layers)
    for name, array in layers.items():
        ints = np.asarray(array).dtype.kind in "iu"  # ids: int32, every other layer float32
        expected = np.asarray(array).astype(np.int32 if ints else np.float32)
        assert back[name].dtype == expected.dtype
        assert back[name].shape == expected.shape
        # bit-exact: compare the raw bytes, so -0.0 and denormals count too
        assert back[name].tobytes() == np.ascontiguousarray(expected).tobytes(), name
    assert read_exr_attributes(path)["spectrinsic.sample"] == "s1"


def test_channels_are_named_and_stored_as_float32(tmp_path):
    import OpenEXR

    rgb = np.arange(2 * 3 * 3, dtype=np.float32).reshape(2, 3, 3)
    path = write_exr(
        tmp_path / "n.exr", {"normals": rgb}, channel_names={"normals": ("X", "Y", "Z")}
    )
    f = OpenEXR.File(str(path), separate_channels=True)
    channels = f.channels()
    assert sorted(channels) == ["normals.X", "normals.Y", "normals.Z"]
    assert all(ch.type() == OpenEXR.FLOAT for ch in channels.values())
    np.testing.assert_array_equal(channels["normals.Y"].pixels, rgb[..., 1])


def test_float16_is_refused(tmp_path):
    with pytest.raises(DatasetError, match="float16"):
        write_exr(tmp_path / "h.exr", {"image": np.zeros((2, 2, 3), np.float16)})


def test_files_of_other_writers_group_rgb_channels(tmp_path):
    import OpenEXR

    rgb = np.random.default_rng(1).random((4, 5, 3), dtype=np.float32)
    channels = {f"beauty.{c}": np.ascontiguousarray(rgb[..., i]) for i, c in enumerate("RGB")}
    OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION}, channels).write(str(tmp_path / "o.exr"))
    np.testing.assert_array_equal(read_exr(tmp_path / "o.exr")["beauty"], rgb)


def test_corrupt_and_missing_files_raise_dataset_errors(tmp_path):
    path = write_exr(tmp_path / "c.exr", {"image": np.ones((8, 8, 3), np.float32)})
    data = bytearray(path.read_bytes())
    path.write_bytes(bytes(data[: len(data) // 2]))
    with pytest.raises(DatasetError, match="c.exr"):
        read_exr(path)
    with pytest.raises(DatasetError, match="does not exist"):
        read_exr(tmp_path / "missing.exr")
    good = write_exr(tmp_path / "g.exr", {"image": np.ones((2, 2, 3), np.float32)})
    with pytest.raises(DatasetError, match="no layer 'depth'"):
        read_exr(good, layers=["depth"])


def test_integer_ids_round_trip_exactly_beyond_float32(tmp_path):
    """float32 stops at 2**24: id 16777217 used to read back as 16777216. Ids are now stored as
    UINT channels holding the int32 bits, -1 (background) included."""
    ids = np.array([[-1, 0, 16777217], [2**31 - 1, 5, -1]], dtype=np.int32)
    path = write_exr(tmp_path / "ids.exr", {"object_id": ids, "depth": np.ones((2, 3), np.float32)})
    back = read_exr(path)
    assert back["object_id"].dtype == np.int32 and back["depth"].dtype == np.float32
    np.testing.assert_array_equal(back["object_id"], ids)


def test_ids_outside_int32_are_refused_not_wrapped(tmp_path):
    with pytest.raises(DatasetError, match="beyond the 32-bit range"):
        write_exr(tmp_path / "ids.exr", {"object_id": np.array([[3_000_000_000]], dtype=np.int64)})
    assert not (tmp_path / "ids.exr").exists()


def test_stacked_read_equals_the_layers_stacked_and_refuses_what_does_not_stack(tmp_path):
    """read_exr_stacks fills (N, H, W, C) straight from the decoded channels: bit for bit the
    layers read_exr returns, stacked; absent, integer and unequal layers are one-line errors."""
    rng = np.random.default_rng(3)
    layers = _random_layers(rng)
    layers["cube2"] = rng.standard_normal((9, 7, 31)).astype(np.float32) * 1e-30
    path = write_exr(tmp_path / "s.exr", layers)
    plain = read_exr(path)
    got = read_exr_stacks(path, {"cubes": ["cube2", "cube"], "one": ["depth"]})
    assert got["cubes"].dtype == np.float32 and got["cubes"].shape == (2, 9, 7, 31)
    assert np.array_equal(got["cubes"], np.stack([plain["cube2"], plain["cube"]]))
    assert got["one"].shape == (1, 9, 7, 1)
    assert np.array_equal(got["one"][0, ..., 0], plain["depth"])
    for bad, words in (
        (["cube", "nope"], "lacks the layers ['nope']"),
        (["cube", "shading"], "one channel count"),
        (["material_id"], "not float layers"),
    ):
        with pytest.raises(DatasetError, match=re.escape(words)) as info:
            read_exr_stacks(path, {"x": bad})
        assert "\n" not in str(info.value)
