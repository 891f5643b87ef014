"""Lists of plain numbers passed through whole (issue 45): every walker over a scene record gives
what its value-by-value walk gave.

The references are the walks as they were before the fast path (one call per value), kept here:
the walkers must agree with them on records holding mesh rows, non-finite floats, numpy
scalars, tuples, mixed lists and ``csv:`` names in every position.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from spectrinsic.gt_export.relight import _csv_names
from spectrinsic.gt_export.relight.checks import readable_names
from spectrinsic.gt_export.sample import plain_data
from spectrinsic.number_lists import copy_numbers, finite_numbers, numbers_only
from spectrinsic.spectra.user_spectra import portable_names

CSV = "csv:/abs/spectra.csv#red"


def _walk(data: Any, leaf) -> Any:  # noqa: ANN001
    """The value-by-value walk: *leaf* on every string, lists and tuples to lists."""
    if isinstance(data, str):
        return leaf(data)
    if isinstance(data, dict):
        return {k: _walk(v, leaf) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [_walk(v, leaf) for v in data]
    return data


def _reference_plain(value: Any) -> Any:
    """plain_data(value) without digits, one call per value (before issue 45)."""
    if isinstance(value, dict):
        return {str(k): _reference_plain(v) for k, v in value.items()}
    if isinstance(value, np.generic):
        return _reference_plain(value.item())
    if isinstance(value, (list, tuple)):
        return [_reference_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def _record() -> dict[str, Any]:
    rng = np.random.default_rng(4)
    vertices = rng.normal(size=(50, 3)).tolist()
    return {
        "meshes": [
            {"vertices": vertices, "faces": rng.integers(0, 50, (20, 3)).tolist(), "name": "m"},
            {"vertices": [tuple(v) for v in vertices[:5]], "flags": [True, False, 1]},
            {"vertices": [[0.0, float("nan"), 1.0]], "weights": [1.0, float("inf")]},
            {"mixed": [[1, 2], [3, CSV]], "ragged": [[1.0], [2.0, [3.0]]], "scalar": np.float32(2)},
            {"numpy_rows": [[np.float64(0.5), 1]], "empty": [], "empty_rows": [[], []]},
        ],
        "materials": [{"spectrum": CSV, "table": [[400, 0.1], [700, 0.9]]}],
        "lights": [[CSV, 2.0], ("csv:rel.csv#a", [1, 2])],
    }


def test_plain_data_gives_the_value_by_value_walk():
    record = _record()
    assert plain_data(record) == _reference_plain(record)
    assert plain_data(record)["meshes"][2] == {
        "vertices": [[0.0, "nan", 1.0]],
        "weights": [1.0, "inf"],
    }


def test_the_name_walkers_give_the_value_by_value_walk(tmp_path):
    record = plain_data(_record())
    (tmp_path / "rel.csv").write_text("wavelength,a\n400,1\n700,1\n")
    assert portable_names(record, tmp_path) == _walk(record, lambda s: portable_names(s, tmp_path))
    readable = readable_names(record, tmp_path, tmp_path)
    assert readable == _walk(record, lambda s: readable_names(s, tmp_path, tmp_path))
    assert readable["lights"][1][0] != "csv:rel.csv#a"  # the walkers did change names
    names: set[str] = set()
    _walk(record, lambda s: names.add(s) if s.lower().startswith("csv:") else None)
    assert _csv_names(record) == names == {CSV, "csv:rel.csv#a"}


@pytest.mark.parametrize(
    ("value", "plain"),
    [
        ([1, 2.5, True], True),
        ([[1, 2], [3, 4]], True),
        (((1, 2), (3, 4)), True),
        ([], True),
        ([[1, 2], (3, 4)], False),  # rows of two kinds: walked
        ([[1, [2]]], False),
        ([1, None], False),
        ([np.float64(1.0)], False),  # a numpy scalar is converted by the walk
        ([["a"]], False),
    ],
)
def test_numbers_only_knows_a_list_of_plain_numbers(value, plain):
    assert numbers_only(value) is plain


def test_finite_numbers_and_the_copy():
    assert finite_numbers([[1.0, -2.0], [3, 4]])
    assert not finite_numbers([[1.0, float("-inf")]])
    assert not finite_numbers([float("inf"), float("-inf")])  # their sum is nan
    rows = [[1, 2], [3, 4]]
    copied = copy_numbers(rows)
    assert copied == rows and copied is not rows
    assert copy_numbers(((1, 2),)) == [[1, 2]]
